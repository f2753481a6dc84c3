"""Corpus cases of hardening round 2's last classes: names that an ASCII terminal or file
system cannot show or hold, files that cannot be read where an FMU or an SSP's XML is
read (a FIFO, /proc's memory file), ``plot -o`` naming a folder, FMU steps and arrays too
large for ``fmu info``, and SSPs from hostile hands: members that leave the package or
inflate, a FIFO as the SSD, XML entities (the billion laughs, an external file) and nesting
deeper than any system needs. The XML is parsed without entity expansion, DTDs or network
(``blocks/ssp/xml.py``)."""

from __future__ import annotations

import functools
import json
import os
import subprocess
from pathlib import Path

from tests.blocks.ssp.conftest import ssd
from tests.blocks.ssp.test_import import component

from .cases_fmu import BILLION, _scratch, diagram, fmu, fmu3, prints, with_step
from .corpus import Case

RAMP = "name: Prüfstand\ntime: {t_end: 10 ms}\nblocks:\n  ramp: {type: Ramp, period: 1 ms, params: {slope: 1.0}}\n" \
       "log: [ramp.y]\n"
ASCII_LOCALE = {"LC_ALL": "C", "LANG": "C", "PYTHONUTF8": "0", "PYTHONCOERCECLOCALE": "0"}
"""A C locale in which Python keeps ASCII file names (no UTF-8 mode, no locale coercion)."""

SSD = ssd(f"<ssd:Elements>{component('a')}</ssd:Elements>")
LAUGHS = ('<?xml version="1.0"?>\n<!DOCTYPE lolz [<!ENTITY lol0 "lol">'
          + "".join(f'<!ENTITY lol{i} "{f"&lol{i - 1};" * 10}">' for i in range(1, 10)) + ']>\n'
          + SSD.split("\n", 1)[1].replace('name="root"', 'name="&lol9;"'))
EXTERNAL = ('<?xml version="1.0"?>\n<!DOCTYPE x [<!ENTITY ext SYSTEM "file:///etc/passwd">]>\n'
            + SSD.split("\n", 1)[1].replace('name="root"', 'name="&ext;"'))
DEEP = SSD.replace('<ssd:System name="root">',
                   '<ssd:System name="root"><ssd:Annotations>' + "<x>" * 100_000 + "</x>" * 100_000
                   + "</ssd:Annotations>")


def ssp(ssd_text: str = SSD, **members: bytes | str) -> bytes:
    """An SSP archive of ``ssd_text`` and ``members`` (``__`` for ``/`` in their names), with a
    few bytes as its FMU (these cases never load it)."""
    from tests.blocks.fmu.build import zip_bytes

    return zip_bytes({"SystemStructure.ssd": ssd_text, "resources/fo.fmu": fmu(),
                      **{name.replace("__", "/"): data for name, data in members.items()}})


@functools.cache
def _fifo_ssp() -> str:
    """An SSP folder whose SystemStructure.ssd is a FIFO, and whose parameter file is one too."""
    folder = _scratch() / "fifo-ssp"
    (folder / "resources").mkdir(parents=True)
    os.mkfifo(folder / "SystemStructure.ssd")
    return str(folder)


@functools.cache
def _fifo_parameters() -> str:
    """An SSP folder whose component's parameter file (resources/p.ssv) is a FIFO."""
    folder = _scratch() / "fifo-ssv"
    (folder / "resources").mkdir(parents=True)
    binding = '<ssd:ParameterBindings><ssd:ParameterBinding source="resources/p.ssv"/></ssd:ParameterBindings>'
    (folder / "SystemStructure.ssd").write_text(ssd(f"<ssd:Elements>{component('a', extra=binding)}</ssd:Elements>"))
    (folder / "resources" / "fo.fmu").write_bytes(fmu())
    os.mkfifo(folder / "resources" / "p.ssv")
    return str(folder)


def saved_in(folder: str, text: str):
    """A ``check``: the run was saved in ``folder`` and stdout says ``text``."""
    def check(root: Path, proc: subprocess.CompletedProcess) -> None:
        assert json.loads((root / folder / "run.json").read_text())["status"] == "complete"
        assert text in proc.stdout, proc.stdout
    return check


