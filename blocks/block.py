"""The block contract: declared ports, parameters and feedthrough; state lives outside.

A block object is configuration only. The executor owns the state: it calls
``initial_state()`` once, then ``output`` and ``update`` at every sample hit (and the
optional ``advance`` fast path for runs of hits with held inputs). Because nothing
mutable is kept on the block, one block object can serve many runs, and a run can be
checkpointed or batched by copying its state.
"""

from __future__ import annotations

import copy
import functools
import inspect
from fractions import Fraction
from typing import TYPE_CHECKING, Any, ClassVar, Mapping

import numpy as np

if TYPE_CHECKING:
    from blocks.engine.kernel import Kernel

Signal = np.ndarray
"""A port value: a 1-D float64 array of the port's declared width."""


class BlockError(Exception):
    """Raised by a block during a run; ``port`` names the offending signal if there is one.

    An ``advance`` that fails part-way may pass ``rows``: the outputs of the hits it did
    complete, shaped as ``advance`` returns them, so the run's log keeps everything
    computed before the failure.
    """

    def __init__(self, message: str, port: str | None = None, rows: dict[str, np.ndarray] | None = None):
        super().__init__(message)
        self.port = port
        self.rows = rows


_NOT_GIVEN: Any = object()


class EndRun(Exception):
    """Raised by a block's ``update`` to end the run normally (an FMU that requests
    termination, say): the run is complete, only shorter.

    The run finishes the tick of the request, goes on to the block's next hit (or to its
    own end time if that comes first) and ends there as at a normal end time: the outputs
    of the blocks that fire there are computed and logged, nothing is updated. ``reason``
    is a short text for the status line; ``state``, when given, is the block's new state,
    as ``update`` would have returned it (otherwise the state keeps what ``update`` did
    to it in place). Only ``update`` may raise it: from ``output`` or ``advance`` it fails
    the run.
    """

    def __init__(self, reason: str, state: Any = _NOT_GIVEN):
        super().__init__(reason)
        self.reason = reason
        self.state = state

    @property
    def has_state(self) -> bool:
        return self.state is not _NOT_GIVEN


class ParameterError(ValueError):
    """Invalid parameters found by a block's constructor, one entry per problem.

    ``problems`` pairs where the offending value is (the parameter, then the keys and list
    indices into it: ``("object", "mass")``, ``("fingers", 1, "links")``; ``()`` when no
    one value is to blame) with a message naming it. The diagram loader reports each
    problem on a line of its own, at the line of the diagram, params file or ``--set``
    that gave that value; any other exception of a constructor is one problem at the
    block's parameters. ``hint``, if given, says how to fix them (the loader's default
    hint points to the type's parameter documentation).
    """

    def __init__(self, problems, message: str | None = None, hint: str = ""):
        self.problems = [(tuple(path), str(text)) for path, text in problems]
        self.hint = hint
        super().__init__(message if message is not None else "; ".join(t for _, t in self.problems))


