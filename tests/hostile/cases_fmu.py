"""Corpus cases for FMUs: code that must not run, archives that must not be unpacked,
files that are not where they are said to be (or not files), steps and arrays too large
or small to be, settings that would only fail once a run has started, Ctrl-C inside an
FMU, and FMUs that crash, call exit() or hang (which run in processes of their own).

Most cases need no compiler: loading a diagram never loads an FMU's binary, so their
FMUs carry a few bytes in its place. The cases that run an FMU use the test FMUs of
``tests/blocks/fmu/sources``, compiled once per session (``_libraries``); without a C
compiler those cases are left out.
"""

from __future__ import annotations

import atexit
import functools
import json
import os
import re
import shutil
import subprocess
import tempfile
from pathlib import Path

from tests.blocks.fmu import build as fmu_build

from .corpus import Case

XML = (fmu_build.SOURCES / "first_order_fmi2.xml").read_text()
NOT_A_LIBRARY = b"not a shared library: a diagram's validation never loads it"


@functools.cache
def _scratch() -> Path:
    """A folder for what a case cannot carry as a file (a FIFO), removed at exit."""
    root = Path(tempfile.mkdtemp(prefix="hostile-fmu-"))
    atexit.register(shutil.rmtree, root, True)
    return root


@functools.cache
def _libraries() -> tuple[bytes, bytes, Path, bytes, bytes] | None:
    """The marker library, the library that sends itself SIGINT inside doStep (and then
    returns 'fatal'), the folder the marker library leaves its traces in, the misbehaving
    first-order library (``sources/misbehave.h``) and the plain one; None without a compiler."""
    if fmu_build.build_error():
        return None
    root = _scratch()
    (root / "markers").mkdir()
    marker = fmu_build.marker_library(root, root / "markers")
    return (marker, fmu_build.interrupting_library(root, 4), root / "markers",
            fmu_build.misbehaving_library(root, "cs2"),
            fmu_build.compile_library(root / f"plain{fmu_build.EXT}", "first_order_fmi2.c", "fmi2_unsupported.c"))


@functools.cache
def _fifo() -> str:
    """The path of a FIFO named like an FMU (a reader opening it would wait for a writer)."""
    path = _scratch() / "plant.fmu"
    os.mkfifo(path)
    return str(path)


def fmu(library: bytes = NOT_A_LIBRARY, xml: str = XML, identifier: str = "FirstOrder",
        **extra: bytes | str) -> bytes:
    """An FMI 2 FMU archive: the first-order modelDescription, ``library`` as its binary,
    and ``extra`` members (``extra`` names use ``__`` for ``/``)."""
    files = fmu_build.fmi2_files(library, xml, identifier)
    files.update({name.replace("__", "/"): data for name, data in extra.items()})
    return fmu_build.zip_bytes(files)


def traces(identifier: str) -> set[str]:
    """What the marker FMU ``identifier`` left so far: 'loaded' and/or 'instantiated'."""
    markers = _libraries()[2]
    return {p.name.rsplit(".", 1)[1] for p in markers.glob(f"{identifier}{fmu_build.EXT}.*")}


def ran(identifier: str, expected: set[str]):
    """A ``check``: the code of the marker FMU ``identifier`` left exactly ``expected``."""
    def check(folder: Path, proc: subprocess.CompletedProcess) -> None:
        assert traces(identifier) == expected, f"{identifier}: traces {traces(identifier)}, expected {expected}"
    return check


def saved_as(status: str):
    """A ``check``: the run's results were saved in ``out`` with a status that begins so."""
    def check(folder: Path, proc: subprocess.CompletedProcess) -> None:
        info = json.loads((folder / "out" / "run.json").read_text())
        assert info["status"].startswith(status), info["status"]
        assert (folder / "out" / "signals.npz").is_file()
    return check


def diagram(path: str = "plant.fmu", period: str = "0.1 s", params: str = "") -> str:
    """A diagram driving the first-order FMU ``path`` with a step."""
    return f"""\
name: fmu-case
time: {{t_end: 0.5 s}}
blocks:
  src: {{type: Step, period: 0.1 s, params: {{time: 0.2}}}}
  plant: {{type: FMU, period: {period}, params: {{path: {path}{', ' + params if params else ''}}}}}
connections:
  - src.y -> plant.u
log: [plant.y]
"""