CASES = [
    Case("non-ascii-names-on-an-ascii-stdout-are-escaped", ("run", "d.yaml", "-o", "oüt"), 0, "",
         files={"d.yaml": RAMP}, env={"PYTHONIOENCODING": "ascii"},
         check=saved_in("oüt", "Pr\\xfcfstand: 0.01 s simulated")),
    Case("a-non-ascii-error-on-an-ascii-stderr-is-one-line", ("validate", "d.yaml", "--set", "ramp.slöpe=1"), 2,
         r"^--set ramp\.sl\\xf6pe=1: block 'ramp' \(Ramp\) has no parameter 'sl\\xf6pe'",
         files={"d.yaml": RAMP}, env={"PYTHONIOENCODING": "ascii"}),
    Case("a-path-that-ascii-file-names-cannot-hold", ("validate", "d.yaml"), 2,
         r"^d\.yaml:5: block 'plant' \(FMU\): FMU 'pl\\xe4nt\.fmu' cannot be read: the path has a character "
         r"\('\\xe4'\) that this system's file names \(ascii\) cannot hold; run in a UTF-8 locale",
         files={"d.yaml": diagram("plänt.fmu"), "plänt.fmu": fmu()}, env=ASCII_LOCALE),
    Case("fmu-that-cannot-be-read-is-not-called-no-fmu", ("validate", "d.yaml"), 2,
         r"d\.yaml:5: block 'plant' \(FMU\): FMU '/proc/self/mem' cannot be read: Input/output error",
         files={"d.yaml": diagram("/proc/self/mem")}),
    Case("fmu-info-of-a-file-that-cannot-be-read", ("fmu", "info", "/proc/self/mem"), 2,
         r"^hierhand: error: FMU '/proc/self/mem' cannot be read: "),
    Case("fmu-info-shows-a-step-of-1e308-as-unusable", ("fmu", "info", "plant.fmu"), 0, "",
         files={"plant.fmu": fmu(xml=with_step("1e308"))},
         check=prints("step 1e308 (not usable: out of range (1e-12 s to 1e9 s))")),
    Case("fmu-info-of-an-fmi3-array-of-a-billion-elements", ("fmu", "info", "plant.fmu"), 0, "",
         files={"plant.fmu": fmu3(BILLION)}, check=prints("    z          output")),
    Case("plot-o-naming-a-folder", ("plot", "r", "-o", "pics"), 2,
         r"^hierhand: error: -o pics: is a folder; name the \.png, \.svg or \.pdf file to write "
         r"\(e\.g\. -o pics/signals\.png\)",
         files={"pics/keep.txt": "mine"}),
    Case("plot-o-naming-no-png", ("plot", "r", "-o", "picture"), 2,
         r"^hierhand: error: -o picture: write a \.png, \.svg or \.pdf file \(e\.g\. -o picture\.png\)",
         absent=("picture.png",)),
    Case("ssp-member-outside-the-package", ("validate", "s.ssp"), 2,
         r"^s\.ssp: unsafe SSP archive, not unpacked: .*member '\.\./\.\./evil\.txt' has a '\.\.' component",
         files={"s.ssp": ssp(**{"..__..__evil.txt": "x"})}, absent=("../evil.txt", "../../evil.txt")),
    Case("ssp-member-that-inflates-a-thousand-times", ("validate", "s.ssp"), 2,
         r"^s\.ssp: unsafe SSP archive, not unpacked: .*'resources/zeros\.bin' inflates .* more than 200 times",
         files={"s.ssp": ssp(**{"resources__zeros.bin": b"\0" * (8 << 20)})}),
    Case("ssp-whose-ssd-is-a-fifo", ("validate", _fifo_ssp() + "/SystemStructure.ssd"), 2,
         r"SystemStructure\.ssd: cannot be read: it is a FIFO \(named pipe\), not a regular file"),
    Case("ssp-folder-whose-ssd-is-a-fifo", ("validate", _fifo_ssp()), 2, r"not a regular file"),
    Case("ssp-parameter-file-that-is-a-fifo", ("validate", _fifo_parameters()), 2,
         r"SystemStructure\.ssd:\d+: component 'a': parameter source 'resources/p\.ssv' is a FIFO \(named pipe\), "
         r"not a regular file"),
    Case("ssp-billion-laughs", ("validate", "s.ssp"), 2,
         r"^\S*s\.ssp/SystemStructure\.ssd:\d+: not well-formed XML: ", files={"s.ssp": ssp(LAUGHS)}),
    Case("ssp-external-entity-is-not-read", ("validate", "s.ssp"), 2,
         r"SystemStructure\.ssd:\d+: not well-formed XML: .*external entity", files={"s.ssp": ssp(EXTERNAL)}),
    Case("ssp-xml-nested-100000-deep", ("validate", "s.ssp"), 2,
         r"SystemStructure\.ssd:\d+: not well-formed XML: Excessive depth", files={"s.ssp": ssp(DEEP)}),
]
