"""Initial feedthrough: a block whose outputs read its inputs at t = 0 only (as an FMU's
initial outputs may follow the inputs set before initialisation) is computed after its
sources at t = 0, holds its inputs where that would close a loop, and has no feedthrough
at later ticks."""

from __future__ import annotations

import numpy as np
import pytest

import blocks
from blocks import build_schedule, loads_diagram
from blocks.library.math_blocks import Gain
from blocks.engine.schedule import HeldInput
from hierhand.cli import main

from ..blockdefs import StartsFromInput, StartsFromOneInput

DEFS = "python:tests.blocks.blockdefs"
RAMP = "{type: Ramp, period: 1 ms, params: {slope: 1000.0, initial: 5.0}}"
"""5, 6, 7, 8 at t = 0, 1, 2, 3 ms."""

LOOP = f"""
time: {{t_end: 3 ms}}
blocks:
  src: {RAMP}
  s: {{type: Sum, params: {{signs: "++"}}}}
  d: {{type: {DEFS}:StartsFromInput, period: 1 ms}}
  g: {{type: Gain, params: {{k: 0.5}}}}
connections: [src.y -> s.u0, s.y -> d.u, d.y -> g.u, g.y -> s.u1]
log: [d.y]
"""


def load(text: str):
    return loads_diagram(text, filename="initial.yaml", trust=True)


def gain_and_ramp(kind: str, wires: str, log: str):
    """Block ``d`` of type ``kind`` (listed first, so file order alone would compute it
    first), a gain ``g`` of 2 and the ramp ``src``, wired by ``wires``."""
    return load(f"""
time: {{t_end: 3 ms}}
blocks:
  d: {{type: {DEFS}:{kind}, period: 1 ms}}
  g: {{type: Gain, params: {{k: 2.0}}}}
  src: {RAMP}
connections: [{wires}]
log: [{log}]
""")


def test_initial_reads_are_the_reads_unless_declared():
    assert Gain(2.0).initial_reads("y") == Gain(2.0).reads("y") == {"u"}
    block = StartsFromInput()
    assert block.reads("y") == frozenset() and block.initial_reads("y") == {"u"}
    two = StartsFromOneInput()
    assert two.initial_reads("y") == {"u"} and two.initial_reads("z") == frozenset()
    assert two.reads("y") == two.reads("z") == frozenset()


def test_at_t0_the_output_follows_its_source_through_a_lazy_gain_then_lags_one_hit():
    d = gain_and_ramp("StartsFromInput", "src.y -> g.u, g.y -> d.u", "d.y")
    s = build_schedule(d, d.t_end)
    assert "g" in s.lazy
    assert [b for b, _ in s.initial.evaluate] == ["src", "g", "d"]
    assert s.initial_held == ()
    np.testing.assert_allclose(blocks.simulate(d)["d.y"][1][:, 0], [10.0, 10.0, 12.0, 14.0])


def test_a_loop_through_the_initial_feedthrough_holds_the_input_at_t0_only():
    d = load(LOOP)
    held = (HeldInput("d", "u", "d.y -> g.u -> g.y -> s.u1 -> s.y -> d.u"),)
    assert build_schedule(d, d.t_end).initial_held == held
    assert build_schedule(d, None).initial_held == held
    # t = 0: d sees its default -1; then d.y is the previous s = src + 0.5 * d.y
    np.testing.assert_allclose(blocks.simulate(d)["d.y"][1][:, 0], [-1.0, 4.5, 8.25, 11.125])


def test_validate_notes_the_initial_feedthrough_and_the_held_input(tmp_path, capsys):
    path = tmp_path / "loop.yaml"
    path.write_text(LOOP, encoding="utf-8")
    assert main(["validate", str(path), "--trust"]) == 0
    out = capsys.readouterr().out
    (listing,) = [line for line in out.splitlines() if line.lstrip().startswith("d ")]
    assert listing.endswith("(feedthrough at t = 0 from u)")
    assert ("    d.u holds its initial value at t = 0: d is computed before its source, which depends "
            "on it (d.y -> g.u -> g.y -> s.u1 -> s.y -> d.u)") in out.splitlines()


T0_ONLY = """
  c: {type: Constant, params: {value: 1.0}}
  k: {type: Sum, params: {signs: "++"}}"""
"""Blocks that fire at t = 0 only (fed by a constant alone)."""


@pytest.mark.parametrize("extra_blocks, extra, loop", [
    ("", "s.y -> h.u, h.y -> s.u2", "s.y -> h.u -> h.y -> s.u2 -> s.y"),
    (T0_ONLY, "c.y -> k.u0, k.y -> h.u, h.y -> k.u1, h.y -> s.u2", "h.y -> k.u1 -> k.y -> h.u -> h.y"),
], ids=["through-the-held-loop", "at-t0-only"])
def test_a_loop_of_ordinary_feedthrough_beside_it_is_still_an_error(extra_blocks, extra, loop):
    with pytest.raises(blocks.DiagramError) as info:
        load(f"""
blocks:
  src: {RAMP}
  s: {{type: Sum, params: {{signs: "+++"}}}}
  d: {{type: {DEFS}:StartsFromInput, period: 1 ms}}
  g: {{type: Gain, params: {{k: 0.5}}}}
  h: {{type: Gain, params: {{k: 0.25}}}}{extra_blocks}
connections: [src.y -> s.u0, s.y -> d.u, d.y -> g.u, g.y -> s.u1, {extra}]
""")
    (issue,) = info.value.issues
    assert issue.message == f"algebraic loop: {loop}"


def test_per_port_initial_feedthrough_orders_only_the_ports_that_read_at_t0():
    def run(wires: str):
        d = gain_and_ramp("StartsFromOneInput", wires, "d.y, d.z")
        r = blocks.simulate(d)
        return build_schedule(d, d.t_end), r["d.y"][1][:, 0], r["d.z"][1][:, 0]

    # z does not read w at t = 0, so d.y -> g -> d.w is no loop; y(0) follows src
    s, y, z = run("src.y -> d.u, d.y -> g.u, g.y -> d.w")
    assert s.initial_held == ()
    np.testing.assert_allclose(y, [5.0, 5.0, 6.0, 7.0])
    np.testing.assert_allclose(z, [0.0, 10.0, 10.0, 12.0])
    # d.z -> g -> d.u: at t = 0, z first, then g, then y (no input held)
    s, y, z = run("src.y -> d.w, d.z -> g.u, g.y -> d.u")
    assert s.initial_held == ()
    steps = list(s.initial.evaluate)
    assert steps.index(("d", ("z",))) < steps.index(("g", ("y",))) < steps.index(("d", ("y",)))
    np.testing.assert_allclose(y, [0.0, 0.0, 10.0, 12.0])
    # d.y -> g -> d.u closes a loop at t = 0: u is held
    s, y, _ = run("src.y -> d.w, d.y -> g.u, g.y -> d.u")
    assert s.initial_held == (HeldInput("d", "u", "d.y -> g.u -> g.y -> d.u"),)
    np.testing.assert_allclose(y, [-1.0, -2.0, -4.0, -8.0])
