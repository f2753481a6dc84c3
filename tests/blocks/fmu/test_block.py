"""The FMU import block, with small FMI 2.0 and 3.0 co-simulation FMUs compiled at test time.

The C sources and model descriptions are in ``sources/``: a discrete first-order
system x[k+1] = a x[k] + b u[k], y = x, with a vector output z = [scale * x, time]
(``z[2]``/``z[1]`` scalars in FMI 2, an array in FMI 3) and a doStep that fails when u
exceeds a threshold. They are built with the system C compiler and fmpy's FMI headers;
without a compiler these tests are skipped.
"""

from __future__ import annotations

from fractions import Fraction

import gc
import os
import re
import shutil
from pathlib import Path

import numpy as np
import pytest

import blocks
from blocks import DiagramError, SimulationError, load_diagram, loads_diagram, simulate
from blocks.fmu import FMU

fmpy = pytest.importorskip("fmpy")

from .build import compile_library, fmi2_files, zip_files  # noqa: E402


def diagram(path: Path, period: str = "0.1 s", start_values: str = "{}", source: str | None = None,
            extra: str = "", t_end: str = "1 s", log: str = "[f.y, f.z]", params: str = ""):
    src = source or "{type: Step, period: 0.1 s, params: {time: 0.3, before: 1.0, after: 2.0}}"
    return loads_diagram(f"""
time: {{t_end: {t_end}}}
blocks:
  src: {src}
  f: {{type: FMU, period: {period}, params: {{path: '{path}', start_values: {start_values}{', ' + params if params else ''}}}}}
{extra}
connections:
  - src.y -> f.u
log: {log}
""", filename="fmu.yaml")


def first_order(a: float, b: float, x0: float, u) -> np.ndarray:
    """x[k+1] = a x[k] + b u[k] with x[0] = x0: the values x[0..len(u)]."""
    x = [x0]
    for uk in u:
        x.append(a * x[-1] + b * uk)
    return np.array(x)


def load_error(text_or_call) -> str:
    with pytest.raises(DiagramError) as info:
        text_or_call()
    return str(info.value)


# -- simulation ---------------------------------------------------------------------------


def test_the_outputs_feed_through_from_the_inputs_the_model_structure_names(fmus):
    """Per output, the inputs its ModelStructure entry lists (all of them where it lists
    none, the attribute absent): that is the block's feedthrough, unless 'feedthrough:
    false' asks for the Jacobi exchange; an FMU read with feedthrough runs in Python."""
    xml = fmus.xml3
    for vr, depends in ((7, ' dependencies="6"'), (8, ""), (12, ' dependencies="10"')):
        xml = xml.replace(f'<Output valueReference="{vr}" dependencies=""/>', f'<Output valueReference="{vr}"{depends}/>')
    path = fmus.make("declared.fmu", xml, version=3)
    assert FMU(path).feedthrough == {"y": {"u"}, "z": {"u", "w"}, "wsum": set(), "yf": {"w"}}
    assert FMU(path, feedthrough=False).feedthrough is False
    xml2 = fmus.xml2.replace('<Unknown index="9" dependencies=""/>', '<Unknown index="9"/>', 1)
    declared = fmus.make("declared2.fmu", xml2)
    assert FMU(declared).feedthrough == {"y": set(), "z": {"u"}} and FMU(declared).kernel() is None
    jacobi = FMU(declared, feedthrough=False)
    assert not jacobi.has_feedthrough() and jacobi.kernel() is not None


def test_fmi2_fmu_matches_the_closed_form(fmus):
    d = diagram(fmus.fmi2)
    block = d.blocks["f"].block
    assert block.inputs == {"u": 1} and block.outputs == {"y": 1, "z": 2}
    assert block.feedthrough is False and block.fmi_version == "2.0"
    assert block.variable_of("z") == "z[...]"
    results = simulate(d)
    assert results.complete, results.status
    t, y = results["f.y"]
    np.testing.assert_allclose(t, np.arange(11) / 10)
    u = np.where(t[:-1] < 0.3, 1.0, 2.0)           # the input held over each step
    np.testing.assert_allclose(y[:, 0], first_order(0.5, 1.0, 0.0, u), rtol=1e-12)
    _, z = results["f.z"]
    np.testing.assert_allclose(z[:, 0], y[:, 0], rtol=1e-12)  # z[1] = scale * x, sorted by index
    np.testing.assert_allclose(z[:, 1], t, atol=1e-12)         # z[2] = the FMU's own time


