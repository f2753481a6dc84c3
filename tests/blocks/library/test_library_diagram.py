"""One diagram with every block of the library, run by the C core, by the reference
loop and with every block through its Python methods: the same samples to the last bit
(all three run the blocks' C kernels; the executors' own work differs), and every block
offers a GIL-free kernel."""

from __future__ import annotations

import numpy as np

import blocks
from blocks.engine.kernel import Kernel
from blocks.library import LIBRARY
from blocks.library.kernel_block import KernelBlock

EVERY_BLOCK = """
name: every-library-block
time: {t_end: 0.5 s}
blocks:
  sine:   {type: Sine, period: 1 ms, params: {amplitude: [1.0, 0.5], frequency: [2.0, 7.0]}}
  pulse:  {type: Pulse, period: 1 ms, params: {period: 0.1, duty: 0.3}}
  chirp:  {type: Chirp, period: 1 ms, params: {f0: 1.0, f1: 20.0, target_time: 0.5}}
  noise:  {type: RandomNumber, period: 2 ms, params: {variance: 0.01, seed: 4}}
  white:  {type: BandLimitedWhiteNoise, period: 1 ms, params: {power: 1.0e-5, seed: 9}}
  rnd:    {type: RandomNumber, period: 5 ms, params: {distribution: uniform, minimum: 0.0, maximum: 3.0}}
  data:   {type: FromFile, period: 1 ms, params: {path: table.csv, method: linear}}
  mux:    {type: Mux, params: {widths: [2, 1], labels: [s, p]}}
  demux:  {type: Demux, params: {widths: [1, 2]}}
  sel:    {type: Selector, params: {indices: [2, 0]}}
  cat:    {type: Concatenate, params: {widths: [2, 1]}}
  prod:   {type: Product, params: {ops: "*/"}}
  div:    {type: Divide, params: {ops: "/", multiplication: matrix, shapes: [[2, 2]]}}
  cat4:   {type: Concatenate, params: {widths: [2, 2]}}
  bias4:  {type: Bias, params: {bias: [3.0, 0.0, 0.0, 3.0]}}
  bias2:  {type: Bias, params: {bias: [2.0, 2.0]}}
  abs:    {type: Abs}
  sign:   {type: Sign}
  bias:   {type: Bias, params: {bias: 0.25}}
  mm:     {type: MinMax, params: {function: max}}
  mm2:    {type: MinMax, params: {function: min, inputs: 2}}
  math:   {type: Math, params: {function: atan2}}
  exp:    {type: Math, params: {function: exp}}
  rel:    {type: Relational, params: {op: ">"}}
  cmp:    {type: Compare, params: {op: ">=", constant: 0.0}}
  logic:  {type: Logic, params: {op: xor, inputs: 2}}
  any:    {type: Logic, params: {op: or, inputs: 1}}
  sw:     {type: Switch, params: {criterion: nonzero}}
  msw:    {type: MultiportSwitch, params: {inputs: 3, default: last}}
  lut:    {type: LookupTable1D, params: {breakpoints: [-1, 0, 1], table: [0, 2, -1], extrapolation: linear}}
  lut2:   {type: LookupTable2D, params: {row_breakpoints: [-1, 1], column_breakpoints: [-1, 0, 1],
                                         table: [[0, 1, 2], [3, 4, 5]]}}
  dz:     {type: DeadZone, params: {start: -0.2, end: 0.2}}
  quant:  {type: Quantizer, params: {interval: 0.1}}
  rate:   {type: RateLimiter, period: 1 ms, params: {rising: 5.0, falling: -2.0}}
  lash:   {type: Backlash, params: {width: 0.3}}
  mem:    {type: Memory}
  integ:  {type: DiscreteIntegrator, period: 1 ms, params: {method: trapezoidal, lower: -1, upper: 1,
                                                            reset: rising}}
  fwd:    {type: DiscreteIntegrator, period: 1 ms, params: {gain: 2.0}}
  deriv:  {type: DiscreteDerivative, period: 1 ms}
  avg:    {type: MovingAverage, params: {window: 8}}
  pid:    {type: PID, period: 1 ms, params: {P: 1.0, I: 10.0, D: 0.01, N: 100, form: ideal,
                                             integrator: backward, filter: trapezoidal, lower: -0.5,
                                             upper: 0.5, anti_windup: clamping, tracking: true, reset: level}}
  stop:   {type: Stop}
  never:  {type: Compare, params: {op: ">", constant: 1.0e9}}
  const:  {type: Constant, params: {value: [0.5, -1.0]}}
  step:   {type: Step, period: 1 ms, params: {time: 0.2, before: 0.0, after: [1.0, 2.0]}}
  ramp:   {type: Ramp, period: 1 ms, params: {slope: 2.0, start: 0.1, initial: 0.5}}
  gain:   {type: Gain, params: {k: 2.5}}
  kmat:   {type: Gain, params: {k: [[1.0, 0.5], [-0.25, 2.0], [0.1, 0.3]]}}
  sum:    {type: Sum, params: {signs: "+-+"}}
  sat:    {type: Saturation, params: {lower: -0.5, upper: 0.7}}
  delay:  {type: UnitDelay, period: 2 ms, params: {initial: [1.0, 2.0]}}
  zoh:    {type: ZeroOrderHold, period: 5 ms}
  ss:     {type: DiscreteStateSpace, period: 1 ms, params: {A: [[0.9, 0.1], [-0.2, 0.8]], B: [[1.0], [0.5]],
                                                            C: [[1.0, -1.0]], D: [[0.1]]}}
  tf:     {type: DiscreteTransferFunction, period: 1 ms, params: {num: [0.5, 0.1], den: [1.0, -1.2, 0.36]}}
connections:
  - sine.y -> mux.u0
  - pulse.y -> mux.u1
  - mux.y -> demux.u
  - mux.y -> sel.u
  - sel.y -> cat.u0
  - chirp.y -> cat.u1
  - sine.y -> prod.u0
  - demux.y1 -> bias2.u
  - bias2.y -> prod.u1
  - cat.y -> abs.u
  - abs.y -> sign.u
  - sign.y -> bias.u
  - bias.y -> mm.u
  - sine.y -> mm2.u0
  - sel.y -> mm2.u1
  - noise.y -> math.u0
  - chirp.y -> math.u1
  - noise.y -> exp.u
  - math.y -> rel.u0
  - chirp.y -> rel.u1
  - chirp.y -> cmp.u
  - rel.y -> logic.u0
  - cmp.y -> logic.u1
  - cat.y -> any.u
  - sine.y -> sw.u0
  - pulse.y -> sw.control
  - prod.y -> sw.u1
  - rnd.y -> msw.control
  - chirp.y -> msw.u0
  - noise.y -> msw.u1
  - white.y -> msw.u2
  - chirp.y -> lut.u
  - chirp.y -> lut2.u0
  - white.y -> lut2.u1
  - chirp.y -> dz.u
  - chirp.y -> quant.u
  - chirp.y -> rate.u
  - chirp.y -> lash.u
  - chirp.y -> mem.u
  - chirp.y -> integ.u
  - pulse.y -> integ.reset
  - data.y -> fwd.u
  - chirp.y -> deriv.u
  - sine.y -> avg.u
  - chirp.y -> pid.u
  - data.y -> pid.track
  - pulse.y -> pid.reset
  - sine.y -> cat4.u0
  - sine.y -> cat4.u1
  - cat4.y -> bias4.u
  - bias4.y -> div.u
  - chirp.y -> never.u
  - never.y -> stop.u
  - const.y -> sum.u0
  - step.y -> sum.u1
  - sine.y -> sum.u2
  - sum.y -> gain.u
  - gain.y -> kmat.u
  - kmat.y -> sat.u
  - gain.y -> delay.u
  - chirp.y -> zoh.u
  - zoh.y -> ss.u
  - ramp.y -> tf.u
log: all
"""

