"""Bad diagrams and bad command lines: exit code 2, one ``file:line: message`` per problem.

Every case writes a small diagram into a temporary folder and runs the real command
line in a subprocess, so the test sees exactly what a user sees: the exit code, and on
stderr one line per problem that starts with the diagram's path and the exact line of
the offending text (computed here from the text, never hard-coded), names the block or
port concerned, and carries no traceback.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

import blocks
from blocks import DiagramError

# A valid diagram written in block style, so that every key sits on its own line and
# each error has one unambiguous line. src fires every 1 ms, delay every 2 ms.
BASE = """\
name: bad-input
time:
  t_end: 10 ms
blocks:
  src:
    type: Step
    period: 1 ms
    params:
      time: 0.002
  gain:
    type: Gain
    params:
      k: 2.0
  delay:
    type: UnitDelay
    period: 2 ms
connections:
  - src.y -> gain.u
  - gain.y -> delay.u
log:
  - delay.y
"""

LOOP = """\
name: loop
time:
  t_end: 10 ms
blocks:
  src:
    type: Step
    period: 1 ms
    params:
      time: 0.0
  err:
    type: Sum
    params:
      signs: "+-"
  g:
    type: Gain
    params:
      k: 2.0
connections:
  - src.y -> err.u0
  - err.y -> g.u
  - g.y -> err.u1
log:
  - g.y
