"""A constructor's ``ParameterError``: one issue per problem, at the line that gave the value
(the diagram's params, the params file, or the --set), as hand files are reported."""

from __future__ import annotations

import pytest

from blocks import DiagramError, ParameterError, load_diagram

LIMITS = "python:tests.blocks.blockdefs:Limits"
DIAGRAM = f"""\
name: limits
blocks:
  lim:
    type: {LIMITS}
{{extra}}"""


def issues(tmp_path, extra: str, params: str | None = None, overrides=None):
    (tmp_path / "d.yaml").write_text(DIAGRAM.format(extra=extra))
    if params is not None:
        (tmp_path / "p.yaml").write_text(params)
    with pytest.raises(DiagramError) as info:
        load_diagram(tmp_path / "d.yaml", overrides=overrides, trust=True)
    return [(i.file, i.line, i.message) for i in info.value.issues]


def test_problems_are_reported_at_their_inline_lines(tmp_path):
    found = issues(tmp_path, "    params:\n      gains:\n        a: 1\n        b: -1\n        c: -2\n")
    d = str(tmp_path / "d.yaml")
    assert [(f, line) for f, line, _ in found] == [(d, 8), (d, 9)]
    assert found[0][2] == f"block 'lim' ({LIMITS}): gains.b must be positive, got -1"


def test_problems_are_reported_at_the_params_file_line(tmp_path):
    found = issues(tmp_path, "    params_file: p.yaml\n", "scale: 2\ngains:\n  a: 1\n  b: -1\n")
    assert [(f, line) for f, line, _ in found] == [(str(tmp_path / "p.yaml"), 4)]


def test_inline_value_over_the_params_file_is_reported_inline(tmp_path):
    found = issues(tmp_path, "    params_file: p.yaml\n    params: {gains: {b: -3}}\n", "gains:\n  b: 1\n")
    assert [(f, line) for f, line, _ in found] == [(str(tmp_path / "d.yaml"), 6)]


def test_a_problem_of_a_set_value_names_the_set(tmp_path):
    found = issues(tmp_path, "    params: {gains: {a: 1}}\n", overrides={"lim.gains.a": -1})
    assert found == [("--set lim.gains.a=-1", None, f"block 'lim' ({LIMITS}): gains.a must be positive, got -1")]


def test_any_other_exception_is_one_issue_at_the_params(tmp_path):
    found = issues(tmp_path, "    params:\n      gains: 3\n")
    assert found == [(str(tmp_path / "d.yaml"), 5, f"block 'lim' ({LIMITS}): gains must be a mapping")]


def test_parameter_error_text():
    err = ParameterError([(("a", 1), "a[1] is bad"), ((), "and so is the rest")])
    assert err.problems == [(("a", 1), "a[1] is bad"), ((), "and so is the rest")]
    assert str(err) == "a[1] is bad; and so is the rest"
    assert isinstance(err, ValueError)