TABLE = "time,value\n0,0\n0.1,1\n0.25,-1\n0.5,0.5\n"


def diagram(tmp_path):
    (tmp_path / "table.csv").write_text(TABLE)
    (tmp_path / "every.yaml").write_text(EVERY_BLOCK)
    return blocks.load_diagram(tmp_path / "every.yaml")


def test_the_diagram_holds_every_block_of_the_library(tmp_path):
    used = {spec.type_name for spec in diagram(tmp_path).blocks.values()}
    assert {cls.__name__ for cls in LIBRARY} <= used, {cls.__name__ for cls in LIBRARY} - used


def test_compiled_and_python_runs_agree_to_the_bit(tmp_path, monkeypatch):
    d = diagram(tmp_path)
    compiled = blocks.simulate(d)
    assert compiled.complete, compiled.status
    reference = blocks.simulate(d, engine="reference")
    with monkeypatch.context() as m:
        m.setattr(blocks.engine.compiled, "usable_kernel", lambda *args: None)
        python = blocks.simulate(d)
    for other in (reference, python):
        assert set(compiled) == set(other)
        for name in compiled:
            (tc, vc), (to, vo) = compiled[name], other[name]
            np.testing.assert_array_equal(tc, to, err_msg=name)
            np.testing.assert_array_equal(vc, vo, err_msg=name)
    assert np.ptp(compiled["pid.y"][1]) > 0.5 and np.all(np.isfinite(compiled["div.y"][1]))


def test_every_block_runs_in_c_without_the_gil(tmp_path):
    d = diagram(tmp_path)
    blocks.simulate(d, t_end="1 ms")
    for name, spec in d.blocks.items():
        if isinstance(spec.block, KernelBlock):
            kernel = spec.block.kernel()
            assert isinstance(kernel, Kernel) and kernel.nogil, name
