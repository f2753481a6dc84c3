"""A block type described (``blocks.typeinfo``): its ports with their units and elements, and
its parameters as its class docstring's ``Parameters`` section documents them."""

from __future__ import annotations

import pytest

from blocks import Block
from blocks.library import LIBRARY
from blocks.registry import block_types
from blocks.typeinfo import ParamDoc, describe_type, parameter_docs, parse_parameters


class Plain(Block):
    def __init__(self):
        self.inputs = {"u": 1}
        self.outputs = {"y": 2}


class Described(Block):
    def __init__(self):
        self.inputs = {"u": 3, "bias": 1}
        self.input_defaults = {"bias": 0.0}
        self.outputs = {"pose": 3, "flags": 2, "bare": 2}

    def port_units(self, port):
        return {"u": "N m", "bias": "N m", "pose": ["m", "m", "rad"], "flags": "1"}.get(port)

    def element_labels(self, port):
        return {"u": ["a.1", "a.2", "b.1"], "pose": ["x", "y", "theta"]}.get(port)


def test_ports_without_units_or_names_stay_on_one_line():
    text = describe_type(Plain)
    assert "  inputs: u[1]\n  outputs: y[2]\n" in text


def test_each_port_shows_its_unit_and_element_names():
    lines = describe_type(Described).splitlines()
    start = lines.index("  inputs (optional: bias):")
    assert lines[start:start + 7] == [
        "  inputs (optional: bias):",
        "    u[3]      N m; elements a.1, a.2, b.1",
        "    bias[1]   N m",
        "  outputs:",
        "    pose[3]   x (m), y (m), theta (rad)",
        "    flags[2]  1 (dimensionless)",
        "    bare[2]",
    ]


class Documented(Block):
    """A block documented the numpydoc way.

    Some prose about it, with a ``Parameters`` word that is no heading.

    Parameters
    ----------
    gain : float
        how much the input is scaled,
        on two lines

        and a second paragraph
    lo, hi : scalar or vector
        the limits
    *names
        no type
    mode

    Notes
    -----
    mode : not a parameter
        this section is not read
    """

    def __init__(self, gain: float = 2.0, lo: float = 0.0, hi: float = 1.0, mode: str = "a"):
        self.inputs, self.outputs = {"u": 1}, {"y": 1}


class Shared:
    """A mixin documenting a parameter its blocks share.

    Parameters
    ----------
    a : int
        from the mixin
    b : int
        from the mixin too
    """


class UsesShared(Shared, Block):
    """A block that documents ``a`` itself, which wins over the mixin's text.

    Parameters
    ----------
    a : int
        from the block
    """

    def __init__(self, a: int = 1, b: int = 2):
        self.inputs, self.outputs = {}, {"y": 1}


class Refined(Documented):
    """A subclass that documents only what it changes.

    Parameters
    ----------
    gain : int
        a whole gain
    """


def test_the_parameters_section_is_read_entry_by_entry():
    docs = parse_parameters(Documented.__doc__)
    assert docs == {
        "gain": ParamDoc("float", "how much the input is scaled, on two lines and a second paragraph"),
        "lo": ParamDoc("scalar or vector", "the limits"),
        "hi": ParamDoc("scalar or vector", "the limits"),
        "names": ParamDoc("", "no type"),
        "mode": ParamDoc("", ""),
    }


@pytest.mark.parametrize("doc", [None, "", "Just a summary.", "Summary.\n\nParameters\n\nk : float\n    text\n"])
def test_a_docstring_without_the_section_documents_nothing(doc):
    assert parse_parameters(doc) == {}


def test_the_section_ends_at_a_line_that_is_no_entry():
    doc = "Summary.\n\nParameters\n----------\nk : float\n    the gain\n\nThis is prose, not an entry.\n"
    assert parse_parameters(doc) == {"k": ParamDoc("float", "the gain")}


def test_the_nearest_class_wins_and_subclasses_inherit_what_they_do_not_document():
    assert parameter_docs(UsesShared) == {"a": ParamDoc("int", "from the block"),
                                          "b": ParamDoc("int", "from the mixin too")}
    refined = parameter_docs(Refined)
    assert refined["gain"] == ParamDoc("int", "a whole gain")
    assert refined["lo"] == ParamDoc("scalar or vector", "the limits")


def test_hierhand_blocks_shows_type_default_and_text_from_the_docstring():
    text = describe_type(Documented)
    assert "    gain (float; default 2.0): how much the input is scaled, on two lines and a second paragraph\n" in text
    assert "    mode (default 'a')\n" in text


def test_the_registered_types_are_the_library_and_the_installed_entry_points():
    from blocks import registry

    types = block_types()
    assert registry._load_errors == {}
    assert {cls.registered_name() for cls in LIBRARY} <= set(types)
    assert {"FMU", "HandPlant", "GraspReflex", "ManipulationPD", "ObjectSupport", "Suppresser"} <= set(types)


@pytest.mark.parametrize("name", sorted(block_types()))
def test_every_registered_block_documents_exactly_its_parameters(name):
    """Every type ``hierhand blocks`` lists (the library and every ``blocks.types`` entry
    point, hierhand's included): each ``__init__`` parameter documented with a text, in
    its own docstring or a base class's / mixin's, and nothing documented it does not take."""
    cls = block_types()[name]
    docs = parameter_docs(cls)
    params = list(cls.parameters())
    assert sorted(docs) == sorted(params), (
        f"{name}: undocumented {sorted(set(params) - set(docs))}, documented but no parameter "
        f"{sorted(set(docs) - set(params))}; write them in the Parameters section of its docstring")
    assert [n for n, doc in docs.items() if not doc.text] == []
    own = list(parse_parameters(cls.__doc__))
    assert own == [n for n in params if n in own], f"{name}: document the parameters in signature order"