def prints(text: str):
    """A ``check``: the command printed ``text`` on stdout."""
    def check(folder: Path, proc: subprocess.CompletedProcess) -> None:
        assert text in proc.stdout, proc.stdout
    return check


def with_step(step: str) -> str:
    """The first-order modelDescription with the DefaultExperiment stepSize ``step``."""
    return XML.replace('stepSize="0.1"', f'stepSize="{step}"')


XML3 = (fmu_build.SOURCES / "first_order_fmi3.xml").read_text()
BILLION = re.sub(r'(<Float64 name="z".*?<Dimension start=)"2"', r'\1"1000000000"', XML3, flags=re.S)
assert BILLION != XML3


def fmu3(xml: str) -> bytes:
    """An FMI 3 FMU archive of ``xml`` with a few bytes as its binary."""
    import fmpy

    return fmu_build.zip_bytes({"modelDescription.xml": xml,
                                f"binaries/{fmpy.platform_tuple}/FirstOrder3{fmu_build.EXT}": NOT_A_LIBRARY})


FIXED_STEP = XML.replace('canHandleVariableCommunicationStepSize="true"', 'canHandleVariableCommunicationStepSize="false"')
BOMB = {"resources__zeros.bin": b"\0" * (8 << 20)}  # 8 MiB that deflate about 1000 times

