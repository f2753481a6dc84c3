"""YAML with positions: lines of keys and items, duplicate keys, recursive aliases, syntax errors."""

from __future__ import annotations

import pytest
import yaml

from hypothesis import given, settings
from hypothesis import strategies as st

from blocks.yamlsource import LineDict, LineList, YamlSourceError, line_of, load_yaml

TEXT = """\
# a comment on line 1
alpha: 1
beta:
  - first
  - name: second
    value: 2

  - [3, 4]
gamma: {delta: 5, eps: [6, 7]}
zeta:
  inner:
    deep: true
"""


def test_values_are_those_of_safe_load():
    assert load_yaml(TEXT) == yaml.safe_load(TEXT)


def test_line_of_each_key():
    data = load_yaml(TEXT)
    assert isinstance(data, LineDict)
    assert data.line_of("alpha") == 2
    assert data.line_of("beta") == 3
    assert data.line_of("gamma") == 9
    assert data.line_of("zeta") == 10
    assert data["zeta"].line_of("inner") == 11
    assert data["zeta"]["inner"].line_of("deep") == 12
    assert data["gamma"].line_of("delta") == 9
    assert data["gamma"].line_of("eps") == 9


def test_line_of_each_list_item():
    data = load_yaml(TEXT)
    items = data["beta"]
    assert isinstance(items, LineList)
    assert [items.line_of(i) for i in range(len(items))] == [4, 5, 8]
    assert items[1].line_of("name") == 5
    assert items[1].line_of("value") == 6


def test_module_line_of_helper():
    data = load_yaml(TEXT)
    assert line_of(data, "beta") == 3
    assert line_of(data["beta"], 2) == 8
    assert line_of({"plain": 1}, "plain", default=7) == 7


def test_multi_line_flow_sequence_items():
    data = load_yaml("items: [\n  a,\n  b,\n  c]\n")
    assert [data["items"].line_of(i) for i in range(3)] == [2, 3, 4]


def test_empty_text_is_none():
    assert load_yaml("") is None
    assert load_yaml("# only a comment\n") is None


def test_scalar_document():
    assert load_yaml("42\n") == 42


@pytest.mark.parametrize("text, key, first, second", [
    ("a: 1\nb: 2\na: 3\n", "a", 1, 3),
    ("outer:\n  x: 1\n  y: 2\n  x: 3\n", "x", 2, 4),
    ("list:\n  - k: 1\n    j: 2\n\n    k: 3\n", "k", 2, 5),
    ("m: {p: 1,\n    p: 2}\n", "p", 1, 2),
])
def test_duplicate_keys_are_rejected_with_both_lines(text, key, first, second):
    with pytest.raises(YamlSourceError) as info:
        load_yaml(text)
    err = info.value
    assert err.line == second
    assert repr(key) in err.message or key in err.message
    assert f"line {first}" in err.message


def test_same_key_in_different_mappings_is_fine():
    data = load_yaml("a: {k: 1}\nb: {k: 2}\n")
    assert data == {"a": {"k": 1}, "b": {"k": 2}}


def test_recursive_alias_is_rejected():
    with pytest.raises(YamlSourceError) as info:
        load_yaml("top: &loop\n  - 1\n  - *loop\n")
    assert "recursive" in info.value.message
    assert info.value.line is not None


def test_recursive_mapping_alias_is_rejected():
    with pytest.raises(YamlSourceError) as info:
        load_yaml("top: &loop\n  self: *loop\n")
    assert "recursive" in info.value.message


def test_plain_aliases_are_allowed():
    data = load_yaml("base: &b [1, 2]\ncopy: *b\nmerged:\n  <<: {x: 1}\n  y: 2\n")
    assert data["copy"] == [1, 2]
    assert data["merged"] == {"x": 1, "y": 2}


@pytest.mark.parametrize("text, line", [
    ("a: b: c\n", 1),
    ("ok: 1\nbad: value: more\n", 2),
    ("ok: 1\nalso:\n  - item\n  key: 3\n", 4),
    ("a: 1\n\tb: 2\n", 2),
    ("a: 'unterminated\n", None),
    ("a: [1, 2\nb: 3\n", None),
    ("ok: 1\nx: !!python/name:os.system ''\n", 2),
])
def test_syntax_errors_carry_a_line(text, line):
    with pytest.raises(YamlSourceError) as info:
        load_yaml(text)
    err = info.value
    assert isinstance(err.line, int) and err.line >= 1
    assert err.line <= text.count("\n") + 1
    if line is not None:
        assert err.line == line
    assert err.message


def test_unhashable_key_is_an_error_with_a_line():
    with pytest.raises(YamlSourceError) as info:
        load_yaml("ok: 1\n? [a, b]\n: 2\n")
    assert info.value.line == 2


@pytest.mark.parametrize("text, line", [
    ("ok: 1\nx: !!python/object:os.system {}\n", 2),
    ("ok: 1\nx: !!python/object/apply:os.system [echo hi]\n", 2),
    ("ok: 1\nx: !custom {a: 1}\n", 2),
])
def test_unknown_tags_on_collections_are_rejected_like_safe_load(text, line):
    # yaml.safe_load refuses these; a strict loader must not silently drop the tag.
    with pytest.raises(yaml.YAMLError):
        yaml.safe_load(text)
    with pytest.raises(YamlSourceError) as info:
        load_yaml(text)
    assert info.value.line == line


yaml_scalars = st.one_of(
    st.none(), st.booleans(), st.integers(), st.text(max_size=20),
    st.floats(allow_nan=False),
)
yaml_values = st.recursive(
    yaml_scalars,
    lambda inner: st.one_of(st.lists(inner, max_size=4),
                            st.dictionaries(st.one_of(st.text(max_size=8), st.integers()), inner, max_size=4)),
    max_leaves=20)


@settings(max_examples=200, deadline=None)
@given(yaml_values, st.sampled_from([False, True]))
def test_load_yaml_agrees_with_safe_load(value, flow):
    text = yaml.safe_dump(value, default_flow_style=flow)
    assert load_yaml(text) == yaml.safe_load(text)
