"""Compiled kernels: how a block offers C versions of its step functions to the executor.

A block whose ``output`` / ``update`` / ``advance`` exist as C functions of the calling
convention in ``blocks/csrc/blocks_kernel.h`` returns a ``Kernel`` from
``Block.kernel()``. The executor's C core (``blocks/csrc/core.c``) then calls them
directly while it interprets the run's op table (no Python between the 1 ms hits of a
controller and a plant, say). A block without a kernel runs through its Python methods,
called by the core's host as ops of the same table; both kinds mix freely in one diagram.

A block whose kernel writes anything besides its state (an FMU instance's time and
outputs, the plant's scratch) gives its Kernel a ``bind``: the executor calls
``bind(state)`` once per run and uses the Kernel it returns, whose context is that run's
own. The bound functions get the state when it is a flat float64 array (the plant's), and
NULL otherwise (an FMU's live instance, whose changes they keep in the context).
Functions may call back into Python (the executor holds the GIL for them), return
``RAISED`` with a Python exception set, and an update may return ``END_RUN`` to end the
run as ``EndRun`` does.

A kernel that needs no GIL says so with ``nogil``: its functions call nothing of Python's
C API and write only the state, their outputs and a context no other run uses at the
same time (a constant one, or one ``bind`` made for this run). The executor then runs
them with the GIL released, so that threads that simulate diagrams (a thread pool, a
Dask worker's threads, a GUI beside a run) run in parallel; it holds the GIL for the
others, such as the FMU kernel that calls back into Python.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

ErrorFactory = Callable[[int, int, float, str], BaseException]
"""``error(code, which, t, phase)``: the exception for a kernel's failure code at time
``t`` in ``phase`` ('output', 'update' or 'advance')."""

END_RUN = -1
"""``BLK_END_RUN``: an update that is done and asks to end the run; ``Kernel.error(END_RUN,
...)`` returns the block's ``EndRun``, whose reason the run records."""

RAISED = -2
"""``BLK_RAISED``: the kernel set a Python exception, which is the step's error as it is."""


def address(array: np.ndarray) -> int:
    """The address of a C-contiguous array's first element, for a kernel's context (keep
    the array alive in ``Kernel.owners``)."""
    if not (isinstance(array, np.ndarray) and array.flags.c_contiguous):
        raise TypeError("a kernel reads C-contiguous arrays; got "
                        + (f"a non-contiguous {array.dtype} array" if isinstance(array, np.ndarray)
                           else type(array).__name__))
    return array.__array_interface__["data"][0]


@dataclass(frozen=True)
class Tunable:
    """A parameter of a block that an exported FMU lets an importer set: its ``name`` as a
    path inside the block (``ki``, ``object.mass``, ``kp[3]``), the slot of the record it
    is written to, what it is and its unit (None: none known)."""

    name: str
    slot: int
    description: str = ""
    unit: str | None = None
    finite: bool = False
    """The value must be finite, the block's one check of it (the kind's constructor
    checks the others)."""
    minimum: float | None = None
    maximum: float | None = None
    """The closed range the kind's constructor holds the value to (a bound of a range
    open at that end, ``> 0``, is given as the closed one, 0: FMI's ``min``/``max`` are
    inclusive); None: unbounded that side."""


@dataclass(frozen=True)
class Link:
    """``length`` slots of a record, from ``slot`` on, that are ``source_slot``... of the
    record of the block ``source`` (a Block object): a value a block takes from another
    (a controller's hand from its plant), which an exported FMU copies over when it
    rebuilds the contexts, after its parameters are written, so that the copy follows
    them. A source that is no block of the exported diagram leaves the slots as they are."""

    slot: int
    length: int
    source: Any = field(repr=False)
    source_slot: int


@dataclass(frozen=True)
class Follow:
    """A flag slot that an exported FMU sets to 1 when its importer sets any of the
    tunables ``when_set`` and none of ``unless_set`` (names as ``Tunable.name``): how a
    derived value follows the values it derives from (an object's inertia its mass and
    size, unless the inertia itself is set), for the kind's constructor to read."""

    slot: int
    when_set: tuple[str, ...]
    unless_set: tuple[str, ...] = ()


@dataclass(frozen=True)
class KernelRecord:
    """What a program without Python (an exported FMU) rebuilds a block's kernel from: the
    name of a kernel type (``blk_kernel_type`` in ``blocks/csrc/blocks_kernel.h``: ``gain``,
    ``HandPlant``) and the numbers its constructor reads, the block's parameters in the
    type's order. ``tunables`` are the slots an importer may set, ``links`` and
    ``follows`` how slots follow others. The same constructor builds the context a native
    run uses where the block's Python side asks it to (the hand's blocks), or the record is
    the context itself (the library's)."""

    kind: str
    values: np.ndarray = field(repr=False)
    tunables: tuple[Tunable, ...] = ()
    links: tuple[Link, ...] = ()
    follows: tuple[Follow, ...] = ()
    builds_state: bool = False
    """Whether the kind's constructor also makes the block's initial state (so that a
    parameter the state starts from, or whose value sizes it, follows); else the FMU keeps
    the state the block's ``initial_state`` gives."""


@dataclass(frozen=True)
class Kernel:
    """The addresses of a block's C functions and of the constants they read.

    ``output``, ``update`` and ``advance`` are function addresses (0 where the block has
    none; a block whose schedule needs a function its kernel lacks runs in Python).
    ``context`` is the pointer passed to them as ``ctx``; ``owners`` keeps alive the
    objects whose memory it and the functions use. The block's state must be a flat
    C-contiguous float64 array (or None for a stateless block), which the kernel updates
    in place, unless the Kernel has a ``bind``: then ``bind(state)`` gives the Kernel of
    one run, whose context holds what the functions change (they get NULL as state). The
    functions compute what the Python methods compute (to round-off; a run uses one or
    the other for all of a block's hits). ``error`` makes the exception for a failure
    code, and the ``EndRun`` for ``END_RUN`` (None: ``blocks.engine.compiled.failure``, a
    message with the code). ``nogil``: the functions may run without the GIL (see the
    module's docstring; what a bound kernel says is what counts). ``record``: how an
    exported FMU rebuilds the context (None: the kernel cannot leave Python, like the FMU
    block's, which calls back into it).
    """

    context: int
    output: int = 0
    update: int = 0
    advance: int = 0
    owners: tuple[Any, ...] = field(default=(), repr=False)
    error: ErrorFactory | None = field(default=None, repr=False)
    bind: Callable[[Any], Kernel] | None = field(default=None, repr=False)
    nogil: bool = False
    record: KernelRecord | None = field(default=None, repr=False)