def test_csv_columns_keep_the_fmus_indices(fmus, tmp_path):
    """z[1], z[2] of the FMI 2 FMU keep their names; the FMI 3 array z counts from 1 as FMI does."""
    simulate(diagram(fmus.fmi2, t_end="0.2 s")).save(tmp_path / "fmi2", csv=True)
    assert (tmp_path / "fmi2" / "signals.csv").read_text().splitlines()[0] == "time,f.y,f.z[1],f.z[2]"
    simulate(diagram(fmus.fmi3, t_end="0.2 s")).save(tmp_path / "fmi3", csv=True)
    assert (tmp_path / "fmi3" / "signals.csv").read_text().splitlines()[0] == "time,f.y,f.z[1],f.z[2]"


def test_start_values_of_every_type_change_the_result(fmus):
    sv = "{a: 0.9, b: 0.5, x0: 2.0, scale: 3, frozen: false}"
    results = simulate(diagram(fmus.fmi2, start_values=sv))
    t, y = results["f.y"]
    u = np.where(t[:-1] < 0.3, 1.0, 2.0)
    np.testing.assert_allclose(y[:, 0], first_order(0.9, 0.5, 2.0, u), rtol=1e-12)
    np.testing.assert_allclose(results["f.z"][1][:, 0], 3 * y[:, 0], rtol=1e-12)
    frozen = simulate(diagram(fmus.fmi2, start_values="{x0: 2.0, frozen: true}"))
    np.testing.assert_array_equal(frozen["f.y"][1], 2.0)


@pytest.mark.parametrize("version", [2, 3])
def test_parameter_values_are_the_start_values_over_the_model_description(fmus, version):
    path = fmus.fmi2 if version == 2 else fmus.fmi3
    block = diagram(path, start_values="{a: 0.9, scale: 3, frozen: true}").blocks["f"].block
    values = block.parameter_values()
    assert values == {"a": 0.9, "b": 1.0, "x0": 0.0, "threshold": 100.0, "scale": 3, "frozen": True}
    assert [type(values[k]) for k in ("a", "scale", "frozen")] == [float, int, bool]
    assert diagram(path).blocks["f"].block.parameter_values()["a"] == 0.5


def test_fmu_in_a_feedback_loop_has_no_algebraic_loop(fmus):
    """Co-simulation outputs do not depend on the same instant's input: u = r - y is fine."""
    d = loads_diagram(f"""
time: {{t_end: 2 s}}
blocks:
  r: {{type: Constant, params: {{value: 1.0}}}}
  e: {{type: Sum, params: {{signs: "+-"}}}}
  f: {{type: FMU, period: 0.1 s, params: {{path: '{fmus.fmi2}', start_values: {{a: 0.8, b: 0.5}}}}}}
connections:
  - r.y -> e.u0
  - f.y -> e.u1
  - e.y -> f.u
log: [f.y]
""")
    _, y = simulate(d)["f.y"]
    x = [0.0]
    for _ in range(20):
        x.append(0.8 * x[-1] + 0.5 * (1.0 - x[-1]))
    np.testing.assert_allclose(y[:, 0], x, rtol=1e-12)


def test_offset_starts_the_fmu_at_its_first_hit(fmus):
    d = loads_diagram(f"""
time: {{t_end: 1 s}}
blocks:
  src: {{type: Constant, params: {{value: 1.0}}}}
  f: {{type: FMU, period: 0.2 s, offset: 0.1 s, params: {{path: '{fmus.fmi2}'}}}}
connections: [src.y -> f.u]
log: [f.z]
""")
    t, z = simulate(d)["f.z"]
    np.testing.assert_allclose(t, [0.1, 0.3, 0.5, 0.7, 0.9])
    np.testing.assert_allclose(z[:, 1], t, atol=1e-12)


