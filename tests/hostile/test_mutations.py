"""Mutated shipped inputs through the real command line: every answer is a complete run or
one line per problem and exit 2, never an internal error, a traceback or an empty message.

Three kinds of input: the shipped diagrams, an SSP (an SSD of two components, packed with
an FMU that ``validate`` reads but never loads) and a sweep's output folder (read by
``sweep-plot``). Each is mutated as bytes (bytes replaced, inserted or cut, from an
alphabet of characters that matter to YAML, XML, CSV and numbers) and as structure (a
value anywhere in the document replaced by a hostile one: huge, tiny, non-finite,
evaluable, a path out, control characters, the wrong type). Hypothesis draws a fixed,
small number of examples (derandomized), so the test costs the same on every run.
"""

from __future__ import annotations

import json
import random
import tempfile
import zipfile
from io import BytesIO
from pathlib import Path

import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from lxml import etree

from tests.blocks.ssp.conftest import ssd
from tests.blocks.ssp.test_import import component, values

from .cases_fmu import fmu
from .corpus import ROOT

def examples(count: int):
    """Settings of ``count`` derandomized examples (a sweep plot costs seconds, a validate less)."""
    return settings(max_examples=count, derandomize=True,
                    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
DIAGRAMS = {name: (ROOT / "diagrams" / name).read_text(encoding="utf-8") for name in ("toy.yaml", "grasp.yaml")}
SSD_TEXT = ssd(f"<ssd:Elements>{component('a', values(('x0', 'Real', '1.0'), ('n', 'Int8', '3')))}"
               f"{component('b')}</ssd:Elements><ssd:Connections><ssd:Connection startElement='a' "
               "startConnector='z[1]' endElement='b' endConnector='u'><ssc:LinearTransformation factor='2' "
               "offset='0.5'/></ssd:Connection></ssd:Connections>")
SWEEP = {"sweep.csv": "point_hash,status,error,wall_s,g.k,m\nab12,ok,,0.5,1.0,2.0\ncd34,ok,,0.5,2.0,4.0\n"
                      "ef56,failed,boom,0.1,3.0,\n",
         "sweep.json": json.dumps({"parameters": ["g.k"], "metrics": {"m": "final(g.y)"}})}
ALPHABET = b"0123456789eE.+-:,[]{}()<>\"'=/\\*^ \n\t#&!|%@`~\x00\x1b\x7f\xff" + "ö".encode()
HOSTILE = [10**30, -10**30, 0, -1, 1e308, -1e308, 5e-324, ".nan", "1e999999999 s", "9**9**9**9", "m^99",
           "../../../x", "/etc/passwd", "\x1b]2;x\x07\x1b[2J", "\u202e", "9" * 5000, True, None, [], {}, [[[]]],
           {"a": {"b": None}}, "", " ", "0:1000000000000", 1000000000000, "1 ms", "nonsense"]
"""Values a structural mutation puts in place of one in the document."""


def mutated_bytes(data: bytes, rng: random.Random) -> bytes:
    """``data`` with one to four edits: a byte replaced, bytes inserted, or a span cut."""
    out = bytearray(data)
    for _ in range(rng.randint(1, 4)):
        at = rng.randrange(len(out) + 1)
        kind = rng.randrange(3)
        if kind == 0 and at < len(out):
            out[at] = rng.choice(ALPHABET)
        elif kind == 1:
            out[at:at] = bytes(rng.choice(ALPHABET) for _ in range(rng.randint(1, 8)))
        else:
            del out[at:at + rng.randint(1, 16)]
    return bytes(out)


def _nodes(value, path=()):
    """Every (path, value) of a parsed YAML document, containers included."""
    yield path, value
    items = value.items() if isinstance(value, dict) else enumerate(value) if isinstance(value, list) else ()
    for key, item in items:
        yield from _nodes(item, (*path, key))


def mutated_yaml(text: str, rng: random.Random) -> str:
    """The document with one value (or key) replaced by a HOSTILE one, dumped again."""
    doc = yaml.safe_load(text)
    path, _ = rng.choice([(p, v) for p, v in _nodes(doc) if p])
    parent = doc
    for key in path[:-1]:
        parent = parent[key]
    replacement = rng.choice(HOSTILE)
    if isinstance(parent, dict) and rng.random() < 0.2:
        parent[str(replacement)[:40]] = parent.pop(path[-1])  # a hostile key instead
    else:
        parent[path[-1]] = replacement
    return yaml.safe_dump(doc, allow_unicode=True)


def mutated_xml(text: str, rng: random.Random) -> str:
    """The SSD with an attribute of one element given a HOSTILE value, or an element removed
    or repeated."""
    root = etree.fromstring(text.encode())
    element = rng.choice(list(root.iter()))
    kind = rng.randrange(3)
    if kind == 0 and element.attrib:
        name = rng.choice(sorted(element.attrib))
        element.set(name, "".join(c for c in str(rng.choice(HOSTILE)) if c in "\t\n" or c >= " " and c != "\x7f"))
    elif kind == 1 and element.getparent() is not None:
        element.getparent().remove(element)
    elif element.getparent() is not None:
        element.getparent().append(etree.fromstring(etree.tostring(element)))
    return etree.tostring(root, xml_declaration=True, encoding="UTF-8").decode()


def mutated_csv(text: str, rng: random.Random) -> str:
    """The sweep's CSV with one cell replaced by a HOSTILE value (as text)."""
    rows = [line.split(",") for line in text.splitlines()]
    row = rng.choice(rows)
    row[rng.randrange(len(row))] = str(rng.choice(HOSTILE))[:6000].replace("\n", " ")
    return "\n".join(",".join(r) for r in rows) + "\n"


def ssp_bytes(ssd_data: bytes) -> bytes:
    buffer = BytesIO()
    with zipfile.ZipFile(buffer, "w") as archive:
        archive.writestr("SystemStructure.ssd", ssd_data)
        archive.writestr("resources/fo.fmu", fmu())
    return buffer.getvalue()


def answered(folder: Path, argv: list[str]) -> None:
    """Run ``argv`` in ``folder``; assert a complete run (0) or one-line problems (2)."""
    from tests.forked_cli import shared

    proc = shared().run(argv, folder, timeout=600)
    shown = f"{argv}\n--- stdout ---\n{proc.stdout[-1500:]}\n--- stderr ---\n{proc.stderr[-3000:]}"
    assert proc.returncode in (0, 2), shown
    assert "Traceback" not in proc.stderr and "internal error" not in proc.stderr, shown
    if proc.returncode == 2:
        lines = proc.stderr.rstrip("\n").split("\n")
        assert lines and all(line.strip() for line in lines), shown


def _folder(tmp_path: Path, seed: int) -> Path:
    """A new folder for one example (Hypothesis may draw a seed twice)."""
    return Path(tempfile.mkdtemp(prefix=f"m{seed}-", dir=tmp_path))


@examples(40)
@given(name=st.sampled_from(sorted(DIAGRAMS)), seed=st.integers(0, 2**32 - 1), structural=st.booleans())
def test_a_mutated_diagram_validates_or_is_refused_in_one_line_each(tmp_path, name, seed, structural):
    rng = random.Random(seed)
    text = DIAGRAMS[name]
    data = mutated_yaml(text, rng).encode() if structural else mutated_bytes(text.encode(), rng)
    folder = _folder(tmp_path, seed)
    (folder / name).write_bytes(data)
    answered(folder, ["validate", name])


@examples(30)
@given(seed=st.integers(0, 2**32 - 1), structural=st.booleans())
def test_a_mutated_ssp_validates_or_is_refused_in_one_line_each(tmp_path, seed, structural):
    rng = random.Random(seed)
    data = mutated_xml(SSD_TEXT, rng).encode() if structural else mutated_bytes(SSD_TEXT.encode(), rng)
    folder = _folder(tmp_path, seed)
    (folder / "s.ssp").write_bytes(ssp_bytes(data))
    answered(folder, ["validate", "s.ssp"])


@examples(20)
@given(seed=st.integers(0, 2**32 - 1), member=st.sampled_from(sorted(SWEEP)), structural=st.booleans())
def test_a_mutated_sweep_folder_plots_or_is_refused_in_one_line(tmp_path, seed, member, structural):
    rng = random.Random(seed)
    folder = _folder(tmp_path, seed)
    (folder / "out").mkdir()
    for name, text in SWEEP.items():
        if name == member:
            data = (mutated_csv(text, rng) if name.endswith(".csv")
                    else json.dumps(yaml.safe_load(mutated_yaml(text, rng)), default=str)).encode() \
                if structural else mutated_bytes(text.encode(), rng)
        else:
            data = text.encode()
        (folder / "out" / name).write_bytes(data)
    answered(folder, ["sweep-plot", "out", "--x", "g.k", "--metric", "m", "-o", "p.png"])
