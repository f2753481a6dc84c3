"""FMUs in processes of their own ('isolation: process', blocks/fmu/isolation/client.py, host.py).

An isolated FMU gives the samples it gives in the run's process, to the last bit, on every
path (the steady step in C on both sides, the Python paths, model exchange). An FMU that
crashes, calls exit() or hangs in any of its calls fails the run there with a message that
names the call, the time and the signal, exit code or timeout, and the results so far are
kept; one that does so in terminate or freeInstance (at the run's end) fails the run at its
end time, all its samples kept. The misbehaving FMUs are ``sources/misbehave.h``'s: one library per kind,
told what to do by a file in the FMU's resources.
"""

from __future__ import annotations

import gc
import logging
import multiprocessing
import re
import threading

import numpy as np
import pytest

from blocks import DiagramError, Results, loads_diagram, simulate
from blocks.fmu import FMU
from blocks.fmu.model import PROCESS_ISOLATION

fmpy = pytest.importorskip("fmpy")

from .build import (  # noqa: E402
    build_error,
    fmi2_files,
    me_fmu,
    misbehaving_fmu,
    typed_fmu,
    zip_files,
)

pytestmark = pytest.mark.skipif(not PROCESS_ISOLATION, reason="FMUs run in processes of their own only on Linux")

HANG_TIMEOUT = "1 s"
"""The call_timeout of the hanging FMUs (which never return; far above what any other call takes)."""


OUTPUT = {"cs2": "f.y", "cs3": "f.y", "me2": "f.x"}
"""The output each kind of misbehaving FMU logs."""


def diagram(path, kind: str = "cs2", params: str = "", t_end: str = "0.5 s", log: str | None = None):
    """The FMU ``path`` (of the misbehaving ``kind``, or one with the same ports) driven by a
    step at 0.2 s, every 0.1 s."""
    log = log or f"[{OUTPUT[kind]}]"
    return loads_diagram(f"""
time: {{t_end: {t_end}}}
blocks:
  src: {{type: Step, period: 0.1 s, params: {{time: 0.2}}}}
  f: {{type: FMU, period: 0.1 s, params: {{path: '{path}'{', ' + params if params else ''}}}}}
connections: [src.y -> f.u]
log: {log}
""", filename="isolated.yaml")


def same(a: Results, b: Results) -> None:
    assert a.status == b.status and list(a) == list(b)
    for name in a:
        assert np.array_equal(a[name][0], b[name][0]) and np.array_equal(a[name][1], b[name][1]), name


def both(path, params: str = "", **kwargs) -> tuple[Results, Results]:
    """The diagram of ``path`` run with the FMU in the run's process and in its own."""
    inside = simulate(diagram(path, params=", ".join(filter(None, [params, "isolation: none"])), **kwargs))
    isolated = simulate(diagram(path, params=", ".join(filter(None, [params, "isolation: process"])), **kwargs))
    return inside, isolated


# -- the same results -------------------------------------------------------------------------


@pytest.mark.parametrize("version", [2, 3])
def test_an_isolated_co_simulation_fmu_gives_the_samples_of_the_run_process(fmus, version, monkeypatch):
    """FMI 2's first-order FMU steps in C on both sides, FMI 3's (a Float32 port) in Python;
    and both again with the block's kernel off (the Python path of the run's side)."""
    path = fmus.fmi2 if version == 2 else fmus.fmi3
    log = "[f.y, f.z]" if version == 2 else "[f.y, f.z, f.yf]"
    inside, isolated = both(path, "start_values: {a: 0.3, b: 0.7}", t_end="2 s", log=log)
    assert isolated.complete
    same(inside, isolated)
    monkeypatch.setattr(FMU, "kernel", lambda self: None)
    same(inside, simulate(diagram(path, params="start_values: {a: 0.3, b: 0.7}, isolation: process",
                                  t_end="2 s", log=log)))


