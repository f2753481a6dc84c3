"""Corpus cases for hostile YAML and the files it names: aliases that multiply, nesting that
overflows a C stack, files too big, devices, binary or badly encoded text, paths out of the
diagram's folder, a diagram name that climbs out of runs/, hand files, and override errors
that must name the option the user typed.

The alias and nesting cases are refused after bounded work: tests/blocks/test_yamlsource.py
counts it (values built, parser events), which no busy machine changes.
"""

from __future__ import annotations

import subprocess
from pathlib import Path

from blocks.limits import MAX_YAML_BYTES

from .cases_diagram import GOOD
from .corpus import Case

LAUGHS = "name: laughs\nl0: &l0 [" + ", ".join(["lol"] * 10) + "]\n" + "".join(
    f"l{i}: &l{i} [" + ", ".join([f"*l{i - 1}"] * 10) + "]\n" for i in range(1, 9)
) + "blocks: {g: {type: Gain, params: {k: *l8}}}\n"
"""The 'billion laughs': 1 KB of anchors, each level ten aliases of the one before (1e9 values)."""

MERGE_LAUGHS = "name: merge-laughs\nm0: &m0 {a: 1, b: 2}\n" + "".join(
    f"m{i}: &m{i} {{<<: [*m{i - 1}, *m{i - 1}, *m{i - 1}, *m{i - 1}]}}\n" for i in range(1, 30)
) + "blocks: {g: {type: Gain, params: *m29}}\n"
"""The same through merge keys: each level merges the one before four times."""



def params_gain(file: str) -> str:
    """GOOD with the gain's parameters taken from ``params_file: FILE`` (line 5)."""
    return GOOD.replace("params: {k: 2.0}}", f"params_file: {file}}}")


PLANT = """\
name: hand
time: {t_end: 1 ms}
blocks:
  plant: {type: HandPlant, period: 0.1 ms, params_file: hand.yaml}
  tau: {type: Constant, params: {value: [0, 0, 0, 0, 0, 0, 0, 0, 0]}}
connections:
  - tau.y -> plant.tau
log: [plant.q]
"""

BAD_HAND = """\
gravity: [0.0, -9.81]
object:
  mass: 0.3
  size: [0.05, 0.05]
  bogus: 3
contact:
  mu_s: 1.0
  bad_key: 2
"""
"""A hand file with two problems, at lines 5 and 8."""

SWEEP = GOOD.replace("gain:", "plant:").replace("gain.", "plant.")
"""A diagram whose gain is named ``plant``, for the sweep cases."""


def stderr_lines(n: int):
    """A ``check`` that stderr holds exactly ``n`` lines: one per problem, nothing else."""

    def check(folder: Path, proc: subprocess.CompletedProcess) -> None:
        lines = proc.stderr.strip().splitlines()
        assert len(lines) == n, f"expected {n} line(s) on stderr, got:\n{proc.stderr}"

    return check


def only_inside(folder: Path, proc: subprocess.CompletedProcess) -> None:
    """The run wrote its results to one folder directly under runs/, and nothing beside runs/."""
    outputs = list((folder / "runs").iterdir())
    assert len(outputs) == 1 and (outputs[0] / "run.json").is_file(), outputs
    assert not outputs[0].name.startswith("."), outputs
    assert sorted(p.name for p in folder.iterdir()) == ["d.yaml", "runs"]
    assert not list(folder.parent.glob("escaped*"))


