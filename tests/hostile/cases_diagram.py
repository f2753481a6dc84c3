"""Corpus cases for diagram files the tool already refuses well (kept as regressions)."""

from __future__ import annotations

from .corpus import Case

GOOD = """\
name: ok
time: {t_end: 10 ms}
blocks:
  src: {type: Step, period: 1 ms, params: {time: 0.002}}
  gain: {type: Gain, params: {k: 2.0}}
connections:
  - src.y -> gain.u
log: [gain.y]
"""

CASES = [
    Case("unknown-block-type", ("validate", "d.yaml"), 2, r"d\.yaml:4: .*unknown block type 'Stepp'",
         files={"d.yaml": GOOD.replace("type: Step,", "type: Stepp,")}),
    Case("missing-diagram", ("run", "nope.yaml"), 2, r"nope\.yaml"),
]
