"""The FMU block's compiled kernel (blocks/csrc/fmu_block_step.c, blocks/fmu/compiled_step.py).

A diagram runs the same whether the FMU steps through its kernel or its Python methods:
the same samples to the last bit, the same status when the FMU fails (also inside a
stretch of events fused into one C call), the same end when the FMU asks to terminate.
``python`` runs a diagram with the FMU's kernel off; ``slow_calls`` counts what the C
step handed to Python, which shows the kernel ran.
"""

from __future__ import annotations

import collections
import re
from pathlib import Path

import numpy as np
import pytest

from blocks import Results, loads_diagram, simulate
from blocks.engine import compiled
from blocks.fmu import FMU
from blocks.fmu import compiled_step as fmu_kernel

fmpy = pytest.importorskip("fmpy")

from .build import SOURCES, build_error, compile_library, fmi2_files, typed_library, zip_files  # noqa: E402

pytestmark = pytest.mark.skipif(fmu_kernel.native() is None, reason="blocks._native is not built")


def python(monkeypatch, diagram) -> Results:
    """``diagram`` run with the FMU blocks' kernels off."""
    with monkeypatch.context() as m:
        m.setattr(FMU, "kernel", lambda self: None)
        return simulate(diagram)


def slow_calls(monkeypatch) -> collections.Counter:
    """Counts of the kernel's calls into Python, by kind ('output', 'update', 'step', ...)."""
    names = {code: kind for kind, code in fmu_kernel.native()["kinds"].items()}
    counts: collections.Counter = collections.Counter()
    call = fmu_kernel.KernelRun.__call__

    def counted(self, kind, t, status):
        counts[names[kind]] += 1
        return call(self, kind, t, status)

    monkeypatch.setattr(fmu_kernel.KernelRun, "__call__", counted)
    return counts


def assert_same(a: Results, b: Results) -> None:
    assert a.status == b.status and a.ended_by == b.ended_by
    assert list(a) == list(b)
    for name in a:
        assert np.array_equal(a[name][0], b[name][0]), name
        assert np.array_equal(a[name][1], b[name][1]), name


@pytest.fixture(scope="module")
def first_order(fmus) -> dict[int, Path]:
    """The first-order FMUs with Float64 ports only: FMI 3's without its Float32 output yf
    (with it, the FMU runs in Python)."""
    xml = re.sub(r'\s*<(Float32 name="yf"|Output valueReference="12"|InitialUnknown valueReference="12")[^>]*/>', "",
                 fmus.xml3)
    assert "yf" not in xml and 'valueReference="12"' not in xml
    return {2: fmus.fmi2, 3: fmus.make("first_order3_float64.fmu", xml, version=3)}


def diagram(path: Path, start_values: str = "{}", extra: str = "", wires: str = "", offset: str = "",
            t_end: str = "1 s", log: str = "[f.y, f.z, src.y]", params: str = ""):
    return loads_diagram(f"""
time: {{t_end: {t_end}}}
blocks:
  src: {{type: Ramp, period: 0.05 s, params: {{slope: 3.0, start: 0.1}}}}
  f: {{type: FMU, period: 0.1 s{offset}, params: {{path: '{path}', start_values: {start_values}{', ' + params if params else ''}}}}}
{extra}
connections:
  - src.y -> f.u
{wires}
log: {log}
""", filename="kernel.yaml")


@pytest.mark.parametrize("version", [2, 3])
def test_the_kernel_gives_the_python_samples_to_the_last_bit(first_order, monkeypatch, version):
    """Events at 0.05 s fuse into one C call per hyperperiod; the FMU is only handed to
    Python for its first outputs (which initialise it)."""
    d = diagram(first_order[version], start_values="{a: 0.3, b: 0.7}")
    reference = python(monkeypatch, d)
    counts = slow_calls(monkeypatch)
    compiled = simulate(d)
    assert compiled.complete
    assert_same(compiled, reference)
    assert counts == {"output": 1}


def test_an_offset_fmu_starts_at_its_first_hit_through_the_kernel(fmus, monkeypatch):
    d = diagram(fmus.fmi2, offset=", offset: 0.05 s")
    reference = python(monkeypatch, d)
    counts = slow_calls(monkeypatch)
    compiled = simulate(d)
    assert_same(compiled, reference)
    assert compiled["f.y"][0][0] == 0.05 and counts == {"output": 1}