@pytest.mark.parametrize("fmi", [2, 3])
def test_an_isolated_fmu_with_ports_of_every_type_gives_the_same_samples(tmp_path, fmi):
    if build_error():
        pytest.skip(build_error())
    path = typed_fmu(tmp_path, fmi, only="CoSimulation")
    d = lambda isolation: loads_diagram(f"""
time: {{t_end: 1 s}}
blocks:
  fmu: {{type: FMU, period: 0.1 s, params: {{path: '{path}', isolation: {isolation}}}}}
log: all
""")
    inside, isolated = simulate(d("none")), simulate(d("process"))
    same(inside, isolated)
    assert inside.ended_by == isolated.ended_by


@pytest.mark.parametrize("model", ["linear", "bouncing", "stair"])
@pytest.mark.parametrize("solver", ["cvode", "euler"])
def test_an_isolated_model_exchange_fmu_gives_the_same_samples(tmp_path, model, solver):
    """The integration runs in the FMU's process, events and event iteration included."""
    if build_error():
        pytest.skip(build_error())
    path = me_fmu(tmp_path, model, 2)
    params = f"solver: {solver}" + (", substep: 10 ms" if solver == "euler" else "")
    text = lambda isolation: f"""
time: {{t_end: 2 s}}
blocks:
  f: {{type: FMU, period: 0.1 s, params: {{path: '{path}', {params}, isolation: {isolation}}}}}
log: all
"""
    if model == "linear":
        text = lambda isolation, base=text: base(isolation).replace(
            "log: all", "  src: {type: Step, period: 0.1 s, params: {time: 0.3}}\nconnections: [src.y -> f.u]\nlog: all")
    same(simulate(loads_diagram(text("none"))), simulate(loads_diagram(text("process"))))


