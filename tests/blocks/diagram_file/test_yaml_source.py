"""YAML with positions: lines of keys and items, duplicate keys, recursive aliases, syntax
errors, and the limits on hostile text: size, kind, encoding, nesting and alias expansion."""

from __future__ import annotations

import copy
import os

import pytest
import yaml

from hypothesis import given, settings
from hypothesis import strategies as st

from blocks.diagram_file import yaml_source
from blocks.limits import MAX_ALIAS_VALUES, MAX_YAML_BYTES, MAX_YAML_DEPTH
from blocks.diagram_file.yaml_source import (
    LineDict,
    LineList,
    YamlSourceError,
    line_at,
    line_of,
    load_yaml,
    read_yaml_file,
)

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


def test_merge_keys_follow_yaml_and_keep_lines():
    text = "a: &a {x: 1, y: 2}\nb: &b {y: 3, z: 4}\nm:\n  <<: [*a, *b]\n  x: 5\n"
    data = load_yaml(text)
    assert data["m"] == yaml.safe_load(text)["m"] == {"x": 5, "y": 2, "z": 4}
    assert data["m"].line_of("x") == 5 and data["m"].line_of("y") == 1 and data["m"].line_of("z") == 2


def test_merge_key_of_a_scalar_is_an_error_with_a_line():
    with pytest.raises(YamlSourceError) as info:
        load_yaml("ok: 1\nm:\n  <<: 3\n")
    assert info.value.line == 3 and "merge key" in info.value.message


def laughs(levels: int, width: int = 10) -> str:
    lines = ["l0: &l0 [" + ", ".join(["lol"] * width) + "]"]
    lines += [f"l{i}: &l{i} [" + ", ".join([f"*l{i - 1}"] * width) + "]" for i in range(1, levels)]
    return "\n".join(lines) + "\n"


class Counted:
    """Counts the calls of a function it stands in for: the work a refusal costs, which a
    busy machine does not change (unlike the seconds it takes)."""

    def __init__(self, function):
        self.function, self.calls = function, 0

    def __call__(self, *args, **kwargs):
        self.calls += 1
        return self.function(*args, **kwargs)


def test_billion_laughs_is_refused_after_bounded_work_at_the_line_of_the_alias(monkeypatch):
    """Ten levels of ten aliases stand for 10^9 values; the refusal builds at most the
    allowed repetitions and the text's own values, a hundred thousand-odd values."""
    text = laughs(9)
    built = Counted(yaml_source._Builder.build)
    monkeypatch.setattr(yaml_source._Builder, "build", lambda self, *a: built(self, *a))
    with pytest.raises(YamlSourceError) as info:
        load_yaml(text)
    assert built.calls <= MAX_ALIAS_VALUES + len(text)
    assert f"more than {MAX_ALIAS_VALUES}" in info.value.message
    assert info.value.line == 5  # l4 repeats l3 (11 111 values) ten times: the first level past the limit
    assert "alias" in info.value.hint


def test_billion_laughs_through_merge_keys_is_refused():
    text = "m0: &m0 {a: 1, b: 2}\n" + "".join(
        f"m{i}: &m{i} {{<<: [*m{i - 1}, *m{i - 1}, *m{i - 1}]}}\n" for i in range(1, 40))
    with pytest.raises(YamlSourceError) as info:
        load_yaml(text)
    assert "aliases repeat" in info.value.message


def test_aliases_repeating_fewer_values_than_the_limit_load():
    data = load_yaml(laughs(4))  # 12 330 repeated values
    assert len(data["l3"]) == 10 and data["l3"][9][9][9][9] == "lol"


def test_nesting_deeper_than_the_limit_is_refused_before_parsing_it_all(monkeypatch):
    """50 000 nested lists are refused after the parser's first hundred-odd events, never
    composed (libyaml's composer would recurse on the C stack)."""
    events = Counted(None)

    def counted_parse(*args, **kwargs):
        for event in real_parse(*args, **kwargs):
            events.calls += 1
            yield event

    real_parse = yaml_source.yaml.parse
    monkeypatch.setattr(yaml_source.yaml, "parse", counted_parse)
    composed = Counted(yaml_source._Loader.get_single_node)
    monkeypatch.setattr(yaml_source._Loader, "get_single_node", lambda self: composed(self))
    for text, line in [("a: 1\nb: " + "[" * 50_000, 2), ("- " * 50_000 + "x\n", 1),
                       ("a:\n" + "".join(" " * i + f"k{i}:\n" for i in range(1, 200)), 101)]:
        events.calls = 0
        with pytest.raises(YamlSourceError) as info:
            load_yaml(text)
        assert events.calls <= 3 * MAX_YAML_DEPTH and composed.calls == 0
        assert info.value.line == line and f"deeper than {MAX_YAML_DEPTH}" in info.value.message


def test_nesting_at_the_limit_loads():
    data = load_yaml("[" * MAX_YAML_DEPTH + "]" * MAX_YAML_DEPTH)
    for _ in range(MAX_YAML_DEPTH - 1):
        data = data[0]
    assert data == []