"""


# -- helpers -----------------------------------------------------------------------------


def edit(text: str, old: str, new: str, count: int = 1) -> str:
    """``text`` with the first ``count`` occurrences of ``old`` replaced; ``old`` must be there."""
    assert old in text, f"test setup: {old!r} not in the diagram"
    return text.replace(old, new, count)


def lines_with(text: str, needle: str) -> list[int]:
    """1-based numbers of the lines of ``text`` that contain ``needle``."""
    return [i for i, line in enumerate(text.splitlines(), start=1) if needle in line]


def line_with(text: str, needle: str, occurrence: int | None = None) -> int:
    """The line containing ``needle``: the only one, or the ``occurrence``-th (0-based)."""
    found = lines_with(text, needle)
    assert found, f"test setup: {needle!r} not in the diagram"
    if occurrence is None:
        assert len(found) == 1, f"test setup: {needle!r} is on several lines {found}"
        return found[0]
    return found[occurrence]


def line_after(text: str, anchor: str, needle: str) -> int:
    """The first line containing ``needle`` at or after the (unique) line containing ``anchor``."""
    start = line_with(text, anchor)
    for i, line in enumerate(text.splitlines()[start - 1:], start=start):
        if needle in line:
            return i
    raise AssertionError(f"test setup: {needle!r} not after {anchor!r}")


def hierhand(*args: str, cwd: Path, env: dict | None = None) -> subprocess.CompletedProcess:
    """``python -m hierhand ARGS`` in ``cwd``: a process of its own, forked from the session's
    command-line server (``tests.forked_cli``), or with ``env`` a fresh interpreter."""
    if env is None:
        from tests.forked_cli import shared

        return shared().run([str(a) for a in args], cwd, timeout=120)
    return subprocess.run([sys.executable, "-m", "hierhand", *args], capture_output=True,
                          text=True, cwd=cwd, env=env, timeout=120)


def issue_lines(stderr: str, path: Path) -> list[tuple[int, str]]:
    """Parse stderr as ``PATH:LINE: message`` lines; fail if any line has another shape."""
    assert stderr.strip(), "expected a message on stderr"
    assert "Traceback" not in stderr, stderr
    pattern = re.compile(re.escape(str(path)) + r":(\d+): (.+)$")
    out = []
    for line in stderr.splitlines():
        m = pattern.match(line)
        assert m, f"stderr line is not '{path}:LINE: message': {line!r}\n--- stderr ---\n{stderr}"
        out.append((int(m.group(1)), m.group(2)))
    return out


@dataclass
class Case:
    """A bad diagram, the line(s) the error must point at and the names it must mention."""

    id: str
    text: str
    lines: set[int]                     # the reported line must be one of these
    names: tuple[str, ...]              # each must appear in the message
    command: str = "validate"


def _cases() -> list[Case]:
    cases = []

    text = edit(BASE, "      k: 2.0\n", "      k: 2.0: 3.0\n")
    cases.append(Case("yaml-syntax-error", text, {line_with(text, "k: 2.0: 3.0")}, ("YAML",)))

    # A list where the diagram mapping should be (e.g. a stray '- ' before 'blocks:').
    text = "- blocks:\n    a:\n      type: Constant\n      params: {value: 1.0}\n"
    cases.append(Case("top-level-is-a-list", text, {1}, ("mapping",)))

    text = BASE + "colour: blue\n"
    cases.append(Case("unknown-top-level-key", text, {line_with(text, "colour: blue")}, ("colour",)))

    text = edit(BASE, "    type: Gain\n", "    type: Gain\n    colour: red\n")
    cases.append(Case("unknown-block-key", text, {line_with(text, "colour: red")}, ("gain", "colour")))

    text = edit(BASE, "type: Gain", "type: Gian")
    cases.append(Case("unknown-block-type", text, {line_with(text, "type: Gian")}, ("gain", "Gian")))

    text = edit(BASE, "- src.y -> gain.u", "- src.out -> gain.u")
    cases.append(Case("unknown-source-port", text, {line_with(text, "src.out -> gain.u")},
                      ("src", "out")))

    text = edit(BASE, "- gain.y -> delay.u", "- gain.y -> delay.inp")
    cases.append(Case("unknown-destination-port", text, {line_with(text, "gain.y -> delay.inp")},
                      ("delay", "inp")))

    # src (Step) is width 1, so gain.y is width 1; the delay is declared width 3.
    text = edit(BASE, "    period: 2 ms\n", "    period: 2 ms\n    params:\n      initial: [0.0, 0.0, 0.0]\n")
    cases.append(Case("width-mismatch", text, {line_with(text, "gain.y -> delay.u")},
                      ("gain.y", "delay.u", "width"), command="run"))

    text = edit(BASE, "  - gain.y -> delay.u\n", "  - gain.y -> delay.u\n  - src.y -> delay.u\n")
    cases.append(Case("input-driven-twice", text, {line_with(text, "src.y -> delay.u")},
                      ("delay.u", "src.y", "gain.y", f"line {line_with(text, 'gain.y -> delay.u')}")))

    text = edit(BASE, "connections:\n", "  total:\n    type: Sum\n    params:\n      signs: \"++\"\n"
                "connections:\n  - src.y -> total.u0\n")
    cases.append(Case("unconnected-input", text, {line_with(text, "  total:")}, ("total", "u1"),
                      command="run"))

    # Nothing at all is connected to a block: it must still be named, on its own line.
    text = edit(BASE, "connections:\n", "  lonely:\n    type: Gain\n    params:\n      k: 3.0\nconnections:\n")
    cases.append(Case("block-with-nothing-connected", text, {line_with(text, "  lonely:")}, ("lonely",)))

    text = edit(BASE, "connections:\n", "  gain:\n    type: Gain\n    params:\n      k: 4.0\nconnections:\n")
    cases.append(Case("duplicate-block-name", text, {line_with(text, "  gain:", occurrence=1)},
                      ("gain", f"line {line_with(text, '  gain:', occurrence=0)}")))

    text = edit(BASE, "period: 1 ms", "period: fast")
    cases.append(Case("period-not-a-duration", text, {line_with(text, "period: fast")}, ("src", "fast")))

    text = edit(BASE, "period: 1 ms", "period: 0")
    cases.append(Case("zero-period", text, {line_with(text, "period: 0")}, ("src", "period")))

    text = edit(BASE, "period: 1 ms", "period: -1 ms")
    cases.append(Case("negative-period", text, {line_with(text, "period: -1 ms")}, ("src", "period")))

    text = edit(BASE, "t_end: 10 ms", "t_end: 1.5 ms")
    cases.append(Case("t_end-not-a-multiple-of-the-tick", text, {line_with(text, "t_end: 1.5 ms")},
                      ("t_end", "1 ms"), command="run"))

    text = edit(BASE, "    params:\n      k: 2.0\n", "    params_file: gain_params.yaml\n")
    cases.append(Case("missing-params-file", text, {line_with(text, "params_file: gain_params.yaml")},
                      ("gain", "gain_params.yaml"), command="run"))

    text = edit(BASE, "k: 2.0", "kk: 2.0")
    cases.append(Case("unknown-parameter", text, {line_with(text, "kk: 2.0")}, ("gain", "kk")))

    # Step requires 'time'; the block has a params mapping without it.
    text = edit(BASE, "      time: 0.002\n", "      before: 0.5\n")
    cases.append(Case("missing-required-parameter", text, {line_after(text, "  src:", "params:")},
                      ("src", "time")))

    # The same without any params key: the error points at the block itself.
    text = edit(BASE, "    period: 1 ms\n    params:\n      time: 0.002\n", "    period: 1 ms\n")
    cases.append(Case("missing-required-parameter-no-params", text, {line_with(text, "  src:")},
                      ("src", "time")))

    text = edit(BASE, "    period: 1 ms\n", "    period: 1 ms\n    offset: 1 ms\n")
    cases.append(Case("offset-equal-to-period", text, {line_with(text, "offset: 1 ms")}, ("src", "offset")))

    text = edit(BASE, "    period: 1 ms\n", "    period: 1 ms\n    offset: 3 ms\n")
    cases.append(Case("offset-above-period", text, {line_with(text, "offset: 3 ms")}, ("src", "offset")))
    return cases


CASES = _cases()


@pytest.mark.parametrize("case", CASES, ids=[c.id for c in CASES])
def test_cli_reports_bad_diagram_with_exact_line(case: Case, tmp_path: Path):
    path = tmp_path / "diagram.yaml"
    path.write_text(case.text, encoding="utf-8")
    out = tmp_path / "out"
    args = ["run", str(path), "-o", str(out)] if case.command == "run" else ["validate", str(path)]
    proc = hierhand(*args, cwd=tmp_path)
    assert proc.returncode == 2, proc.stderr
    issues = issue_lines(proc.stderr, path)
    assert len(issues) == 1, proc.stderr
    line, message = issues[0]
    assert line in case.lines, f"reported line {line}, expected {sorted(case.lines)}: {proc.stderr}"
    for name in case.names:
        assert name in message, f"{name!r} not named in: {message}"
    assert not out.exists(), "bad input must not leave a results folder"


def test_algebraic_loop_names_the_port_chain(tmp_path: Path):
    path = tmp_path / "loop.yaml"
    path.write_text(LOOP, encoding="utf-8")
    proc = hierhand("validate", str(path), cwd=tmp_path)
    assert proc.returncode == 2, proc.stderr
    issues = issue_lines(proc.stderr, path)
    assert len(issues) == 1, proc.stderr
    line, message = issues[0]
    assert "algebraic loop: " in message
    chain = message.split("algebraic loop: ", 1)[1].split(" (hint")[0].split(";")[0].strip().split(" -> ")
    loop = ["err.y", "g.u", "g.y", "err.u1"]
    # The chain walks the loop in signal-flow order, starting anywhere (closing it is optional).
    if len(chain) == len(loop) + 1:
        assert chain[0] == chain[-1], chain
        chain = chain[:-1]
    assert len(chain) == len(loop), chain
    start = loop.index(chain[0])
    assert chain == loop[start:] + loop[:start], chain
    loop_lines = {line_with(LOOP, "err.y -> g.u"), line_with(LOOP, "g.y -> err.u1")}
    assert line in loop_lines, (line, loop_lines)


def test_algebraic_loop_broken_by_delay_is_accepted(tmp_path: Path):
    text = edit(LOOP, "  - g.y -> err.u1\n", "  - {from: g.y, to: err.u1, delay: 1}\n")
    path = tmp_path / "loop.yaml"
    path.write_text(text, encoding="utf-8")
    proc = hierhand("validate", str(path), cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr


# -- --set overrides -------------------------------------------------------------------------


@pytest.mark.parametrize("item, names", [
    ("gain.k", ("gain.k",)),                      # no '='
    ("nosuch.k=2", ("nosuch",)),                  # unknown block
    ("gain.kk=2", ("gain", "kk")),                # unknown parameter
    ("gain.k=[1, 2", ("gain.k",)),                # value is not YAML
], ids=["no-equals", "unknown-block", "unknown-parameter", "unparsable-value"])
def test_bad_set_override_is_one_line_naming_the_set(item: str, names: tuple[str, ...], tmp_path: Path):
    path = tmp_path / "diagram.yaml"
    path.write_text(BASE, encoding="utf-8")
    proc = hierhand("run", str(path), "-o", str(tmp_path / "out"), "--set", item, cwd=tmp_path)
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    line = lines[0]
    assert line.startswith("--set ") or line.startswith("hierhand: error: --set "), line
    for name in names:
        assert name in line, f"{name!r} not in {line!r}"
    assert not (tmp_path / "out").exists()


def test_good_set_override_is_accepted(tmp_path: Path):
    path = tmp_path / "diagram.yaml"
    path.write_text(BASE, encoding="utf-8")
    proc = hierhand("validate", str(path), "--set", "gain.k=3", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr


# -- python: block types and --trust ---------------------------------------------------------

TRUSTED_MODULE = '''\
"""A block type outside the registry; importing it leaves a marker file."""
from pathlib import Path

import numpy as np

from blocks import Block

Path(__file__).with_name("imported.flag").write_text("imported")


class Triple(Block):
    """y = 3 u."""

    def __init__(self):
        self.inputs = {"u": 1}
        self.outputs = {"y": 1}
        self.feedthrough = True

    def output(self, t, state, inputs):
        return {"y": 3.0 * inputs["u"]}
'''


@pytest.fixture
def trusted_setup(tmp_path: Path):
    module_dir = tmp_path / "pymods"
    module_dir.mkdir()
    (module_dir / "tripler_mod.py").write_text(TRUSTED_MODULE, encoding="utf-8")
    text = edit(BASE, "    type: Gain\n    params:\n      k: 2.0\n", "    type: python:tripler_mod:Triple\n")
    path = tmp_path / "diagram.yaml"
    path.write_text(text, encoding="utf-8")
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(module_dir), env.get("PYTHONPATH", "")) if p)
    return path, text, env, module_dir / "imported.flag"


def test_python_type_without_trust_is_refused_and_not_imported(trusted_setup, tmp_path: Path):
    path, text, env, flag = trusted_setup
    proc = hierhand("run", str(path), "-o", str(tmp_path / "out"), cwd=tmp_path, env=env)
    assert proc.returncode == 2, proc.stderr
    issues = issue_lines(proc.stderr, path)
    assert len(issues) == 1, proc.stderr
    line, message = issues[0]
    assert line == line_with(text, "type: python:tripler_mod:Triple")
    assert "--trust" in message
    assert "gain" in message
    assert not flag.exists(), "the module named in the diagram was imported without --trust"
    assert not (tmp_path / "out").exists()


def test_python_type_with_trust_loads_and_runs(trusted_setup, tmp_path: Path):
    path, text, env, flag = trusted_setup
    out = tmp_path / "out"
    proc = hierhand("run", str(path), "-o", str(out), "--trust", "-q", cwd=tmp_path, env=env)
    assert proc.returncode == 0, proc.stderr
    assert flag.exists()
    results = blocks.Results.load(out)
    t, y = results["delay.y"]
    # delay (2 ms) holds 3 * step(t >= 2 ms) one sample late: 0 at 0 and 2 ms, then 3.
    assert list(t) == pytest.approx([0.0, 0.002, 0.004, 0.006, 0.008, 0.010])
    assert list(y[:, 0]) == [0.0, 0.0, 3.0, 3.0, 3.0, 3.0]


# -- many errors at once ---------------------------------------------------------------------

MULTI = """\
name: many-errors
bogus_key: 1
time:
  t_end: 10 ms