CASES = [
    # 1. aliases that multiply: refused after a bounded number of repeated values
    Case("yaml-billion-laughs", ("validate", "d.yaml"), 2, r"^d\.yaml:\d+: .*aliases .*100000",
         files={"d.yaml": LAUGHS}, check=stderr_lines(1)),
    Case("yaml-merge-key-laughs", ("validate", "d.yaml"), 2, r"^d\.yaml:\d+: .*aliases",
         files={"d.yaml": MERGE_LAUGHS}, check=stderr_lines(1)),
    Case("yaml-laughs-in-params-file", ("validate", "d.yaml"), 2, r"^p\.yaml:\d+: .*aliases",
         files={"d.yaml": params_gain("p.yaml"), "p.yaml": LAUGHS.replace("name: laughs\n", "")
                .replace("blocks: {g: {type: Gain, params: {k: *l8}}}", "k: *l8")}),
    # 2. nesting deep enough to overflow the C parser's stack: refused before it is parsed
    Case("yaml-deep-flow-nesting", ("validate", "d.yaml"), 2, r"^d\.yaml:2: .*nested deeper than 100",
         files={"d.yaml": "name: deep\nblocks: " + "[" * 50_000 + "\n"}, check=stderr_lines(1)),
    Case("yaml-deep-block-nesting", ("validate", "d.yaml"), 2, r"^d\.yaml:3: .*nested deeper than 100",
         files={"d.yaml": "name: deep\nblocks:\n  " + "- " * 50_000 + "x\n"}),
    Case("yaml-deep-nesting-in-hand-file", ("fmu", "export", "--hand", "h.yaml", "-o", "out.fmu"), 2,
         r"^h\.yaml:1: .*nested deeper than 100", files={"h.yaml": "gravity: " + "[" * 50_000},
         absent=("out.fmu",), check=stderr_lines(1)),
    # 3. size: checked before the file is read
    Case("yaml-diagram-too-big", ("validate", "d.yaml"), 2, rf"^d\.yaml: .*larger than {MAX_YAML_BYTES}",
         files={"d.yaml": GOOD + "#" * MAX_YAML_BYTES}, check=stderr_lines(1)),
    Case("yaml-params-file-too-big", ("validate", "d.yaml"), 2,
         r"^d\.yaml:5: block 'gain': params_file 'p\.yaml': file larger than",
         files={"d.yaml": params_gain("p.yaml"), "p.yaml": "k: 1\n" + "#" * MAX_YAML_BYTES}),
    Case("yaml-hand-file-too-big", ("fmu", "export", "--hand", "h.yaml", "-o", "out.fmu"), 2,
         r"^h\.yaml: .*larger than", files={"h.yaml": "#" * (MAX_YAML_BYTES + 1)}, absent=("out.fmu",)),
    # 4. params_file: devices, binary files, paths out of the diagram's folder, unknown keys
    Case("yaml-params-file-device", ("validate", "--trust", "d.yaml"), 2,
         r"^d\.yaml:5: block 'gain': params_file '/dev/zero': not a regular file",
         files={"d.yaml": params_gain("/dev/zero")}, check=stderr_lines(1)),
    Case("yaml-params-file-folder", ("validate", "d.yaml"), 2,
         r"^d\.yaml:5: block 'gain': params_file 'sub': not a regular file",
         files={"d.yaml": params_gain("sub"), "sub/x.yaml": "k: 1\n"}),
    Case("yaml-params-file-binary", ("validate", "d.yaml"), 2, r"^p\.yaml:2: .*not UTF-8 text.*column 3",
         files={"d.yaml": params_gain("p.yaml"), "p.yaml": b"k: 1\n\x00\x01\xff\xfe\x00"},
         check=stderr_lines(1)),
    Case("yaml-params-file-absolute", ("validate", "d.yaml"), 2,
         r"^d\.yaml:5: block 'gain': params_file '/etc/hostname' is outside the diagram's folder.*--trust",
         files={"d.yaml": params_gain("/etc/hostname")}, check=stderr_lines(1)),
    Case("yaml-params-file-climbs-out", ("validate", "sub/d.yaml"), 2,
         r"^sub/d\.yaml:5: block 'gain': params_file '\.\./p\.yaml' is outside the diagram's folder",
         files={"sub/d.yaml": params_gain("../p.yaml"), "p.yaml": "k: 1\n"}),
    Case("yaml-params-file-climbs-out-trusted", ("validate", "--trust", "sub/d.yaml"), 0, r"^$",
         files={"sub/d.yaml": params_gain("../p.yaml"), "p.yaml": "k: 1\n"}),
    Case("yaml-params-file-in-subfolder", ("validate", "d.yaml"), 0, r"^$",
         files={"d.yaml": params_gain("params/../params/p.yaml"), "params/p.yaml": "k: 1\n"}),
    Case("yaml-params-file-unknown-key", ("validate", "d.yaml"), 2,
         r"^p\.yaml:2: block 'gain' \(Gain\) has no parameter 'kk' \(hint: did you mean 'k'\?\)",
         files={"d.yaml": params_gain("p.yaml"), "p.yaml": "k: 1\nkk: 2\n"},
         check=stderr_lines(1)),
    # 5. encoding: the line (and column) of the first bad byte or character
    Case("yaml-nul-byte", ("validate", "d.yaml"), 2, r"^d\.yaml:4: .*NUL.*column 6",
         files={"d.yaml": GOOD.replace("  src:", "  src\x00:").encode()}, check=stderr_lines(1)),
    Case("yaml-latin-1", ("validate", "d.yaml"), 2, r"^d\.yaml:2: .*not UTF-8 text: byte 0xe9 at column 17",
         files={"d.yaml": GOOD.replace("ok\n", "ok\ndescription: caf\u00e9\n").encode("latin-1")},
         check=stderr_lines(1)),
    Case("yaml-control-character", ("validate", "d.yaml"), 2, r"^d\.yaml:2: .*U\+0007.*column 15",
         files={"d.yaml": GOOD.replace("ok\n", "ok\ndescription: \u00e9\x07\n")}, check=stderr_lines(1)),
    # 6. override errors name the option the user typed
    Case("yaml-grid-override-named", ("sweep", "d.yaml", "-o", "out", "--serial", "--grid", "plant.nope=1,2"), 2,
         r"^--grid plant\.nope=1,2: block 'plant' \(Gain\) has no parameter 'nope'",
         files={"d.yaml": SWEEP}, absent=("out",), check=stderr_lines(1)),
    Case("yaml-random-override-named", ("sweep", "d.yaml", "-o", "out", "--serial",
                                        "--random", "nope.k=uniform(0, 1)"), 2,
         r"^--random nope\.k=uniform\(0, 1\): no block named 'nope'", files={"d.yaml": SWEEP}, absent=("out",)),
    Case("yaml-points-override-named", ("sweep", "d.yaml", "-o", "out", "--serial", "--points", "p.csv"), 2,
         r"^--points p\.csv:1: column 'plant\.k\.x': 'plant\.k' is a float",
         files={"d.yaml": SWEEP, "p.csv": "plant.k.x\n1\n2\n"}, absent=("out",)),
    Case("yaml-set-override-named", ("validate", "d.yaml", "--set", "gain.kk=3"), 2,
         r"^--set gain\.kk=3: block 'gain' \(Gain\) has no parameter 'kk'", files={"d.yaml": GOOD}),
    # 7. the diagram's name becomes one safe folder under runs/, never a path
    Case("yaml-name-climbs-out", ("run", "-q", "d.yaml"), 0, r"^$",
         files={"d.yaml": GOOD.replace("name: ok", "name: ../../escaped")},
         absent=("../escaped", "../../escaped"), check=only_inside),
    Case("yaml-name-absolute", ("run", "-q", "d.yaml"), 0, r"^$",
         files={"d.yaml": GOOD.replace("name: ok", "name: /tmp/hierhand-corpus-escaped")},
         absent=("/tmp/hierhand-corpus-escaped",), check=only_inside),
    Case("yaml-name-dots", ("run", "-q", "d.yaml"), 0, r"^$",
         files={"d.yaml": GOOD.replace("name: ok", "name: '..'")}, check=only_inside),
    # 8. hand files: one line per problem at the hand file's line; exit 2 for bad input
    Case("yaml-hand-params-file-lines", ("validate", "d.yaml"), 2,
         r"^hand\.yaml:5: block 'plant' \(HandPlant\): object\.bogus is not a known key",
         files={"d.yaml": PLANT, "hand.yaml": BAD_HAND}, check=stderr_lines(2)),
    Case("yaml-hand-params-file-value", ("validate", "d.yaml"), 2,
         r"^hand\.yaml:3: block 'plant' \(HandPlant\): object\.mass must be > 0",
         files={"d.yaml": PLANT, "hand.yaml": BAD_HAND.replace("  bogus: 3\n", "").replace("  bad_key: 2\n", "")
                .replace("mass: 0.3", "mass: -1")}, check=stderr_lines(1)),
    Case("yaml-fmu-export-bad-hand", ("fmu", "export", "--hand", "bad.yaml", "-o", "out.fmu"), 2,
         r"^bad\.yaml:5: object\.bogus is not a known key.*\nbad\.yaml:8: contact\.bad_key",
         files={"bad.yaml": BAD_HAND}, absent=("out.fmu",), check=stderr_lines(2)),
    Case("yaml-fmu-export-broken-hand", ("fmu", "export", "--hand", "bad.yaml", "-o", "out.fmu"), 2,
         r"^bad\.yaml:2: YAML syntax error", files={"bad.yaml": "gravity: [0.0, -9.81]\nobject: mass: 1\n"},
         absent=("out.fmu",), check=stderr_lines(1)),
    Case("yaml-reproduce-no-diagrams", ("reproduce", "--diagrams", "/nonexistent", "-o", "rep"), 2,
         r"/nonexistent/grasp\.yaml: task diagram not found", absent=("rep",), check=stderr_lines(1)),
]
