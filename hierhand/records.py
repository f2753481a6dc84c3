"""The hierhand blocks' kernel records, and the contexts their kernel types build from them.

The kernels are kernel types in C (``hierhand/csrc/kernel_types.h``): a constructor that
builds a context from a record of doubles (``blocks.engine.kernel.KernelRecord``), and adapters
that call the very functions the blocks' Python methods call, so either path gives the
same bits. A block's ``kernel()`` writes its record and makes a ``Context`` of it through
that constructor, the one an exported FMU calls to rebuild the block from the same record
with its tunable parameters written in. ``KERNELS`` holds the adapters' addresses by
``"Block.phase"`` (``"HandPlant.advance"``). The adapters call no Python and write only
the state, the outputs and the plant's own context (one per run, made by its Kernel's
``bind``), so every Kernel says ``nogil``.

A hand travels in a record as a segment: a flag saying whether the object's inertia
follows its mass and size, then the hand vector. The plant's record holds its hand's
numbers as tunables; a controller that models the plant's hand takes its segment from the
plant's record by a ``Link`` (``model.hand_source.hand_link``), so an FMU parameter
``plant.object.mass`` reaches them all, as ``--set plant.object.mass=...`` does. Each
record's slots are a layout of ``hierhand/csrc/layouts.h`` (``hierhand.layouts``:
``PLANT_RECORD``, ``REFLEX_RECORD``, ...), and ``record`` checks a record's length
against it.
"""

from __future__ import annotations

import re
from typing import Any

import numpy as np

from blocks.engine.kernel import Follow, KernelRecord, Link, Tunable

from . import _native
from .layouts import RECORDS, SEGMENT

KERNELS: dict[str, int] = _native.kernels()
"""Function addresses by ``"Block.phase"``: the types of ``blocks/csrc/blocks_kernel.h``."""

Context = _native.Context
"""``Context(kind, record)``: the context kind's constructor builds from a record (its
``address`` is a Kernel's context; keep the object alive); ValueError with the
constructor's message for numbers it refuses."""

OBJECT_SHAPE = ("object.mass", "object.size[1]", "object.size[2]")
"""The numbers an object's plate inertia is computed from."""

_UNIT = re.compile(r"\[([^\]]+)\]$")


def hand_segment(hand: Any, follows: bool) -> np.ndarray:
    """A hand's segment (``hand``: a ``Hand``): ``follows`` whether its object's inertia
    is computed from its mass and size."""
    return np.concatenate(([1.0 if follows else 0.0], hand.vector))


def hand_tunables(at: int) -> tuple[Tunable, ...]:
    """The hand's numbers as tunables, named as the C core names them, for a segment at
    ``at``: their hand-file description and its unit."""
    out = []
    for i, (name, doc, at_least_zero) in enumerate(_native.hand_parameters()):
        unit = _UNIT.search(doc)
        out.append(Tunable(name, at + SEGMENT.HAND + i, doc, unit.group(1) if unit else "1",
                           minimum=0.0 if at_least_zero else None))
    return tuple(out)


def inertia_follows(at: int) -> tuple[Follow, ...]:
    """The rule that the object's inertia follows its mass and size once one of them is set
    (and it is not), for a segment at ``at``."""
    return (Follow(at + SEGMENT.FOLLOWS, OBJECT_SHAPE, ("object.inertia",)),)


def record(kind: str, *parts: Any, tunables: tuple[Tunable, ...] = (), links: tuple[Link, ...] = (),
           follows: tuple[Follow, ...] = ()) -> KernelRecord:
    """A record of ``kind`` whose values are ``parts`` (numbers and arrays) one after the other,
    in the order of the kind's record layout (``hierhand.layouts.RECORDS[kind]``), whose
    size they fill (or exceed, where its last slot is of variable length). Every hand kind
    builds its block's state (kernel_types.h)."""
    values = np.concatenate([np.asarray(p, dtype=np.float64).ravel() for p in parts])
    layout = RECORDS[kind]
    if values.size != layout.size and not (layout.open_ended and values.size > layout.size):
        raise ValueError(f"a {kind} record holds the {layout.size} values of {layout.name}, not {values.size}")
    values.flags.writeable = False
    return KernelRecord(kind, values, tunables, links, follows, builds_state=True)


def context_of(rec: KernelRecord) -> Any:
    """The ``Context`` a record's constructor builds."""
    return Context(rec.kind, rec.values)