CASES = [
    Case("fmu-missing-names-the-path-and-the-diagram-folder", ("validate", "sub/d.yaml"), 2,
         r"sub/d\.yaml:5: block 'plant' \(FMU\): FMU file not found: looked at /\S+/sub/fmus/plant\.fmu "
         r"\(in a diagram, a relative path is resolved against the diagram's folder",
         files={"sub/d.yaml": diagram("fmus/plant.fmu"), "fmus/plant.fmu": fmu()}),
    Case("fmu-period-off-the-step-of-a-fixed-step-fmu-fails-validate", ("validate", "d.yaml"), 2,
         r"d\.yaml:5: block 'plant' \(FMU\): the period 50 ms is not the step 100 ms of FMU 'plant\.fmu' "
         r"\(its DefaultExperiment stepSize\), which cannot vary its communication step",
         files={"d.yaml": diagram(period="50 ms"), "plant.fmu": fmu(xml=FIXED_STEP)}),
    Case("fmu-zip-bomb-refused-by-validate", ("validate", "d.yaml"), 2,
         r"d\.yaml:5: block 'plant' \(FMU\): unsafe FMU archive, not extracted: .*'resources/zeros\.bin' "
         r"inflates from \d+ to 8388608 bytes or more, more than 200 times",
         files={"d.yaml": diagram(), "plant.fmu": fmu(**BOMB)}),
    Case("fmu-zip-bomb-refused-by-fmu-info", ("fmu", "info", "plant.fmu"), 2,
         r"^hierhand: error: unsafe FMU archive, not extracted: .*more than 200 times",
         files={"plant.fmu": fmu(**BOMB)}),
    Case("fmu-model-description-bomb-refused-by-fmu-info", ("fmu", "info", "plant.fmu"), 2,
         r"'modelDescription\.xml' inflates .* more than 200 times",
         files={"plant.fmu": fmu(xml=XML.replace("<ModelVariables>", " " * (8 << 20) + "<ModelVariables>"))}),
    Case("fmu-member-escaping-the-folder-refused", ("validate", "d.yaml"), 2,
         r"unsafe FMU archive, not extracted: .*member '\.\./\.\./evil\.txt' has a '\.\.' component",
         files={"d.yaml": diagram(), "plant.fmu": fmu(**{"..__..__evil.txt": "x"})},
         absent=("../evil.txt", "../../evil.txt")),
    Case("fmu-info-not-a-zip", ("fmu", "info", "plant.fmu"), 2, r"not a readable zip archive",
         files={"plant.fmu": "just text"}),
    Case("fmu-info-reads-a-binary-it-never-loads", ("fmu", "info", "plant.fmu"), 0, "",
         files={"plant.fmu": fmu()}),
    Case("fmu-path-naming-a-fifo-is-refused-unopened", ("validate", "d.yaml"), 2,
         r"d\.yaml:5: block 'plant' \(FMU\): FMU '.*plant\.fmu' cannot be read as an FMU: it is a FIFO \(named "
         r"pipe\), not a regular file", files={"d.yaml": diagram(_fifo())}),
    Case("fmu-info-of-a-fifo-is-refused-unopened", ("fmu", "info", _fifo()), 2,
         r"^hierhand: error: FMU '.*' cannot be read as an FMU: it is a FIFO"),
    Case("fmu-path-naming-dev-zero-is-refused-unread", ("validate", "d.yaml"), 2,
         r"d\.yaml:5: block 'plant' \(FMU\): FMU '/dev/zero' cannot be read as an FMU: it is a device, not a "
         r"regular file", files={"d.yaml": diagram("/dev/zero")}),
    Case("fmu-default-step-1e-308-is-out-of-range", ("validate", "d.yaml"), 2,
         r"d\.yaml:5: block 'plant' \(FMU\): an FMU block needs a period, .* its DefaultExperiment stepSize "
         r"'1e-308' is out of range \(1e-12 s to 1e9 s\)",
         files={"d.yaml": diagram().replace("period: 0.1 s, params: {path", "params: {path"),
                "plant.fmu": fmu(xml=with_step("1e-308"))}),
    Case("fmu-default-step-1e308-is-out-of-range", ("run", "d.yaml", "-o", "out"), 2,
         r"d\.yaml:5: block 'plant' \(FMU\): .*stepSize '1e308' is out of range",
         files={"d.yaml": diagram().replace("period: 0.1 s, params: {path", "params: {path"),
                "plant.fmu": fmu(xml=with_step("1e308"))}, absent=("out",)),
    Case("fmu-default-step-of-a-billion-digits-exponent-is-not-a-number-of-seconds", ("validate", "d.yaml"), 2,
         r"stepSize '1e999999999' is not a positive finite number of seconds",
         files={"d.yaml": diagram().replace("period: 0.1 s, params: {path", "params: {path"),
                "plant.fmu": fmu(xml=with_step("1e999999999"))}),
    Case("fmu-info-shows-an-unusable-step-as-such", ("fmu", "info", "plant.fmu"), 0, "",
         files={"plant.fmu": fmu(xml=with_step("1e-308"))},
         check=prints("step 1e-308 (not usable: out of range (1e-12 s to 1e9 s))")),
    Case("fmu-fmi3-array-of-a-billion-elements-is-refused", ("validate", "d.yaml"), 2,
         r"d\.yaml:5: block 'plant' \(FMU\): variable 'z' of FMU 'plant\.fmu' is an array of 1000000000 "
         r"elements, more than the limit of 1000000",
         files={"d.yaml": diagram(), "plant.fmu": fmu3(BILLION)}),
]