def test_python_blocks_around_the_compiled_fmu(fmus, monkeypatch):
    """A Python block feeds the FMU and another reads it: values cross between the worlds
    as they do between Python blocks.

    The executor runs the FMU's source and ``h`` through their Python methods (it takes no
    kernel of theirs); a library block's kernel itself cannot be switched off, since its
    Python methods call it."""
    extra = ("  g: {type: Gain, params: {k: 0.5}}\n"
             "  h: {type: Gain, params: {k: -2.0}}")
    d = diagram(fmus.fmi2, extra=extra, wires="  - f.y -> g.u\n  - g.y -> h.u", log="[f.y, g.y, h.y]")
    in_python = (d.blocks["src"].block, d.blocks["h"].block)
    usable = compiled.usable_kernel
    ran_in_python: collections.Counter = collections.Counter()

    def no_kernel_for_python_blocks(block, *args):
        if any(block is b for b in in_python):
            ran_in_python[type(block).__name__] += 1
            return None
        return usable(block, *args)

    monkeypatch.setattr(compiled, "usable_kernel", no_kernel_for_python_blocks)
    reference = python(monkeypatch, d)
    counts = slow_calls(monkeypatch)
    result = simulate(d)
    assert result.complete, result.status
    assert_same(result, reference)
    assert counts == {"output": 1}
    assert set(ran_in_python) == {"Ramp", "Gain"}


def handed(kind: str, isolation: str) -> str:
    """The kind of slow call that hands a step which was not a plain success to Python: the
    FMU call's own in the run's process, 'hosted' for an FMU in a process of its own."""
    return kind if isolation == "none" else "hosted"


@pytest.mark.parametrize("isolation", ["none", "process"])
@pytest.mark.parametrize("version", [2, 3])
def test_a_failing_step_inside_a_fused_stretch_fails_as_in_python(first_order, monkeypatch, version, isolation):
    """doStep fails at t = 0.3 s (u = 0.6 exceeds the threshold), inside a C call that runs
    the events at 0.3 and 0.35 s: same status, same samples up to there."""
    d = diagram(first_order[version], start_values="{threshold: 0.55}", params=f"isolation: {isolation}")
    reference = python(monkeypatch, d)
    counts = slow_calls(monkeypatch)
    compiled = simulate(d)
    assert compiled.status.startswith("failed at t=0.3 s: block 'f' (FMU)"), compiled.status
    assert f"fmi{version}DoStep at t=0.3 s (step 0.1 s) returned status 'error'" in compiled.status
    assert "exceeds the threshold" in compiled.status                 # the FMU's log line
    assert_same(compiled, reference)
    assert counts == {"output": 1, handed("step", isolation): 1}
    assert simulate(d).status == compiled.status                      # the broken instance was not pooled


def test_a_discard_through_the_kernel_is_the_same_failure(fmus, monkeypatch):
    d = loads_diagram(f"""
time: {{t_end: 1 s}}
blocks:
  src: {{type: Step, period: 0.1 s, params: {{time: 0.2, before: 0.0, after: -5.0}}}}
  f: {{type: FMU, period: 0.1 s, params: {{path: '{fmus.fmi2}', start_values: {{threshold: 2}}}}}}
connections: [src.y -> f.u]
log: [f.y]
""")
    reference = python(monkeypatch, d)
    compiled = simulate(d)
    assert "fmi2DoStep at t=0.2 s (step 0.1 s) returned status 'discard'" in compiled.status
    assert_same(compiled, reference)


@pytest.mark.parametrize("isolation", ["none", "process"])
@pytest.mark.parametrize("which, failing", [("set", "fmi2SetReal"), ("get", "fmi2GetReal")])
def test_a_failing_set_or_get_through_the_kernel_fails_as_in_python(tmp_path, monkeypatch, which, failing, isolation):
    """The FMU refuses to take u (to give y) from t = 0.3 s: inside a fused C call, the
    same status, FMU log line and samples as through the Python methods."""
    why = build_error()
    if why:
        pytest.skip(why)
    library = compile_library(tmp_path / f"fail_{which}{fmpy.sharedLibraryExtension}", "first_order_fmi2.c",
                              "fmi2_unsupported.c", defines={f"FAIL_{which.upper()}_AT": "0.3"})
    path = zip_files(tmp_path / f"fail_{which}.fmu", fmi2_files(library))
    d = diagram(path, params=f"isolation: {isolation}")
    reference = python(monkeypatch, d)
    counts = slow_calls(monkeypatch)
    compiled = simulate(d)
    at = "0.3" if which == "set" else "0.2"   # a get fails after the step from 0.2 s to 0.3 s
    assert compiled.status.startswith(f"failed at t={at} s: block 'f' (FMU)"), compiled.status
    assert f"{failing} returned status 'error'" in compiled.status
    assert f"cannot {which} " in compiled.status                          # the FMU's log line
    assert_same(compiled, reference)
    assert counts == {"output": 1, handed(which, isolation): 1}
    assert simulate(d).status == compiled.status                          # the broken instance was not pooled