def test_runs_reuse_one_instance_reset_between_runs(fmus):
    d = diagram(fmus.fmi2, start_values="{a: 0.7}")
    block = d.blocks["f"].block
    first = simulate(d)
    assert len(block._model.idle) == 1
    pooled = block._model.idle[0]
    second = simulate(d)
    assert block._model.idle == [pooled] and block._model.live == 0
    np.testing.assert_array_equal(first["f.y"][1], second["f.y"][1])
    # Two states alive at once get two instances, each with its own FMU state.
    s1, s2 = block.initial_state(), block.initial_state()
    u = {"u": np.array([1.0])}
    block.output(0.0, s1, u)
    block.output(0.0, s2, u)
    assert s1.instance is not s2.instance
    block.update(0.0, s1, u)
    assert block.output(0.1, s1, u)["y"][0] == 1.0 and block.output(0.0, s2, u)["y"][0] == 0.0
    s1.close()
    s2.close()
    assert len(block._model.idle) == 2 and block._model.live == 0


def test_close_frees_instances_and_extracted_files(fmus):
    d = diagram(fmus.fmi2)
    block = d.blocks["f"].block
    simulate(d)
    folder = block._model.dir
    assert (folder / "modelDescription.xml").is_file()
    block.close()
    assert not folder.exists() and block._model.idle == []
    with pytest.raises(blocks.BlockError, match="closed"):
        block.initial_state()


def test_extracted_files_go_away_with_the_block(fmus):
    d = diagram(fmus.fmi2)
    simulate(d)
    folder = d.blocks["f"].block._model.dir
    del d
    gc.collect()
    assert not folder.exists()