def _running_cases() -> list[Case]:
    """validate, graph and fmu info read the FMU without running its code; run runs it;
    Ctrl-C inside the FMU's doStep (in the run's process) stops the run as interrupted
    (exit 130), results saved; an FMU that crashes, calls exit() or hangs (in a process of
    its own, the default for FMUs of other tools) fails the run (exit 1), results saved."""
    if _libraries() is None:
        return []
    marker, interrupting, _, misbehaving, plain = _libraries()
    cases = []
    for name, argv in (("validate", ("validate", "d.yaml")), ("graph", ("graph", "d.yaml")),
                       ("graph-dot", ("graph", "d.yaml", "-o", "g.dot")), ("info", ("fmu", "info", "plant.fmu"))):
        ident = f"Traced_{name.replace('-', '_')}"
        cases.append(Case(f"fmu-{name}-does-not-run-fmu-code", argv, 0, "",
                          files={"d.yaml": diagram(), "plant.fmu": fmu(marker, identifier=ident)},
                          check=ran(ident, set())))
    cases.append(Case("fmu-run-runs-fmu-code", ("run", "d.yaml", "-o", "out", "-q"), 0, "",
                      files={"d.yaml": diagram(), "plant.fmu": fmu(marker, identifier="Traced_run")},
                      check=ran("Traced_run", {"loaded", "instantiated"})))
    cases.append(Case("fmu-ctrl-c-in-do-step-is-an-interrupt", ("run", "d.yaml", "-o", "out", "-q"), 130,
                      r"interrupted at t=0\.2 s by SIGINT",
                      files={"d.yaml": diagram(params="isolation: none"), "plant.fmu": fmu(interrupting)},
                      check=saved_as("interrupted at t=0.2 s by SIGINT")))
    run = ("run", "d.yaml", "-o", "out", "-q")
    failed = r"hierhand: d\.yaml: failed at t={t} s: block 'plant' \(FMU\) {phase}: FMU 'plant\.fmu' "
    for name, instructions, t, phase, message in (
            ("segfault-in-do-step", "fmi2DoStep segv 0.2", "0.2", "update",
             r"crashed in fmi2DoStep \(the step from t=0\.2 s to 0\.3 s\): SIGSEGV \(a segmentation fault"),
            ("exit-0-in-do-step", "fmi2DoStep exit0 0.2", "0.2", "update",
             r"called exit\(0\) in fmi2DoStep \(the step from t=0\.2 s to 0\.3 s\), which ended the process"),
            ("abort-in-instantiate", "fmi2Instantiate abort", "0", "output",
             r"crashed in fmi2Instantiate \(instantiating it\): SIGABRT \(an abort"),
            ("stack-overflow-in-exit-initialization", "fmi2ExitInitializationMode overflow", "0", "output",
             r"crashed in fmi2ExitInitializationMode \(initialising it at t=0 s\): SIGSEGV")):
        cases.append(Case(f"fmu-{name}-fails-the-run-with-its-results", run, 1,
                          failed.format(t=re.escape(t), phase=phase) + message,
                          files={"d.yaml": diagram(), "plant.fmu": fmu(misbehaving, **{
                              "resources__misbehave.txt": instructions})},
                          check=saved_as(f"failed at t={t} s: block 'plant' (FMU)")))
    cases.append(Case("fmu-hang-in-do-step-fails-the-run-after-its-call-timeout", run, 1,
                      failed.format(t="0\\.3", phase="update")[:-1] + r": fmi2DoStep \(the step from t=0\.3 s to 0\.4 s\) "
                      r"did not return within 1 s, so the FMU was stopped .*\(hint: if the FMU needs longer for one "
                      r"call, raise the block's 'call_timeout'",
                      files={"d.yaml": diagram(params="call_timeout: 1 s"),
                             "plant.fmu": fmu(misbehaving, **{"resources__misbehave.txt": "fmi2DoStep hang 0.3"})},
                      check=saved_as("failed at t=0.3 s: block 'plant' (FMU)")))
    cases.append(Case("fmu-truncated-binary-is-a-bus-error-that-fails-the-run", run, 1,
                      failed.format(t="0", phase="output") + r"crashed in loading its binary \(instantiating it\): "
                      r"SIGBUS \(a bus error: e\.g\. a truncated or changed binary file\)",
                      files={"d.yaml": diagram(), "plant.fmu": fmu(plain[:len(plain) // 2])},
                      check=saved_as("failed at t=0 s: block 'plant' (FMU)")))
    for name, instructions, message in (
            ("crash-in-terminate", "fmi2Terminate segv",
             r"crashed in fmi2Terminate \(terminating it after its run\): SIGSEGV"),
            ("crash-in-free-instance", "fmi2FreeInstance segv",
             r"crashed in fmi2FreeInstance \(freeing it after its run\): SIGSEGV"),
            ("exit-in-free-instance", "fmi2FreeInstance exit0",
             r"called exit\(0\) in fmi2FreeInstance \(freeing it after its run\)")):
        cases.append(Case(f"fmu-{name}-fails-the-run-at-its-end", run, 1,
                          r"failed at t=0\.5 s: block 'plant' \(FMU\) finish: FMU 'plant\.fmu' " + message,
                          files={"d.yaml": diagram(), "plant.fmu": fmu(misbehaving, **{
                              "resources__misbehave.txt": instructions})},
                          check=saved_as("failed at t=0.5 s: block 'plant' (FMU) finish")))
    return cases


CASES += _running_cases()