def test_runs_in_threads_each_have_their_own_isolated_instance(fmus):
    d = diagram(fmus.fmi2, params="isolation: process", t_end="3 s")
    reference = simulate(d)
    results: list[Results] = []
    threads = [threading.Thread(target=lambda: results.append(simulate(d))) for _ in range(3)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert len(results) == 3
    for r in results:
        same(reference, r)


def _run_in_fork(path, queue) -> None:
    queue.put(simulate(diagram(path, params="isolation: process")).info["status"])


def test_a_forked_process_runs_its_own_fmu_processes(fmus):
    """A fork of a process whose block holds an idle isolated instance (a sweep's local
    runner) makes instances of its own; the parent's stays the parent's."""
    d = diagram(fmus.fmi2, params="isolation: process")
    first = simulate(d)
    context = multiprocessing.get_context("fork")
    queue = context.Queue()
    child = context.Process(target=_run_in_fork, args=(fmus.fmi2, queue))
    child.start()
    assert queue.get(timeout=120) == "complete"
    child.join(timeout=120)
    assert child.exitcode == 0
    same(first, simulate(d))


# -- where an FMU runs --------------------------------------------------------------------------


def test_fmus_of_other_tools_run_isolated_and_this_projects_exports_in_the_run_process(fmus):
    assert FMU(fmus.fmi2).isolation == "process"
    ours = fmus.make("ours.fmu", fmus.xml2.replace('generationTool="tests/blocks/fmu"', 'generationTool="hierhand 0.1.0"'))
    assert FMU(ours).isolation == "none" and FMU(ours, isolation="process").isolation == "process"
    assert FMU(fmus.fmi2, isolation="none").isolation == "none"
    assert "runs in a process of its own" in FMU(fmus.fmi2).describe()
    assert "runs in the run's process" in FMU(ours).describe()


@pytest.mark.parametrize("timeout, seconds", [("1 min", 60.0), ("0.5 h", 1800.0), ("1 day", 86400.0)])
def test_a_call_timeout_is_read_in_any_unit_of_time(fmus, timeout, seconds):
    assert diagram(fmus.fmi2, params=f"call_timeout: {timeout}").blocks["f"].block._model.timeout == seconds


@pytest.mark.parametrize("params, message", [
    ("isolation: sandbox", r"parameter 'isolation' must be one of process, none, got 'sandbox'"),
    ("isolation: none, call_timeout: 5 s", r"parameter 'call_timeout' is for FMUs that run in a process of their own"),
    ("call_timeout: soon", r"parameter 'call_timeout': cannot read 'soon' as a duration"),
    ("call_timeout: -1 s", r"parameter 'call_timeout' must be positive"),
])
def test_isolation_parameters_are_checked_at_load_time(fmus, params, message):
    with pytest.raises(DiagramError, match=r"isolated\.yaml:5: block 'f' \(FMU\): " + message):
        diagram(fmus.fmi2, params=params)


# -- an FMU that kills its process ------------------------------------------------------------

CRASHES = [
    # kind, call, how, from, the phase and time the run fails at, rows logged
    ("cs2", "fmi2Instantiate", "segv", 0, "output", 0, 0),
    ("cs2", "fmi2SetupExperiment", "abort", 0, "output", 0, 0),
    ("cs2", "fmi2EnterInitializationMode", "exit3", 0, "output", 0, 0),
    ("cs2", "fmi2ExitInitializationMode", "overflow", 0, "output", 0, 0),
    ("cs2", "fmi2SetReal", "exit0", 0.2, "update", 0.2, 3),
    ("cs2", "fmi2DoStep", "segv", 0.2, "update", 0.2, 3),
    ("cs2", "fmi2DoStep", "abort", 0.2, "update", 0.2, 3),
    ("cs2", "fmi2DoStep", "exit3", 0.2, "update", 0.2, 3),
    ("cs2", "fmi2DoStep", "exit0", 0.2, "update", 0.2, 3),
    ("cs2", "fmi2DoStep", "overflow", 0.2, "update", 0.2, 3),
    ("cs2", "fmi2GetReal", "segv", 0.3, "update", 0.2, 3),
    ("cs3", "fmi3InstantiateCoSimulation", "abort", 0, "output", 0, 0),
    ("cs3", "fmi3DoStep", "segv", 0.2, "update", 0.2, 3),
    ("cs3", "fmi3GetFloat64", "exit3", 0.3, "update", 0.2, 3),
    ("me2", "fmi2GetDerivatives", "segv", 0.25, "update", 0.2, 3),
    ("me2", "fmi2SetTime", "abort", 0.25, "update", 0.2, 3),
    ("me2", "fmi2NewDiscreteStates", "exit0", 0, "output", 0, 0),
]
OUTCOMES = {
    "segv": r"crashed in {call} \({during}\): SIGSEGV \(a segmentation fault: an invalid memory access, or a stack "
            r"overflow\) ended the process that ran it",
    "overflow": r"crashed in {call} \({during}\): SIGSEGV \(a segmentation fault: an invalid memory access, or a "
                r"stack overflow\) ended the process that ran it",
    "abort": r"crashed in {call} \({during}\): SIGABRT \(an abort: e\.g\. a failed assertion in the FMU\) ended "
             r"the process that ran it",
    "exit3": r"called exit\(3\) in {call} \({during}\), which ended the process that ran it \(an FMU must return "
             r"an error status instead\)",
    "exit0": r"called exit\(0\) in {call} \({during}\), which ended the process that ran it",
}


def _during(phase: str, t: float, call: str) -> str:
    if call.startswith("fmi2Instantiate") or call.startswith("fmi3Instantiate"):
        return "instantiating it"
    if phase == "output":
        return r"initialising it at t=0 s"
    return rf"the step from t={t:g} s to {t + 0.1:g} s"


@pytest.mark.parametrize("kind, call, how, start, phase, t, rows", CRASHES,
                         ids=[f"{c[1]}-{c[2]}" for c in CRASHES])
def test_an_fmu_that_kills_its_process_fails_the_run_naming_the_call(tmp_path, misbehaving, kind, call, how, start,
                                                                       phase, t, rows):
    path = misbehaving_fmu(tmp_path / "bad.fmu", kind, misbehaving[kind], f"{call} {how} {start}")
    d = diagram(path, kind, params="solver: euler" if kind == "me2" else "")
    results = simulate(d)
    expected = (rf"failed at t={t:g} s: block 'f' \(FMU\) {phase}: FMU '{re.escape(str(path))}' "
                + OUTCOMES[how].format(call=call, during=_during(phase, t, call)))
    assert re.match(expected, results.status), results.status
    assert len(results[OUTPUT[kind]][0]) == rows                 # the results so far
    assert simulate(d).status == results.status                  # a new process for the next run


def test_a_crash_inside_cvode_names_the_call_cvode_made(tmp_path, misbehaving):
    """CVode calls the FMU from its right-hand side (fmu_me_integration.c), which traces the call too."""
    path = misbehaving_fmu(tmp_path / "bad.fmu", "me2", misbehaving["me2"], "fmi2GetDerivatives abort 0.25")
    results = simulate(diagram(path, "me2", params="solver: cvode"))
    assert re.match(r"failed at t=0\.[12] s: block 'f' \(FMU\) update: FMU '.*' crashed in fmi2GetDerivatives \(the "
                    r"step from t=0\.[12] s to 0\.[23] s\): SIGABRT", results.status), results.status


def test_a_crash_on_the_python_path_is_the_same_failure(tmp_path, misbehaving, monkeypatch):
    path = misbehaving_fmu(tmp_path / "bad.fmu", "cs2", misbehaving["cs2"], "fmi2DoStep segv 0.2")
    compiled = simulate(diagram(path))
    monkeypatch.setattr(FMU, "kernel", lambda self: None)
    same(compiled, simulate(diagram(path)))


def test_a_truncated_binary_is_a_bus_error_in_loading(tmp_path, fmus):
    """The loader maps the library's file beyond its end: SIGBUS in the FMU's process."""
    cut = fmus.lib2[:len(fmus.lib2) // 2]
    path = zip_files(tmp_path / "cut.fmu", fmi2_files(cut))
    results = simulate(diagram(path))
    assert re.match(r"failed at t=0 s: block 'f' \(FMU\) output: FMU '.*' crashed in loading its binary "
                    r"\(instantiating it\): SIGBUS \(a bus error: e\.g\. a truncated or changed binary file\)",
                    results.status), results.status


# -- an FMU that hangs ----------------------------------------------------------------------------

HANGS = [
    ("cs2", "fmi2Instantiate", 0, "output", "instantiating it"),
    ("cs2", "fmi2ExitInitializationMode", 0, "output", "initialising it at t=0 s"),
    ("cs2", "fmi2DoStep", 0.3, "update", "the step from t=0.3 s to 0.4 s"),
    ("cs3", "fmi3DoStep", 0.3, "update", "the step from t=0.3 s to 0.4 s"),
    ("me2", "fmi2GetDerivatives", 0.35, "update", "the step from t=0.3 s to 0.4 s"),
]


@pytest.mark.parametrize("kind, call, start, phase, during", HANGS, ids=[h[1] for h in HANGS])
def test_an_fmu_that_hangs_fails_the_run_after_the_call_timeout(tmp_path, misbehaving, kind, call, start, phase,
                                                                 during):
    path = misbehaving_fmu(tmp_path / "hangs.fmu", kind, misbehaving[kind], f"{call} hang {start}")
    params = f"call_timeout: {HANG_TIMEOUT}" + (", solver: euler" if kind == "me2" else "")
    results = simulate(diagram(path, kind, params=params))
    t = 0 if phase == "output" else 0.3
    assert results.status == (f"failed at t={t:g} s: block 'f' (FMU) {phase}: FMU '{path}': {call} ({during}) did "
                              "not return within 1 s, so the FMU was stopped (the FMU logged no messages) (hint: if "
                              "the FMU needs longer for one call, raise the block's 'call_timeout', e.g. "
                              "'call_timeout: 1 h')"), results.status
    assert len(results[OUTPUT[kind]][0]) == (0 if phase == "output" else 4)


# -- after the run ------------------------------------------------------------------------------


@pytest.mark.parametrize("how, message", [
    ("segv", "crashed in fmi2Terminate (terminating it after its run): SIGSEGV"),
    ("exit3", "called exit(3) in fmi2Terminate (terminating it after its run)"),
])
def test_a_crash_in_terminate_fails_the_run_at_its_end_with_its_results(tmp_path, misbehaving, how, message):
    """terminate runs when the run gives its instance back, at its end and before its
    results are made (``Block.finish``): a crash there fails the run at its end time,
    naming the call, and every sample is kept."""
    path = misbehaving_fmu(tmp_path / "late.fmu", "cs2", misbehaving["cs2"], f"fmi2Terminate {how}")
    results = simulate(diagram(path))
    assert results.status.startswith("failed at t=0.5 s: block 'f' (FMU) finish: "), results.status
    assert message in results.status, results.status
    assert len(results["f.y"][0]) == 6


@pytest.mark.parametrize("kind, call, how, message", [
    ("cs2", "fmi2FreeInstance", "segv", "crashed in fmi2FreeInstance (freeing it after its run): SIGSEGV"),
    ("cs2", "fmi2FreeInstance", "exit3", "called exit(3) in fmi2FreeInstance (freeing it after its run)"),
    ("cs3", "fmi3FreeInstance", "abort", "crashed in fmi3FreeInstance (freeing it after its run): SIGABRT"),
], ids=["fmi2-segv", "fmi2-exit3", "fmi3-abort"])
def test_a_crash_in_free_instance_fails_the_run_at_its_end_with_its_results(tmp_path, misbehaving, kind, call, how,
                                                                            message):
    """freeInstance runs at the run's end too, after terminate, in the FMU's process: a
    crash there fails the run it ends, every sample kept; the next run starts a new process."""
    path = misbehaving_fmu(tmp_path / "late.fmu", kind, misbehaving[kind], f"{call} {how}")
    d = diagram(path, kind)
    results = simulate(d)
    assert results.status.startswith("failed at t=0.5 s: block 'f' (FMU) finish: "), results.status
    assert message in results.status, results.status
    assert len(results["f.y"][0]) == 6
    assert simulate(d).status == results.status


def _host_pids(d) -> list[int]:
    """The processes of the FMU instances the block ``f`` of ``d`` keeps for its next runs."""
    return [inst.pid for inst in d.blocks["f"].block._model.idle]


@pytest.mark.parametrize("kind", ["cs2", "cs3", "me2"])
def test_the_runs_of_a_diagram_share_the_fmus_process_each_with_a_new_instance(tmp_path, misbehaving, fmus, kind):
    """Each run ends by freeing its FMU instance, yet the process that ran it (the FMU's
    binary loaded) serves the next run, which instantiates the FMU there again: the same
    samples every time, and one process for all."""
    path = misbehaving_fmu(tmp_path / "tame.fmu", kind, misbehaving[kind])
    d = diagram(path, kind, params="solver: euler" if kind == "me2" else "")
    first = simulate(d)
    gc.collect()
    pids = _host_pids(d)
    for _ in range(2):
        same(first, simulate(d))
        gc.collect()
        assert _host_pids(d) == pids and len(pids) == 1
    d.blocks["f"].block.close()
    assert first.complete and len(first[OUTPUT[kind]][0]) == 6


def test_a_well_behaved_misbehaving_fmu_is_the_first_order_fmu(tmp_path, misbehaving, fmus):
    """Without instructions the misbehaving library is the plain first-order FMU."""
    path = misbehaving_fmu(tmp_path / "tame.fmu", "cs2", misbehaving["cs2"])
    same(simulate(diagram(fmus.fmi2, params="isolation: none")), simulate(diagram(path)))



def _kill_the_launcher_between_runs(path, queue) -> None:
    from blocks.fmu.isolation.launcher import Launcher

    d = diagram(path, params="isolation: process")
    first = simulate(d)
    gc.collect()                                                  # the run's instance back in the pool
    launcher = Launcher.here().process
    launcher.kill()
    launcher.wait(timeout=60)
    again = simulate(d)
    queue.put((first.info["status"], again.info["status"], Launcher.here().process.pid != launcher.pid,
               [first[name][1].tolist() == again[name][1].tolist() for name in first]))


def test_runs_go_on_when_the_fmu_processes_were_killed_between_them(fmus):
    """Another program kills the launcher (and with it the idle FMU process of the block's
    pool): the next run starts both again. (In a process of its own, whose launcher is its
    own: this one's serves the other tests.)"""
    context = multiprocessing.get_context("fork")
    queue = context.Queue()
    child = context.Process(target=_kill_the_launcher_between_runs, args=(fmus.fmi2, queue))
    child.start()
    first, again, restarted, equal = queue.get(timeout=120)
    child.join(timeout=120)
    assert first == again == "complete" and restarted and all(equal)