def test_fmus_loaded_in_many_threads_at_once_leave_the_working_folder_alone(fmus, monkeypatch):
    """fmpy changes into an FMU's binary folder to load it and back: threads loading at
    once must not leave the process in one FMU's extracted folder (removed with its block).
    The binaries here load in microseconds; a large one's load is made to take 20 ms."""
    import ctypes
    import threading
    import time
    from concurrent.futures import ThreadPoolExecutor

    import fmpy.fmi1

    class SlowLoader:
        """A loader that takes 20 ms and counts how many loads overlap (each changes the
        working folder, so they must not)."""
        loading = overlapped = 0

        def LoadLibrary(self, path):
            self.loading += 1
            self.overlapped = max(self.overlapped, self.loading)
            time.sleep(0.02)
            self.loading -= 1
            return ctypes.cdll.LoadLibrary(path)

    loader = SlowLoader()
    monkeypatch.setattr(fmpy.fmi1, "cdll", loader)
    here = os.getcwd()
    threads = 8
    start = threading.Barrier(threads)

    def run(version: int):
        start.wait()
        d = diagram(fmus.fmi2 if version == 2 else fmus.fmi3, t_end="0.2 s", log="[f.y]", params="isolation: none")
        return simulate(d).complete

    with ThreadPoolExecutor(threads) as pool:
        for _ in range(3):
            assert all(pool.map(run, [2, 3] * (threads // 2)))
            gc.collect()
            assert os.getcwd() == here
    assert loader.overlapped == 1


def test_fmu_diagrams_loaded_and_run_in_many_threads_at_once_all_complete(fmus):
    """Each thread loads (reading and validating the modelDescription) and runs its own
    diagram, the FMU in a process of its own, all starting at once."""
    import threading
    from concurrent.futures import ThreadPoolExecutor

    threads = 8
    start = threading.Barrier(threads)

    def run(version: int):
        start.wait()
        r = simulate(diagram(fmus.fmi2 if version == 2 else fmus.fmi3, t_end="0.2 s", log="[f.y]"))
        return r.complete or r.status

    with ThreadPoolExecutor(threads) as pool:
        for _ in range(6):
            outcomes = list(pool.map(run, [2, 3] * (threads // 2)))
            assert outcomes == [True] * threads, outcomes


def test_fmi3_arrays_float32_and_input_defaults(fmus):
    d = loads_diagram(f"""
time: {{t_end: 0.5 s}}
blocks:
  src: {{type: Constant, params: {{value: 1.0}}}}
  f: {{type: FMU, period: 0.1 s, params: {{path: '{fmus.fmi3}', start_values: {{a: 0.5, scale: 2, w: [3, 4]}}}}}}
connections: [src.y -> f.u]
log: [f.y, f.z, f.wsum, f.yf]
""")
    block = d.blocks["f"].block
    assert block.fmi_version == "3.0"
    assert block.inputs == {"u": 1, "w": 2}
    assert block.outputs == {"y": 1, "z": 2, "wsum": 1, "yf": 1}
    np.testing.assert_array_equal(block.input_defaults["w"], [3.0, 4.0])  # unconnected: start values
    results = simulate(d)
    assert results.complete, results.status
    t, y = results["f.y"]
    np.testing.assert_allclose(y[:, 0], first_order(0.5, 1.0, 0.0, np.ones(5)), rtol=1e-12)
    np.testing.assert_allclose(results["f.z"][1], np.column_stack((2 * y[:, 0], t)), atol=1e-12)
    np.testing.assert_allclose(results["f.wsum"][1][1:, 0], 7.0)
    np.testing.assert_allclose(results["f.yf"][1][:, 0], y[:, 0], rtol=1e-6)
    again = simulate(d)                              # the pooled FMI 3 instance, reset
    assert len(block._model.idle) == 1
    np.testing.assert_array_equal(again["f.z"][1], results["f.z"][1])


def test_fmi3_array_input_connected(fmus):
    d = loads_diagram(f"""
time: {{t_end: 0.2 s}}
blocks:
  src: {{type: Constant, params: {{value: 1.0}}}}
  w: {{type: Constant, params: {{value: [0.25, 0.5]}}}}
  f: {{type: FMU, period: 0.1 s, params: {{path: '{fmus.fmi3}'}}}}
connections: [src.y -> f.u, w.y -> f.w]
log: [f.wsum]
""")
    np.testing.assert_allclose(simulate(d)["f.wsum"][1][:, 0], [0.0, 0.75, 0.75])


# -- what runs an FMU's code ---------------------------------------------------------------


def _traces(fmus, identifier: str) -> set[str]:
    """What the marker FMU of ``identifier`` left: 'loaded', 'instantiated' (see marker.c)."""
    return {p.name.rsplit(".", 1)[1] for p in fmus.markers.glob(f"{identifier}{fmpy.sharedLibraryExtension}.*")}


def test_loading_a_diagram_does_not_run_the_fmus_code(fmus, tmp_path):
    """Only a run loads the binary: loading, describing and scheduling read modelDescription.xml."""
    path = zip_files(tmp_path / "traced.fmu", fmi2_files(fmus.marker, identifier="TracedLoad"))
    d = diagram(path)
    block = d.blocks["f"].block
    assert block.parameter_values()["a"] == 0.5 and block.describe().startswith("FMI 2.0")
    blocks.build_schedule(d, None)
    state = block.initial_state()
    assert _traces(fmus, "TracedLoad") == set()
    assert block._model.dir is None                     # nothing extracted either
    state.close()
    assert simulate(d).complete
    assert _traces(fmus, "TracedLoad") == {"loaded", "instantiated"}


# -- run-time failures --------------------------------------------------------------------


@pytest.mark.parametrize("version", [2, 3])
def test_dostep_error_names_block_time_status_and_fmu_log(fmus, version):
    path = fmus.fmi2 if version == 2 else fmus.fmi3
    d = diagram(path, start_values="{threshold: 1.5}", log="[f.y]")
    results = simulate(d)
    assert not results.complete
    status = results.status
    assert status.startswith("failed at t=0.3 s: block 'f' (FMU)"), status
    assert f"fmi{version}DoStep at t=0.3 s (step 0.1 s) returned status 'error'" in status
    assert "input u = 2 exceeds the threshold 1.5 at t = 0.3" in status       # the FMU's log line
    t, y = results["f.y"]                                                    # results so far kept
    np.testing.assert_allclose(t, [0.0, 0.1, 0.2, 0.3])
    np.testing.assert_allclose(y[:, 0], first_order(0.5, 1.0, 0.0, [1, 1, 1]))
    with pytest.raises(SimulationError) as info:
        simulate(d, raise_on_failure=True)
    assert info.value.block == "f" and info.value.time == pytest.approx(0.3)
    # The failed instance was freed, not pooled; the next run starts clean and fails the same way.
    assert simulate(d).status == status


def test_dostep_discard_is_a_failure(fmus):
    src = "{type: Step, period: 0.1 s, params: {time: 0.2, before: 1.0, after: -5.0}}"
    results = simulate(diagram(fmus.fmi2, start_values="{threshold: 2}", source=src))
    assert "fmi2DoStep at t=0.2 s (step 0.1 s) returned status 'discard'" in results.status
    assert "step discarded" in results.status


@pytest.mark.parametrize("status", [0, 4], ids=["ok", "fatal"])
def test_ctrl_c_during_a_step_is_an_interrupt_not_an_fmu_failure(fmus, tmp_path, status):
    """SIGINT arrives inside doStep, which then logs (the KeyboardInterrupt is raised in the
    log callback, where ctypes loses it) and returns ok, or 'fatal' as an FMU whose memory
    callback was broken would. Either way the run stops as interrupted, results kept. (In the
    run's process: the SIGINT is the FMU's own process's.)"""
    path = zip_files(tmp_path / "interrupting.fmu", fmi2_files(fmus.interrupting[status]))
    d = diagram(path, log="[f.y]", params="isolation: none")
    try:
        results = simulate(d)
    except KeyboardInterrupt:  # pragma: no cover - would otherwise stop the whole test session
        pytest.fail("the interrupt escaped the run")
    assert results.status == "interrupted at t=0.2 s", results.status
    assert results.interrupted and not results.complete
    np.testing.assert_allclose(results["f.y"][0], [0.0, 0.1, 0.2])   # the results so far
    assert "fmi2DoStep" not in results.status


# -- load-time errors ---------------------------------------------------------------------


def test_unknown_start_value_is_named_with_a_suggestion(fmus):
    msg = load_error(lambda: diagram(fmus.fmi2, start_values="{thresold: 3}"))
    assert "fmu.yaml:" in msg and "block 'f' (FMU)" in msg
    assert "unknown variable 'thresold' in start_values" in msg
    assert "did you mean 'threshold'?" in msg


@pytest.mark.parametrize("values, expected", [
    ("{y: 1.0}", "cannot set a start value for 'y'"),
    ("{z: [1, 2]}", "cannot set a start value for 'z[1]'"),
    ("{scale: 1.5}", "start value of 'scale' must be an integer"),
    ("{frozen: 3}", "start value of 'frozen' must be true or false"),
    ("{a: [1, 2]}", "start value of 'a' must have 1 entries"),
    ("{a: hello}", "start value of 'a' must be a number"),
    ("[1, 2]", "parameter 'start_values' must be a mapping"),
])
def test_bad_start_values(fmus, values, expected):
    assert expected in load_error(lambda: diagram(fmus.fmi2, start_values=values))


def test_without_a_period_the_fmus_default_step_is_the_period(fmus):
    text = f"""
time: {{t_end: 0.5 s}}
blocks:
  src: {{type: Constant, params: {{value: 1.0}}}}
  f: {{type: FMU, params: {{path: '{fmus.fmi2}'}}}}
connections: [src.y -> f.u]
log: [f.y]
"""
    d = loads_diagram(text)
    assert d.blocks["f"].period == Fraction(1, 10)  # the FMU's DefaultExperiment stepSize
    t, _ = simulate(d)["f.y"]
    np.testing.assert_allclose(t, [0.0, 0.1, 0.2, 0.3, 0.4, 0.5])


@pytest.mark.parametrize("version", [2, 3])
def test_a_fixed_internal_step_is_shown_and_not_enforced(fmus, version):
    """fixedInternalStepSize is informative (FMI 3): a period that is no multiple of it
    loads and runs, and validate says what the FMU declares."""
    path = fmus.with_fixed_step(version, "0.04", f"fixed{version}.fmu")
    d = diagram(path, period="0.1 s")
    assert d.blocks["f"].block.describe() == (f"FMI {version}.0 co-simulation FMU '{path}' "
                                              "(fixed internal step 40 ms, informative), runs in a process of its own")
    results = simulate(d)
    assert results.complete and len(results["f.y"][0]) == 11


@pytest.mark.parametrize("version", [2, 3])
def test_an_fmu_that_cannot_vary_its_step_takes_only_the_step_it_declares(fmus, version):
    """canHandleVariableCommunicationStepSize="false": the period must be its
    DefaultExperiment stepSize (0.1 s), else its fixed internal step."""
    xml = (fmus.xml2 if version == 2 else fmus.xml3).replace('canHandleVariableCommunicationStepSize="true"',
                                                               'canHandleVariableCommunicationStepSize="false"')
    path = fmus.make(f"fixed_step{version}.fmu", xml, version=version)
    msg = load_error(lambda: diagram(path, period="50 ms"))
    assert msg.startswith("fmu.yaml:5: block 'f' (FMU): the period 50 ms is not the step 100 ms of FMU '"), msg
    assert ("(its DefaultExperiment stepSize), which cannot vary its communication step "
            "(canHandleVariableCommunicationStepSize is false); use 'period: 100 ms'") in msg, msg
    assert diagram(path, period="0.1 s").blocks["f"].period == Fraction(1, 10)
    text = f"time: {{t_end: 0.5 s}}\nblocks:\n  f: {{type: FMU, params: {{path: '{path}'}}}}\n"
    assert loads_diagram(text).blocks["f"].period == Fraction(1, 10)   # the default step is the declared one
    if version == 3:
        internal = xml.replace('<DefaultExperiment startTime="0" stopTime="1" stepSize="0.1"/>', "").replace(
            "<CoSimulation ", '<CoSimulation fixedInternalStepSize="0.02" ')
        path = fmus.make("fixed_internal3.fmu", internal, version=3)
        assert "is not the step 20 ms of" in load_error(lambda: diagram(path, period="0.1 s"))
        assert diagram(path, period="20 ms").blocks["f"].period == Fraction(1, 50)


def test_a_step_the_fmu_refuses_at_run_time_fails_the_run_with_its_message(fmus, tmp_path):
    library = compile_library(tmp_path / f"internal{fmpy.sharedLibraryExtension}", "first_order_fmi2.c",
                              "fmi2_unsupported.c", defines={"INTERNAL_STEP": "0.04"})
    path = zip_files(tmp_path / "internal.fmu", fmi2_files(library))
    results = simulate(diagram(path, period="0.1 s"))
    assert results.status.startswith("failed at t=0 s: block 'f' (FMU) update: FMU '"), results.status
    assert ("fmi2DoStep at t=0 s (step 0.1 s) returned status 'error'; FMU log: [error] logStatusError: the step "
            "0.1 s is not a whole multiple of the internal step 0.04 s") in results.status, results.status
    assert simulate(diagram(path, period="0.12 s", t_end="0.36 s")).complete


def test_a_relative_path_is_resolved_against_the_diagrams_folder(fmus, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    folder = tmp_path / "project"
    (folder / "fmus").mkdir(parents=True)
    shutil.copy(fmus.fmi2, folder / "fmus" / "plant.fmu")
    text = """
time: {t_end: 0.3 s}
blocks:
  src: {type: Constant, params: {value: 1.0}}
  f: {type: FMU, period: 0.1 s, params: {path: fmus/plant.fmu}}
connections: [src.y -> f.u]
log: [f.y]
"""
    (folder / "d.yaml").write_text(text)
    assert simulate(load_diagram(folder / "d.yaml")).complete
    msg = load_error(lambda: loads_diagram(text, filename="d.yaml", base_dir=tmp_path / "elsewhere"))
    assert f"FMU file not found: looked at {tmp_path / 'elsewhere' / 'fmus' / 'plant.fmu'}" in msg
    assert "a relative path is resolved against the diagram's folder" in msg


def test_not_a_zip(fmus, tmp_path):
    bogus = tmp_path / "bogus.fmu"
    bogus.write_text("not an FMU")
    assert "is not an FMU: not a zip archive" in load_error(lambda: diagram(bogus))
    assert "is a folder" in load_error(lambda: diagram(tmp_path))


def test_no_model_description(fmus, tmp_path):
    empty = zip_files(tmp_path / "empty.fmu", {"resources/readme.txt": "hello"})
    assert "the archive has no modelDescription.xml" in load_error(lambda: diagram(empty))


def test_broken_model_description(fmus):
    truncated = fmus.make("truncated.fmu", fmus.xml2[: len(fmus.xml2) // 2])
    msg = load_error(lambda: diagram(truncated))
    assert "has a broken modelDescription.xml" in msg
    invalid = fmus.make("invalid.fmu", fmus.xml2.replace('causality="input"', 'causality="sideways"'))
    assert "has a broken modelDescription.xml" in load_error(lambda: diagram(invalid))


def test_a_model_exchange_only_fmu_is_taken_as_model_exchange(fmus):
    """An FMU with only a ModelExchange element is no longer refused for its interface: the
    check that follows (its binary, here missing) speaks."""
    xml = fmus.xml2.replace('<CoSimulation modelIdentifier="FirstOrder" '
                            'canHandleVariableCommunicationStepSize="true"/>',
                            '<ModelExchange modelIdentifier="FirstOrderME"/>')
    me = fmus.make("me_only.fmu", xml, binary=False)
    msg = load_error(lambda: diagram(me))
    assert "co-simulation" not in msg and "has no binary for this platform" in msg and "FirstOrderME" in msg, msg


def test_no_binary_for_this_platform(fmus):
    nobin = fmus.make("nobin.fmu", binary=False)
    msg = load_error(lambda: diagram(nobin))
    assert f"has no binary for this platform ({fmpy.platform}/FirstOrder" in msg
    assert "it has no binaries" in msg


def test_instantiation_failure_fails_the_run_with_the_fmu_log(fmus):
    """Only a run loads and instantiates the FMU, so only a run finds a binary that fails."""
    wrong = fmus.make("wrong_guid.fmu", fmus.xml2.replace("8c4e810f", "00000000"))
    status = simulate(diagram(wrong)).status
    assert status.startswith("failed at t=0 s: block 'f' (FMU) output: "), status
    assert "instantiating the FMU failed" in status
    assert "FMU log: [error] logStatusError: wrong FMU type or GUID {00000000" in status


def test_vector_with_a_gap(fmus):
    gap = fmus.make("gap.fmu", fmus.xml2.replace('name="z[1]"', 'name="z[3]"'))
    msg = load_error(lambda: diagram(gap))
    assert "vector 'z' must be numbered 1..n without gaps, but z[1] is missing" in msg


def test_unsafe_archive_is_refused_by_the_block(fmus, tmp_path):
    evil = zip_files(tmp_path / "evil.fmu", {"modelDescription.xml": fmus.xml2, "../evil.txt": "x"})
    msg = load_error(lambda: diagram(evil))
    assert "unsafe FMU archive" in msg and "'../evil.txt'" in msg
    assert not (tmp_path.parent / "evil.txt").exists()


def test_sizes_beyond_what_a_run_can_allocate_are_load_errors(fmus):
    """An FMI 3 array, the states and the event indicators are allocated per run: 10^9 of
    them are refused when the block is made, not a MemoryError when it runs."""
    many = fmus.make("indicators.fmu", fmus.xml2.replace('numberOfEventIndicators="0"',
                                                          'numberOfEventIndicators="4000000000"'))
    with pytest.raises(ValueError, match=r"declares 4000000000 event indicators, more than the limit of 1000000"):
        FMU(many)
    big = fmus.make("array.fmu", re.sub(r'(<Float64 name="z".*?<Dimension start=)"2"', r'\1"1000000000"',
                                        fmus.xml3, flags=re.S), version=3)
    with pytest.raises(ValueError, match=r"variable 'z' of FMU '.*' is an array of 1000000000 elements"):
        FMU(big)


def test_an_fmu_path_that_is_not_a_regular_file_is_refused_unopened(tmp_path):
    os.mkfifo(tmp_path / "pipe.fmu")
    with pytest.raises(ValueError, match=r"it is a FIFO \(named pipe\), not a regular file"):
        FMU(tmp_path / "pipe.fmu")
    with pytest.raises(ValueError, match=r"FMU '/dev/zero' cannot be read as an FMU: it is a device"):
        FMU("/dev/zero")
    with pytest.raises(ValueError, match=r"is a folder; give the path of the .fmu file"):
        FMU(tmp_path)