blocks:
  c:
    type: Constant
    params:
      value: 1.0
  typo:
    type: Gian
  h:
    type: Gain
    period: fast
  s:
    type: Sum
    params:
      sings: "++"
connections:
  - c.y -> nothere.u
  - c.q -> s.u0
log:
  - c.y
"""

MULTI_EXPECTED = {
    line_with(MULTI, "bogus_key"): ("bogus_key",),
    line_with(MULTI, "type: Gian"): ("typo", "Gian"),
    line_with(MULTI, "period: fast"): ("h", "fast"),
    line_with(MULTI, "sings:"): ("s", "sings"),
    line_with(MULTI, "c.y -> nothere.u"): ("nothere",),
    line_with(MULTI, "c.q -> s.u0"): ("c", "q"),
}


def test_cli_reports_all_independent_errors_at_once(tmp_path: Path):
    path = tmp_path / "many.yaml"
    path.write_text(MULTI, encoding="utf-8")
    proc = hierhand("validate", str(path), cwd=tmp_path)
    assert proc.returncode == 2, proc.stderr
    issues = issue_lines(proc.stderr, path)
    by_line: dict[int, list[str]] = {}
    for line, message in issues:
        by_line.setdefault(line, []).append(message)
    assert set(by_line) == set(MULTI_EXPECTED), proc.stderr
    for line, names in MULTI_EXPECTED.items():
        assert len(by_line[line]) == 1, by_line[line]
        for name in names:
            assert name in by_line[line][0], (name, by_line[line][0])


# -- the Python API ------------------------------------------------------------------------------


def test_load_diagram_reports_all_issues_with_lines(tmp_path: Path):
    path = tmp_path / "many.yaml"
    path.write_text(MULTI, encoding="utf-8")
    with pytest.raises(DiagramError) as info:
        blocks.load_diagram(path)
    issues = info.value.issues
    assert {i.line for i in issues} == set(MULTI_EXPECTED)
    assert all(i.file == str(path) for i in issues)
    assert all(isinstance(i, blocks.Issue) and i.message for i in issues)
    # The exception text is the printed form of every issue.
    assert str(info.value).splitlines() == [str(i) for i in issues]
    typo = next(i for i in issues if i.line == line_with(MULTI, "type: Gian"))
    assert "Gain" in typo.hint                      # a close match is suggested
    assert str(typo).startswith(f"{path}:{typo.line}: ")
    assert str(typo).endswith(f"(hint: {typo.hint})")


@pytest.mark.parametrize("case_id", ["unknown-destination-port", "zero-period", "duplicate-block-name",
                                     "t_end-not-a-multiple-of-the-tick", "unknown-parameter"])
def test_load_diagram_issue_line(case_id: str, tmp_path: Path):
    case = next(c for c in CASES if c.id == case_id)
    path = tmp_path / "diagram.yaml"
    path.write_text(case.text, encoding="utf-8")
    with pytest.raises(DiagramError) as info:
        blocks.load_diagram(path)
    assert len(info.value.issues) == 1
    issue = info.value.issues[0]
    assert issue.file == str(path)
    assert issue.line in case.lines
    for name in case.names:
        assert name in issue.message


def test_load_diagram_algebraic_loop(tmp_path: Path):
    path = tmp_path / "loop.yaml"
    path.write_text(LOOP, encoding="utf-8")
    with pytest.raises(DiagramError) as info:
        blocks.load_diagram(path)
    [issue] = info.value.issues
    assert issue.message.startswith("algebraic loop: ")
    for port in ("err.y", "g.u", "g.y", "err.u1"):
        assert port in issue.message


def test_load_diagram_override_errors_name_the_override(tmp_path: Path):
    path = tmp_path / "diagram.yaml"
    path.write_text(BASE, encoding="utf-8")
    with pytest.raises(DiagramError) as info:
        blocks.load_diagram(path, overrides={"gain.kk": 2, "nosuch.k": 1})
    texts = [str(i) for i in info.value.issues]
    assert len(texts) == 2, texts
    assert any(t.startswith("--set gain.kk=") and "kk" in t for t in texts), texts
    assert any(t.startswith("--set nosuch.k=") and "nosuch" in t for t in texts), texts


def test_load_diagram_missing_file_is_a_diagram_error(tmp_path: Path):
    path = tmp_path / "absent.yaml"
    with pytest.raises(DiagramError) as info:
        blocks.load_diagram(path)
    assert str(path) in str(info.value)


def test_cli_missing_diagram_file_exits_2(tmp_path: Path):
    path = tmp_path / "absent.yaml"
    proc = hierhand("validate", str(path), cwd=tmp_path)
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(str(path)), proc.stderr