def test_nesting_through_aliases_is_refused():
    with pytest.raises(YamlSourceError) as info:  # each part 61 levels deep, together 101
        load_yaml("a: &a " + "[" * 60 + "1" + "]" * 60 + "\nb: " + "[" * 40 + "*a" + "]" * 40 + "\n")
    assert "through aliases" in info.value.message and info.value.line == 2


def test_a_chain_of_merge_keys_is_nesting():
    text = "m0: &m0 {a: 1}\n" + "".join(f"m{i}: &m{i} {{<<: *m{i - 1}}}\n" for i in range(1, 1000))
    with pytest.raises(YamlSourceError) as info:
        load_yaml(text)
    assert "through aliases" in info.value.message and info.value.line == MAX_YAML_DEPTH  # m99: 99 merges deep


def test_control_character_has_line_and_column():
    with pytest.raises(YamlSourceError) as info:
        load_yaml("a: 1\nb: \u00e9\x07\n")
    assert info.value.line == 2 and "U+0007 at column 5" in info.value.message


@pytest.mark.parametrize("path, found, line", [
    (("a",), 1, 1), (("b", 0), 2, 3), (("b", 1, "c"), 3, 4), (("b", 1, "c", 0, "x"), 4, 4),
    (("b", 7), 1, 2), (("nope", "x"), 0, 1), ((), 0, 1),
])
def test_line_at_finds_the_deepest_part_of_a_path(path, found, line):
    data = load_yaml("a: 1\nb:\n  - 2\n  - c: [1, 2]\n")
    assert line_at(data, path) == (line, found)


def test_line_at_of_plain_values():
    assert line_at({"a": 1}, ("a",)) == (None, 0)


def test_read_yaml_file_reads_utf8(tmp_path):
    (tmp_path / "f.yaml").write_text("a: caf\u00e9\n", encoding="utf-8")
    assert read_yaml_file(tmp_path / "f.yaml") == "a: caf\u00e9\n"


def test_read_yaml_file_passes_a_missing_file_on(tmp_path):
    with pytest.raises(FileNotFoundError):
        read_yaml_file(tmp_path / "missing.yaml")


@pytest.mark.parametrize("content, line, text", [
    (b"a: 1\nb: caf\xe9\n", 2, "byte 0xe9 at column 7"),
    ("a: 1\nb: \u00e9\u00e9".encode() + b"\xff\n", 2, "byte 0xff at column 6"),
    (b"a: 1\nb: 2\x00\n", 2, "NUL byte at column 5"),
])
def test_read_yaml_file_bad_text_has_line_and_column(tmp_path, content, line, text):
    (tmp_path / "f.yaml").write_bytes(content)
    with pytest.raises(YamlSourceError) as info:
        read_yaml_file(tmp_path / "f.yaml")
    assert info.value.line == line and text in info.value.message


def test_read_yaml_file_refuses_a_big_file_without_reading_it(tmp_path):
    path = tmp_path / "big.yaml"
    with open(path, "wb") as fh:
        fh.truncate(MAX_YAML_BYTES + 1)  # sparse: its size alone must refuse it
    with pytest.raises(YamlSourceError) as info:
        read_yaml_file(path)
    assert f"larger than {MAX_YAML_BYTES}" in info.value.message and info.value.line is None


def test_read_yaml_file_at_the_size_limit(tmp_path):
    path = tmp_path / "full.yaml"
    path.write_bytes(b"a: 1\n" + b"#" * (MAX_YAML_BYTES - 5))
    assert len(read_yaml_file(path)) == MAX_YAML_BYTES


@pytest.mark.parametrize("make", ["folder", "fifo", "device"])
def test_read_yaml_file_refuses_what_is_not_a_regular_file(tmp_path, make):
    path = tmp_path / "thing"
    if make == "folder":
        path.mkdir()
    elif make == "fifo":
        os.mkfifo(path)  # opening it must not wait for a writer
    else:
        path = "/dev/zero"
    with pytest.raises(YamlSourceError) as info:
        read_yaml_file(path)
    assert "not a regular file" in info.value.message


def test_read_yaml_file_unreadable(tmp_path):
    path = tmp_path / "secret.yaml"
    path.write_text("a: 1\n")
    path.chmod(0)
    if os.access(path, os.R_OK):
        pytest.skip("running as a user who reads everything")
    with pytest.raises(YamlSourceError) as info:
        read_yaml_file(path)
    assert "cannot open" in info.value.message


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


@settings(max_examples=200)
@given(yaml_values, st.sampled_from([False, True]))
def test_load_yaml_agrees_with_safe_load(value, flow):
    text = yaml.safe_dump(value, default_flow_style=flow)
    assert load_yaml(text) == yaml.safe_load(text)


def test_a_deep_copy_keeps_every_line_and_shares_nothing():
    data = load_yaml("a:\n  b: [1, [2, 3]]\n  c: {x: 3}\n")
    copied = copy.deepcopy(data)
    assert copied == data and type(copied["a"]) is type(data["a"])
    assert copied["a"].line_of("c") == data["a"].line_of("c") == 3
    assert copied["a"]["b"].line_of(1) == data["a"]["b"].line_of(1) == 2
    copied["a"]["b"][1].append(4)
    copied["a"].key_lines["c"] = 99
    assert data["a"]["b"][1] == [2, 3] and data["a"].line_of("c") == 3
