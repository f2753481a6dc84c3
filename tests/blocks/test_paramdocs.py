"""Parameter documentation from the class docstring's numpydoc ``Parameters`` section."""

from __future__ import annotations

import pytest

from blocks import Block
from blocks.library import LIBRARY
from blocks.paramdocs import ParamDoc, parameter_docs, parse_parameters
from blocks.typeinfo import describe_type


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


class Legacy(Block):
    """A block with the older ``param_docs``, which wins over its docstring.

    Parameters
    ----------
    a : int
        from the docstring
    b : int
        from the docstring too
    """

    param_docs = {"a": "from param_docs"}

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


def test_param_docs_still_win_and_subclasses_inherit_what_they_do_not_document():
    assert parameter_docs(Legacy) == {"a": ParamDoc("", "from param_docs"),
                                      "b": ParamDoc("int", "from the docstring too")}
    refined = parameter_docs(Refined)
    assert refined["gain"] == ParamDoc("int", "a whole gain")
    assert refined["lo"] == ParamDoc("scalar or vector", "the limits")


def test_hierhand_blocks_shows_type_default_and_text_from_the_docstring():
    text = describe_type(Documented)
    assert "    gain (float; default 2.0): how much the input is scaled, on two lines and a second paragraph\n" in text
    assert "    mode (default 'a')\n" in text


@pytest.mark.parametrize("cls", LIBRARY, ids=lambda cls: cls.registered_name())
def test_every_library_block_documents_exactly_its_parameters_in_its_docstring(cls):
    assert "param_docs" not in vars(cls), "document the parameters in the docstring's Parameters section"
    docs = parse_parameters(cls.__doc__)
    assert list(docs) == list(cls.parameters())
    assert all(doc.text for doc in docs.values())