def test_an_fmu_with_ports_of_other_types_runs_in_python(fmus, first_order):
    """Only Float64 ports have a C path; FMI 3's first-order FMU has a Float32 output."""
    assert FMU(first_order[2]).kernel() is not None and FMU(first_order[3]).kernel() is not None
    assert FMU(fmus.fmi3).kernel() is None


# -- termination through the kernel --------------------------------------------------------


def float_only(xml: str, fmi: int) -> str:
    """The typed FMU's model description with only its Float64 ports left (the others
    have value references from 10 up; FMI 3's independent time is 999)."""
    if fmi == 2:
        xml = re.sub(r'\s*<ScalarVariable name="[ibes]_(in|out)".*?</ScalarVariable>', "", xml)
        return re.sub(r'\s*<Unknown index="(6|8|10)"[^>]*/>', "", xml)

    def other(m: re.Match) -> str:
        return m.group(0) if not 10 <= int(m.group(2)) < 999 else ""

    xml = re.sub(r'\s*<(\w+) name="\w+" valueReference="(\d+)"[^>]*?(/>|>.*?</\1>)', other, xml, flags=re.S)
    return re.sub(r'\s*<(Output|InitialUnknown) valueReference="(\d+)"[^>]*/>', other, xml)


@pytest.fixture(scope="module")
def terminating(tmp_path_factory) -> dict[int, Path]:
    """The typed conformance FMUs (they terminate at their parameter stop_at) with only
    their Float64 ports, so that they step through the kernel."""
    why = build_error()
    if why:
        pytest.skip(why)
    build = tmp_path_factory.mktemp("terminating")
    out = {}
    for fmi in (2, 3):
        identifier = f"Typed{fmi}"
        library = typed_library(build, fmi)
        platform = fmpy.platform if fmi == 2 else fmpy.platform_tuple
        files = {"modelDescription.xml": float_only((SOURCES / f"typed_fmi{fmi}.xml").read_text(), fmi),
                 f"binaries/{platform}/{identifier}{fmpy.sharedLibraryExtension}": library}
        out[fmi] = zip_files(build / f"float{fmi}.fmu", files)
    return out


@pytest.mark.parametrize("isolation", ["none", "process"])
@pytest.mark.parametrize("fmi", [2, 3])
@pytest.mark.parametrize("stop_at, end", [(0.25, 0.3), (0.3, 0.3)])
def test_termination_through_the_kernel_ends_the_run_as_in_python(terminating, monkeypatch, fmi, stop_at, end,
                                                                   isolation):
    """The request comes back from a step inside a fused C call (a 0.05 s clock fires in
    between); the run ends at the FMU's next hit, every block logged up to there."""
    d = loads_diagram(f"""
time: {{t_end: 1 s}}
blocks:
  fmu: {{type: FMU, period: 0.1 s, params: {{path: '{terminating[fmi]}', start_values: {{stop_at: {stop_at}}},
                                            isolation: {isolation}}}}}
  clock: {{type: Ramp, period: 0.05 s, params: {{slope: 1}}}}
connections: [clock.y -> fmu.{"r_in" if fmi == 2 else "f_in"}]
log: all
""")
    block = d.blocks["fmu"].block
    assert all(kind == "Float64" for kind in block.port_types.values()) and block.kernel() is not None
    reference = python(monkeypatch, d)
    counts = slow_calls(monkeypatch)
    compiled = simulate(d)
    assert compiled.complete and compiled.ended_by["block"] == "fmu"
    assert compiled.ended_by["time"] == pytest.approx(end)
    assert "requested to terminate the simulation" in compiled.ended_by["reason"]
    assert_same(compiled, reference)
    assert counts == {"output": 1, handed("step", isolation): 1}


@pytest.mark.parametrize("status", [0, 4], ids=["ok", "fatal"])
def test_ctrl_c_inside_a_compiled_step_is_the_runs_interrupt(fmus, monkeypatch, tmp_path, status):
    """SIGINT inside doStep at t = 0.2 s, within a fused C call: the interrupt the FMU's
    log callback noted is raised after the step (ok) or by the failure (fatal), and the
    run stops as interrupted with the results so far, as in Python. (In the run's process:
    the SIGINT is the FMU's own process's.)"""
    path = zip_files(tmp_path / "interrupting.fmu", fmi2_files(fmus.interrupting[status]))
    d = diagram(path, log="[f.y, src.y]", params="isolation: none")
    try:
        reference = python(monkeypatch, d)
        counts = slow_calls(monkeypatch)
        compiled = simulate(d)
    except KeyboardInterrupt:  # pragma: no cover - would otherwise stop the whole test session
        pytest.fail("the interrupt escaped the run")
    assert compiled.status == "interrupted at t=0.2 s", compiled.status
    assert_same(compiled, reference)
    assert counts == ({"output": 1} if status == 0 else {"output": 1, "step": 1})
