"""Corpus cases for sweep inputs and the wiring graph: points files that are no text
files, and free-form diagram names in DOT output."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

from .corpus import Case

TOY = """\
name: {name}
time: {{t_end: 2 ms}}
blocks:
  src: {{type: Constant, params: {{value: 1.0}}}}
  gain: {{type: Gain, period: 1 ms, params: {{k: 2.0}}}}
connections:
  - src.y -> gain.u
log: [gain.y]
"""


def dot_name_is_one_quoted_string(folder: Path, proc: subprocess.CompletedProcess) -> None:
    """The DOT file's first line is the graph statement with the whole name quoted."""
    first = (folder / "g.dot").read_text(encoding="utf-8").splitlines()[0]
    assert re.fullmatch(r'digraph "(?:[^"\\]|\\.)*" \{', first), first
    assert '\\"' in first and "\\n" in first


CASES = [
    Case("points-file-is-a-device", ("sweep", "d.yaml", "-o", "out", "--points", "/dev/zero", "-q"), 2,
         r"--points /dev/zero: not a regular file", files={"d.yaml": TOY.format(name="toy")}),
    Case("points-file-not-utf8", ("sweep", "d.yaml", "-o", "out", "--points", "p.csv", "-q"), 2,
         r"--points p\.csv:3: not UTF-8 text", files={"d.yaml": TOY.format(name="toy"),
                                                        "p.csv": b"gain.k\n1.0\n\xe9\n"}),
    Case("points-file-missing", ("sweep", "d.yaml", "-o", "out", "--points", "nope.csv", "-q"), 2,
         r"--points nope\.csv: no such file", files={"d.yaml": TOY.format(name="toy")}),
    Case("graph-name-with-quotes-and-newline", ("graph", "d.yaml", "-o", "g.dot"), 0, r"^$",
         files={"d.yaml": TOY.format(name='"a \\"quoted\\" name\\nover two lines"')},
         check=dot_name_is_one_quoted_string),
]