class Block:
    """Base class of every block.

    Subclasses set, usually in ``__init__`` from their parameters:

    - ``inputs`` / ``outputs``: port name -> width. ``None`` means "same width as the
      other ``None`` ports of this block, inferred from the connections".
    - ``input_defaults``: inputs that may stay unconnected, with the value they then hold.
    - ``feedthrough``: ``True`` if every output reads every input at the same hit,
      ``False`` if no output does, or a mapping output -> set of inputs it reads.
    - ``initial_feedthrough``: the same, for the outputs at the initial tick (tick 0)
      only; ``None`` (the default) means "as ``feedthrough``". An FMU's initial outputs
      may follow the inputs set before initialisation although later outputs do not;
      the planner drops such a t = 0 dependency where it would close a loop (the input
      then holds its initial value at t = 0, see ``Schedule.initial_held``).
    - ``time_varying``: the outputs depend on ``t`` itself (sources such as Step).

    and may describe what a port's values are, for files, plots and ``hierhand blocks``:
    ``port_units(port)`` (the unit: ``"rad"``, ``"N m"``, ``"1"`` for a dimensionless
    value; one per element where they differ; None, the default, when unknown) and
    ``element_labels(port)`` (names of a vector port's elements: ``thumb.1``, ``x``).
    run.json records both for every logged signal that has them.

    and implement ``output`` (and ``update`` / ``initial_state`` if they have state).
    Parameters are the keyword arguments of ``__init__``, with their defaults; the
    ``Parameters`` section (numpydoc) of the class docstring documents them, which
    ``hierhand blocks`` shows (see ``blocks.typeinfo``).

    Block references. A parameter named in ``block_params`` takes another block of the
    same diagram, as Drake's controllers take the ``MultibodyPlant`` they model: in the
    diagram its value is that block's name (``hand: plant``), and the loader builds the
    referenced block first and passes the ``Block`` object itself to ``__init__``. So a
    model given once, on one block, is the model every block referring to it uses, and
    ``--set plant.mass=...`` reaches them all. ``Diagram.parameters()`` and run.json keep
    the name. References must not form a cycle. From Python, pass the block object.
    """

    type_name: ClassVar[str | None] = None
    path_params: ClassVar[tuple[str, ...]] = ()
    """Parameters holding file paths: the loader resolves relative ones against the
    diagram's folder, as it does ``params_file``."""
    confined_params: ClassVar[tuple[str, ...]] = ()
    """Those of ``path_params`` that name data a diagram reads (FromFile's table): as a
    params file, the file must lie in the diagram's folder or below unless the diagram is
    trusted (``--trust``), so that a diagram from elsewhere cannot play back, and copy into
    its results, a file of the user's. A path given on the command line (``--set``) is the
    user's own and may lie anywhere."""
    block_params: ClassVar[tuple[str, ...]] = ()
    """Parameters whose diagram value is the name of another block of the diagram; the
    constructor receives that block (built and bound before this one)."""
    time_varying: ClassVar[bool] = False
    samples_continuous_time: ClassVar[bool] = False
    """The block's outputs are samples of a continuous-time model (a plant integrated at
    its period), not values held between hits (a controller's): an exported FMU declares
    them ``continuous``, the others ``discrete``."""
    name: str | None = None
    """The block's name in its diagram, set by the loader once the block is built (None
    for a block made from Python); for messages of blocks that refer to it."""

    inputs: dict[str, int | None] = {}
    outputs: dict[str, int | None] = {}
    input_defaults: dict[str, Signal] = {}
    feedthrough: bool | Mapping[str, frozenset[str] | set[str]] = True
    initial_feedthrough: bool | Mapping[str, frozenset[str] | set[str]] | None = None
    period: Fraction | None = None
    port_types: Mapping[str, str] = {}
    """The value type a port's float64 values stand for, where it is not a plain real
    number (``Float64``): an FMU's ``Int32`` or ``Boolean`` ports, in FMI 3 type names. A
    connection between ports of different types is a conversion, which ``validate``
    lists with the rules of ``input_rule`` / ``output_rule``."""

    def __new__(cls, *args: Any, **kwargs: Any):
        # the arguments the constructor is called with, for constructor_arguments()
        self = super().__new__(cls)
        self._constructed_with = (args, kwargs)
        return self

    def constructor_arguments(self) -> dict[str, Any]:
        """The parameters this block was made with, by name (positional ones named after
        ``__init__``'s signature): what a diagram built from Python writes as the block's
        ``params`` when it is saved as YAML (``blocks.save_diagram``)."""
        args, kwargs = getattr(self, "_constructed_with", ((), {}))
        names = [n for n in type(self).parameters()]
        return {**dict(zip(names, args)), **kwargs}

    # -- configuration hooks, called by the diagram builder --------------------------

    def bind(self, period: Fraction | None) -> None:
        """Receive the sample period (``None`` when the diagram gives none). Override to
        precompute; a block with a natural rate of its own (an FMU's default step) may set
        ``self.period`` when given ``None``, and is then scheduled at that period."""
        self.period = period

    def set_width(self, width: int) -> None:
        """Give every port declared with width ``None`` the inferred ``width``; a block whose
        parameters cannot work at that width raises ValueError, a load error at its line."""
        self.inputs = {p: (width if w is None else w) for p, w in self.inputs.items()}
        self.outputs = {p: (width if w is None else w) for p, w in self.outputs.items()}

    # -- the run-time contract ------------------------------------------------------

    def initial_state(self) -> Any:
        """State at t = 0; ``None`` for a stateless block (its ``update`` is never called)."""
        return None

    def output(self, t: float, state: Any, inputs: Mapping[str, Signal]) -> dict[str, Signal]:
        """Outputs at a sample hit.

        ``inputs`` are read-only. Returned arrays are handed to other blocks by reference,
        so the block must not mutate them afterwards (return copies of state arrays).
        """
        raise NotImplementedError(f"{type(self).__name__}.output")

    def update(self, t: float, state: Any, inputs: Mapping[str, Signal]) -> Any:
        """Next state after a sample hit (inputs are those seen by ``output`` at this hit).

        The executor keeps no reference to the previous state, so a block may update
        the given state in place and return it. A block that wants the run to end raises
        ``EndRun`` instead of returning.
        """
        return state

    def advance(self, t: float, state: Any, inputs: Mapping[str, Signal], n: int):
        """Fast path: ``n`` updates with held inputs, the first at time ``t``.

        Returns ``(state_after_n_updates, outputs)`` where ``outputs[port]`` is an
        ``(n, width)`` array of the outputs at the ``n`` following hits
        (``t + period`` ... ``t + n * period``). Only used for blocks without
        feedthrough. This default is the reference loop; a block overrides it with
        something faster (a compiled kernel, a closed form) and the executor then uses it.
        An override that fails part-way raises ``BlockError(..., rows=...)`` with the rows of
        the hits before the failing update, so nothing computed is lost.
        """
        dt = float(self.period) if self.period is not None else 0.0
        rows: dict[str, list[Signal]] = {p: [] for p in self.outputs}
        for i in range(n):
            state = self.update(t + i * dt, state, inputs)
            out = self.output(t + (i + 1) * dt, state, inputs)
            for p in rows:
                rows[p].append(out[p])
        return state, {p: np.asarray(v, dtype=float).reshape(n, self.outputs[p]) for p, v in rows.items()}

    def kernel(self) -> Kernel | None:
        """The block's compiled step functions (``blocks.engine.kernel.Kernel``), which the
        executor calls in C instead of ``output`` / ``update`` / ``advance``; None (the
        default) runs the Python methods. Called once per run, after ``bind``."""
        return None

    # -- introspection helpers used by the loader, the scheduler and the CLI --------

    def port_type(self, port: str) -> str:
        """The type of values a port carries (``port_types``; ``Float64`` if not given)."""
        return self.port_types.get(port, "Float64")

    def input_rule(self, port: str) -> str | None:
        """What values a typed input takes (e.g. "whole numbers from 0 to 255; any other
        value stops the run"); None for a plain real input."""
        return None

    def output_rule(self, port: str) -> str | None:
        """How a typed output's values become float64 (e.g. "exact"); None if plain."""
        return None

    def port_hint(self, port: str) -> str | None:
        """Why ``port`` is not a port of this block when the name means something to it
        (an FMU's String variable), for the loader's "has no input" message; else None."""
        return None

    def element_labels(self, port: str) -> list[str] | None:
        """Names of the elements of port ``port``, one per element (``["1", "2"]``,
        ``["1,1", "1,2", ...]``, ``["thumb.1", "thumb.2", ...]``), for the CSV columns
        ``signal[label]``, the legends of plots and ``hierhand blocks``; None, the default,
        numbers them from 0. A block whose elements have names of their own (an FMU's
        ``y[1]``, ``y[2]``, a hand's fingers) returns them so that files keep them."""
        return None

    def port_units(self, port: str) -> str | list[str] | None:
        """The unit of port ``port`` (input or output): one string for all its elements
        (``"rad"``, ``"N m"``, ``"m/s"``, ``"1"`` for a dimensionless value or a flag), or
        a list of one string per element where they differ (``["m", "m", "rad"]`` for a
        pose; ``""`` for an element of unknown unit); None, the default, when the block
        does not know. Plots put it beside the signal's name and run.json keeps it
        (``units``), and a connection whose other end declares another unit is a load
        error (``blocks.builder.annotations``). A diagram may give the ports a block leaves None
        units of their own (``units: {b.y: rad}``)."""
        return None

    def describe(self) -> str:
        """A short note on where this block's configuration comes from, which
        ``hierhand validate`` prints beside the block (e.g. the model a plant simulates);
        empty for nothing to say."""
        return ""

    @classmethod
    def param_default(cls, name: str) -> Any:
        """The value a ``--set`` path into parameter ``name`` starts from when the diagram
        does not give that parameter (``--set b.gains.1=2``): here the ``__init__`` default
        if it is a list, tuple or mapping (a tuple as a list), else None, which starts an
        empty mapping. A block whose ``None`` default stands for a larger value overrides it."""
        param = cls.parameters().get(name)
        default = None if param is None else param.default
        if isinstance(default, tuple):
            return list(default)
        return copy.deepcopy(default) if isinstance(default, (list, Mapping)) else None

    @classmethod
    def override_path(cls, parts: list[str]) -> list[str]:
        """Where a ``--set block.<parts>`` path leads in the block's parameters: here the
        path itself. A block whose parameters hold named values of their own (an FMU's
        variables in ``start_values``) may lead a path that names none of its parameters
        there, so that ``--set plant.k=2`` sets what the block calls ``k``."""
        return parts

    @classmethod
    def registered_name(cls) -> str:
        return cls.type_name or cls.__name__

    @classmethod
    def example(cls) -> "Block":
        """An instance for documentation (``hierhand blocks`` lists its ports): by default
        the block with its default parameters. A block whose parameters are required, such
        as a reference to another block, overrides it with a typical instance."""
        return cls()

    @classmethod
    def parameters(cls) -> dict[str, inspect.Parameter]:
        """The block's parameters: the keyword arguments of its ``__init__``."""
        return _init_parameters(cls.__init__)

    @classmethod
    def accepts_any_parameter(cls) -> bool:
        """True when ``__init__`` takes ``**kwargs`` (parameters are then not checked by name)."""
        return _accepts_any(cls.__init__)

    def finish(self, state: Any) -> None:
        """Called once after a run's last tick (complete, failed or interrupted), before
        its results are made, with the block's last state: let go of what the state holds
        for the run (an FMU block terminates its instance here). A BlockError raised here
        fails a run that was complete, at the time it ended."""

    def is_stateful(self) -> bool:
        return self.initial_state() is not None

    def has_fast_advance(self) -> bool:
        return type(self).advance is not Block.advance

    def reads(self, output_port: str) -> frozenset[str]:
        """The input ports that ``output_port`` depends on at the same hit."""
        return self._read_by(self.feedthrough, output_port)

    def initial_reads(self, output_port: str) -> frozenset[str]:
        """The input ports that ``output_port`` depends on at the initial tick (tick 0)."""
        ft = self.initial_feedthrough
        return self.reads(output_port) if ft is None else self._read_by(ft, output_port)

    def _read_by(self, ft, output_port: str) -> frozenset[str]:
        """The inputs ``output_port`` reads under the feedthrough declaration ``ft``."""
        if ft is True:
            return frozenset(self.inputs)
        if ft is False:
            return frozenset()
        return frozenset(ft.get(output_port, ()))

    def has_feedthrough(self) -> bool:
        return any(self.reads(p) for p in self.outputs)

    def loop_remedy(self, name: str) -> str | None:
        """How else than a delay an algebraic loop through this block (named ``name`` in
        its diagram) can be broken, for the loop's message; None: no other way."""
        return None


def checked_units(units: Any, width: int | None, port: str) -> str | list[str] | None:
    """``Block.port_units`` as files keep it: None, one string, or one string per element
    (a list whose elements are all alike becomes that one string); ValueError for anything
    else, or a list whose length is not ``width`` (not checked when ``width`` is None)."""
    if units is None or isinstance(units, str):
        return units
    if not isinstance(units, (list, tuple)) or not all(isinstance(u, str) for u in units):
        raise ValueError(f"the units of '{port}' must be a string or a list of strings, got {units!r}")
    if width is not None and len(units) != width:
        raise ValueError(f"{len(units)} units for the {width} elements of '{port}'")
    if units and all(u == units[0] for u in units):
        return units[0]
    return list(units)


@functools.cache
def _init_parameters(init) -> dict[str, inspect.Parameter]:
    sig = inspect.signature(init)
    return {name: p for name, p in sig.parameters.items()
            if name != "self" and p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)}



@functools.cache
def _accepts_any(init) -> bool:
    return any(p.kind == p.VAR_KEYWORD for p in inspect.signature(init).parameters.values())
