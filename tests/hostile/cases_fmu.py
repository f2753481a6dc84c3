"""Corpus cases for FMUs: code that must not run, archives that must not be unpacked,
files that are not where they are said to be, settings that would only fail once a run
has started, and Ctrl-C inside an FMU.

Most cases need no compiler: loading a diagram never loads an FMU's binary, so their
FMUs carry a few bytes in its place. The cases that run an FMU use the test FMUs of
``tests/blocks/fmu/sources``, compiled once per session (``_libraries``); without a C
compiler those cases are left out.
"""

from __future__ import annotations

import atexit
import functools
import json
import shutil
import subprocess
import tempfile
from pathlib import Path

from tests.blocks.fmu import build as fmu_build

from .corpus import Case

XML = (fmu_build.SOURCES / "first_order_fmi2.xml").read_text()
NOT_A_LIBRARY = b"not a shared library: a diagram's validation never loads it"


@functools.cache
def _libraries() -> tuple[bytes, bytes, Path] | None:
    """The marker library, the library that sends itself SIGINT inside doStep (and then
    returns 'fatal'), and the folder the marker library leaves its traces in; None without
    a compiler."""
    if fmu_build.build_error():
        return None
    root = Path(tempfile.mkdtemp(prefix="hostile-fmu-"))
    atexit.register(shutil.rmtree, root, True)
    (root / "markers").mkdir()
    marker = fmu_build.marker_library(root, root / "markers")
    return marker, fmu_build.interrupting_library(root, 4), root / "markers"


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
    """A ``check``: the run's results were saved in ``out`` with this status."""
    def check(folder: Path, proc: subprocess.CompletedProcess) -> None:
        info = json.loads((folder / "out" / "run.json").read_text())
        assert info["status"] == status, info["status"]
        assert (folder / "out" / "signals.npz").is_file()
    return check


def diagram(path: str = "plant.fmu", period: str = "0.1 s") -> str:
    """A diagram driving the first-order FMU ``path`` with a step."""
    return f"""\
name: fmu-case
time: {{t_end: 0.5 s}}
blocks:
  src: {{type: Step, period: 0.1 s, params: {{time: 0.2}}}}
  plant: {{type: FMU, period: {period}, params: {{path: {path}}}}}
connections:
  - src.y -> plant.u
log: [plant.y]
"""


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
]


def _running_cases() -> list[Case]:
    """validate, graph and fmu info read the FMU without running its code; run runs it;
    Ctrl-C inside the FMU's doStep stops the run as interrupted (exit 130), results saved."""
    if _libraries() is None:
        return []
    marker, interrupting, _ = _libraries()
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
                      r"interrupted at t=0\.2 s by SIGINT", files={"d.yaml": diagram(), "plant.fmu": fmu(interrupting)},
                      check=saved_as("interrupted at t=0.2 s by SIGINT")))
    return cases


CASES += _running_cases()
