"""The hierhand blocks' compiled kernels: their records, and contexts built from them.

The kernels are kernel types in C (``hierhand/csrc/kernels.h``): a constructor that
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
plant's record by a ``Link``, so an FMU parameter ``plant.object.mass`` reaches them all,
as ``--set plant.object.mass=...`` does.
"""

from __future__ import annotations

import re
from typing import Any

import numpy as np

from blocks.engine.kernel import Follow, KernelRecord, Link, Tunable

from . import _native

KERNELS: dict[str, int] = _native.kernels()
"""Function addresses by ``"Block.phase"``: the types of ``blocks/csrc/blocks_kernel.h``."""

Context = _native.Context
"""``Context(kind, record)``: the context kind's constructor builds from a record (its
``address`` is a Kernel's context; keep the object alive); ValueError with the
constructor's message for numbers it refuses."""

_L = _native.LAYOUT
SEG_FOLLOWS: int = _L["SEG_FOLLOWS"]
SEG_HAND: int = _L["SEG_HAND"]
SEGMENT: int = _L["SEGMENT"]
"""A hand segment's layout: the follows flag, then the hand vector (hand.h)."""

PLANT_SEGMENT = 1
"""Where HandPlant's record holds its hand segment (after its step)."""

OBJECT_SHAPE = ("object.mass", "object.size[1]", "object.size[2]")
"""The numbers an object's plate inertia is computed from."""

_UNIT = re.compile(r"\[([^\]]+)\]$")


def hand_segment(hand: Any, follows: bool) -> np.ndarray:
    """A hand's segment (``hand``: a ``Hand``): ``follows`` whether its object's inertia
    is computed from its mass and size."""
    return np.concatenate(([1.0 if follows else 0.0], hand.vector))


def hand_link(source: Any, slot: int = 0) -> tuple[Link, ...]:
    """The link of a record's hand segment at ``slot`` to the plant block ``source`` (none
    when the hand was given otherwise, as a ``Hand``)."""
    from .model.plant import HandPlant

    return (Link(slot, SEGMENT, source, PLANT_SEGMENT),) if isinstance(source, HandPlant) else ()


def hand_tunables(at: int) -> tuple[Tunable, ...]:
    """The hand's numbers as tunables, named as the C core names them, for a segment at
    ``at``: their hand-file description and its unit."""
    out = []
    for i, (name, doc) in enumerate(_native.hand_parameters()):
        unit = _UNIT.search(doc)
        out.append(Tunable(name, at + SEG_HAND + i, doc, unit.group(1) if unit else "1"))
    return tuple(out)


def inertia_follows(at: int) -> tuple[Follow, ...]:
    """The rule that the object's inertia follows its mass and size once one of them is set
    (and it is not), for a segment at ``at``."""
    return (Follow(at + SEG_FOLLOWS, OBJECT_SHAPE, ("object.inertia",)),)


def record(kind: str, *parts: Any, tunables: tuple[Tunable, ...] = (), links: tuple[Link, ...] = (),
           follows: tuple[Follow, ...] = ()) -> KernelRecord:
    """A record of ``kind`` whose values are ``parts`` (numbers and arrays) one after the other
    (every hand kind builds its block's state, kernels.h)."""
    values = np.concatenate([np.asarray(p, dtype=np.float64).ravel() for p in parts])
    values.flags.writeable = False
    return KernelRecord(kind, values, tunables, links, follows, builds_state=True)


def context_of(rec: KernelRecord) -> Any:
    """The ``Context`` a record's constructor builds."""
    return Context(rec.kind, rec.values)
