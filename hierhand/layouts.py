"""The slots of the flat arrays the C core and Python share, as the C declares them.

Each array is declared once, as a table of slots in ``hierhand/csrc/layouts.h``; the C
enums and the extension's ``LAYOUTS`` are both made from that table by the preprocessor,
and this module turns each into a ``Layout`` named as the header names it:
``REFLEX_PARAMS.KI`` is the C's ``HH_REFLEX_P_KI``, ``STATE.slice("QD")`` the joint rates
of the plant's state, ``REFLEX_RECORD.size`` the length of GraspReflex's kernel record.
Python writes no offset of its own. ``RECORDS`` gives each kernel type's record layout,
``BLOCK_CLASSES`` the block types that write them, ``INPUT_PORTS`` its input ports in the
order its kernel reads them (the blocks' ``inputs``), ``ports(OUTPUT)`` the output ports of
an output layout, ``DIMENSIONS`` the hand's sizes (fingers, joints, ...).
"""

from __future__ import annotations

from types import MappingProxyType
from typing import Mapping

from . import _native


class Layout:
    """The slots of one flat float64 array: each slot's offset as an attribute
    (``layout.KI``), its width, its slice, and the array's ``size``. A slot of width 0
    marks where a part of variable length starts. In C the slot is ``c_prefix + slot``
    (``HH_REFLEX_P_KI``) and the size ``c_size`` (``HH_REFLEX_N_PARAMS``)."""

    def __init__(self, name: str, size: int, slots: tuple[tuple[str, int, int], ...], c_prefix: str, c_size: str):
        self.name = name
        self.size = size
        self.slots = slots
        """(name, offset, width) of every slot, in order."""
        self.c_prefix = c_prefix
        self.c_size = c_size
        self._widths = {slot: width for slot, _, width in slots}
        for slot, offset, _ in slots:
            setattr(self, slot, offset)

    @property
    def open_ended(self) -> bool:
        """Whether the array goes on past ``size`` (its last slot has width 0)."""
        return self.slots[-1][2] == 0

    def width(self, slot: str) -> int:
        """How many values ``slot`` holds."""
        return self._widths[slot]

    def slice(self, slot: str) -> slice:
        """The values of ``slot``: ``array[layout.slice("QD")]``."""
        offset = getattr(self, slot)
        return slice(offset, offset + self._widths[slot])

    def __repr__(self) -> str:
        return f"<Layout {self.name}: {', '.join(name for name, _, _ in self.slots)} ({self.size} values)>"


LAYOUTS: dict[str, Layout] = {name: Layout(name, *table) for name, table in _native.LAYOUTS.items()}
"""Every layout of layouts.h by its name there (``HH_LAYOUTS`` and ``HH_RECORDS``); each is
also an attribute of this module (``from hierhand.layouts import REFLEX_PARAMS``)."""

RECORDS: dict[str, Layout] = {kind: LAYOUTS[name] for kind, name in _native.RECORD_LAYOUTS.items()}
"""The record layout of each kernel type by the type's name (``RECORDS["GraspReflex"]`` is
``REFLEX_RECORD``)."""

BLOCK_CLASSES: tuple[str, ...] = tuple(_native.BLOCK_CLASSES)
"""hierhand's block types, as ``"module:Class"`` references: the class each record of
``HH_RECORDS`` names. This tuple is hierhand's one ``blocks.types`` entry point, so a new
block type is registered by its line in layouts.h and needs no line in pyproject.toml."""

def ports(layout: Layout) -> Mapping[str, int]:
    """The ports of a layout's slots, in order: each slot's name in lower case and its width
    (a kernel's output row, or its list of input ports)."""
    return MappingProxyType({slot.lower(): width for slot, _, width in layout.slots})


def port_columns(layout: Layout) -> tuple[tuple[str, slice], ...]:
    """Each port of an output row (``ports(layout)``) with its columns: ``row[columns]``."""
    return tuple((slot.lower(), layout.slice(slot)) for slot, _, _ in layout.slots)


INPUT_PORTS: dict[str, Mapping[str, int]] = {name: ports(Layout(name, *table))
                                             for name, table in _native.INPUT_PORTS.items()}
"""Each kernel type's input ports in the order its kernel reads them (``REFLEX_INPUTS``:
{"q": 9, "tip": 9, ...}); each is also an attribute of this module."""

DIMENSIONS: dict[str, int] = dict(_native.DIMENSIONS)
"""The hand's sizes by name (``FINGERS``, ``LINKS``, ``JOINTS``, ``EDGES``, ``MAX_POINTS``)."""

globals().update(LAYOUTS)
globals().update(INPUT_PORTS)
__all__ = ["BLOCK_CLASSES", "DIMENSIONS", "INPUT_PORTS", "LAYOUTS", "Layout", "RECORDS", "port_columns", "ports", *LAYOUTS,
           *INPUT_PORTS]
