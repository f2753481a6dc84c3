"""The FMU block, and its run state: an FMI 2.0 / 3.0 co-simulation or model-exchange FMU as a block.

``FMU`` is what a diagram's ``type: FMU`` makes (the semantics are in the package
docstring). Making it reads and checks the FMU's modelDescription and the block's
parameters and runs none of the FMU's code, so loading, ``validate`` and ``graph`` are
safe; binding it to its period checks the period against the FMU's step rules
(co-simulation) or the solver's sub-step (model exchange). ``initial_state()`` gives each
run an ``FMUState``: a handle to one instance of the block's pool, taken at the run's
first ``output`` or ``update``. ``output`` returns the outputs at the current hit;
``update`` steps the FMU to the next hit with the inputs held (a doStep, or the model
integrated by the block's solver) and reads the outputs there. A scheduled-execution
FMU is activated instead: ``output`` sets the inputs, activates the partitions of the
clocks that tick at the hit and reads the outputs (``scheduled``). Failures become
BlockErrors naming the FMU, the time and the status, with the FMU's recent log; a request
to terminate becomes ``EndRun``; Ctrl-C inside an FMU call stays a KeyboardInterrupt
(``interrupt``).
"""

from __future__ import annotations

import os
import weakref
import zipfile
from collections.abc import Mapping
from fractions import Fraction
from pathlib import Path
from typing import Any, Callable

from ..block import Block, BlockError, EndRun, ParameterError, Signal
from blocks.engine.kernel import Kernel
from ..timebase import format_duration
from . import interrupt
from .description import FMUNotFound, open_fmu_file
from .instance import Instance
from blocks.fmu.compiled_step import fmu_kernel
from .log_messages import status_name
from .model import INTERFACES, ISOLATIONS, float_or_none, isolation_choice
from .pool import PooledModel
from .clocks import ClockRun, check_period
from .solvers import DEFAULT_TOLERANCE, CallFailed, Integration, SolverError, integration, solver_choice
from .start_values import assignments, input_starts, start_of

SAME_STEP = Fraction(1, 10**9)
"""How far (relative) a period may be from the step of an FMU that cannot vary its
communication step and still count as that step."""


class FMUState:
    """The run state of an FMU block: a handle to one FMU instance (external and mutable).

    ``instance`` is taken from the block's pool when the run first needs it (its first
    ``output`` or ``update``), so creating the state runs none of the FMU's code.
    ``time`` is the FMU's current communication point (None before initialisation) and
    ``outputs`` the FMU outputs there. ``close()`` gives the instance back to the block
    early; otherwise that happens when the state is garbage collected.
    """

    __slots__ = ("instance", "model", "time", "outputs", "ended", "clocks", "_release", "__weakref__")

    def __init__(self, model: PooledModel):
        if model.closed:
            raise BlockError(f"{model.shown}: the FMU block was closed")
        self.instance: Instance | None = None
        self.model = model
        self.time: float | None = None
        self.outputs: dict[str, Signal] | None = None
        self.ended: float | None = None
        self.clocks = ClockRun()
        """Scheduled execution: what the run remembers of its clocks."""
        self._release: weakref.finalize | None = None

    def acquire(self) -> Instance:
        """The run's instance, taken from the pool (loading the FMU) on first use."""
        if self.instance is None:
            self.instance = self.model.acquire()
            self._release = weakref.finalize(self, self.model.release, self.instance)
        return self.instance

    def close(self) -> None:
        if self._release is not None:
            self._release()

    def finish(self) -> None:
        """Give the instance back at the end of its run, terminate (and, in a process of
        its own, freeInstance) included: their failure raises, to fail the run."""
        if self._release is not None and self._release.alive:
            self._release.detach()
            self.model.release(self.instance, report=True)

    def __deepcopy__(self, memo):
        raise TypeError("the state of an FMU block is a live FMU instance and cannot be copied")

    def __repr__(self) -> str:
        return f"FMUState({self.model.shown}, t={self.time})"


class FMU(Block):
    """An FMI 2.0 / 3.0 FMU: co-simulation (its period the communication step) or model
    exchange (integrated between its hits by the block's solver).

    Parameters
    ----------
    path : str or path
        the .fmu file; in a diagram a relative path is resolved against the diagram's
        folder (from Python, against the current directory)
    start_values : mapping
        FMU variable names to start values (parameters, inputs, variables with an
        exact/approx start); a vector 'x' for x[1], x[2], ... or an FMI 3 array takes a list
    tolerance : float
        relative tolerance: passed to the FMU, and for model exchange the solver's (CVode's
        relative tolerance; Euler locates state events to it times the sub-step); default:
        the FMU's DefaultExperiment tolerance, for model exchange else 1e-5
    interface : str
        'co_simulation', 'model_exchange' or 'scheduled_execution' (FMI 3); default:
        co-simulation where the FMU offers it, else model exchange, else scheduled execution
    solver : str
        model exchange only: 'cvode' (SUNDIALS' CVode as fmpy ships it, the default) or
        'euler' (forward Euler with a fixed sub-step)
    substep : duration
        'solver: euler' only: the sub-step, which must divide the period; default: the
        FMU's DefaultExperiment stepSize (made to divide the period), else the period
    feedthrough : bool
        co-simulation only. true (the default there): at a hit, the inputs are set and then the
        outputs the FMU declares dependent on them (its ModelStructure Outputs: all of its
        inputs where an output has no dependencies attribute) are read, before the blocks
        downstream read them, as OMSimulator orders the exchange; a loop through those
        dependencies is an algebraic loop. false: every output comes from before the
        hit's inputs are set (the Jacobi exchange, as libcosim's master does), so the FMU
        has no feedthrough and breaks any loop through it
    isolation : str
        'process': each instance runs in a process of its own, so that a crash, an exit()
        or a hang in the FMU fails the run (with its results so far) instead of ending it;
        'none': in the run's process, the fastest. Default: 'none' for FMUs exported by
        this project's 'fmu export', 'process' for all others
    call_timeout : duration
        'isolation: process' only: how long one call into the FMU (a step, initialisation,
        ...) may take before the FMU counts as hung and the run fails; default 10 min
    """
    time_varying = True
    path_params = ("path",)

    def __init__(self, path: Any, start_values: Mapping[str, Any] | None = None,
                 tolerance: float | None = None, interface: str | None = None, solver: str | None = None,
                 substep: Any = None, feedthrough: bool | None = None, isolation: str | None = None,
                 call_timeout: Any = None):
        if not isinstance(path, (str, os.PathLike)) or not str(path).strip():
            raise ValueError(f"parameter 'path' must be the path of an .fmu file, got {path!r}")
        file = Path(path).expanduser()
        resolved = (file if file.is_absolute() else Path.cwd() / file).absolute()
        shown = f"FMU '{path}'"
        try:
            with open_fmu_file(resolved, shown) as fp:
                fp.read(1)  # a file that cannot be read says so (is_zipfile would call it no zip archive)
                fp.seek(0)
                is_zip = zipfile.is_zipfile(fp)
        except FMUNotFound:
            raise ParameterError([(("path",), f"FMU file not found: looked at {resolved} (in a diagram, a "
                                  "relative path is resolved against the diagram's folder; from Python, "
                                  "against the current directory)")],
                                 hint="check the path; an FMU that a tool exports must be exported "
                                      "before a diagram can use it") from None
        except OSError as exc:
            raise ValueError(f"{shown} cannot be read: {exc.strerror or exc}") from None
        if not is_zip:
            raise ValueError(f"{shown} is not an FMU: not a zip archive")
        if start_values is None:
            start_values = {}
        if not isinstance(start_values, Mapping):
            raise ValueError("parameter 'start_values' must be a mapping of variable names to values, "
                             f"got {type(start_values).__name__}")
        if tolerance is not None:
            tolerance = float_or_none(tolerance)
            if tolerance is None:
                raise ValueError("parameter 'tolerance' must be a positive number")
        if interface is not None and interface not in INTERFACES:
            raise ValueError(f"parameter 'interface' must be one of {', '.join(INTERFACES)}, got {interface!r}")
        self._solver, self._substep = solver_choice(solver, substep)
        self.path = resolved
        self._model = PooledModel(resolved, shown, interface)
        model = self._model
        if not model.exchange and (solver is not None or substep is not None):
            given = "solver" if solver is not None else "substep"
            other = ("ask for 'interface: model_exchange' to integrate it with the block's solver"
                     if model.md.modelExchange is not None else "it has no model-exchange interface")
            raise ValueError(f"parameter '{given}' is for model-exchange FMUs; {shown} runs as co-simulation, "
                             f"with its own solver ({other})")
        model.isolation, model.timeout = isolation_choice(model, isolation, call_timeout)
        if model.scheduled and model.isolation == "process":
            if isolation == "process":
                raise ValueError(f"{shown} runs scheduled execution, which the block runs in the run's process "
                                 "only; drop 'isolation: process'")
            model.isolation = "none"
        self._assignments = assignments(model, start_values)
        self.tolerance = tolerance if tolerance is not None else model.default_tolerance
        if model.exchange and self.tolerance is None:
            self.tolerance = DEFAULT_TOLERANCE
        self.inputs = {p.name: p.width for p in model.inputs.values()}
        self.outputs = {p.name: p.width for p in model.outputs.values()}
        self._clock_ports = {c.port: c.name for c in model.clocks if c.kind in ("triggered", "output")}
        """Scheduled execution: the ports of its triggered input clocks and its output clocks."""
        for c in model.clocks:
            if c.kind in ("triggered", "output"):
                (self.inputs if c.kind == "triggered" else self.outputs)[c.port] = 1
        self.input_defaults = input_starts(model, self._assignments)
        self.port_types = {p.name: p.kind.name for p in (*model.inputs.values(), *model.outputs.values())}
        if feedthrough is not None and not isinstance(feedthrough, bool):
            raise ValueError(f"parameter 'feedthrough' must be true or false, got {feedthrough!r}")
        if feedthrough and model.exchange:
            raise ValueError(f"parameter 'feedthrough' is for co-simulation FMUs; {shown} runs as model exchange")
        self._direct = ((model.scheduled or (feedthrough is not False and not model.exchange))
                        and any(model.direct_reads.values()))
        self.feedthrough = model.direct_reads if self._direct else False
        if model.scheduled and self._clock_ports:  # a triggered clock's port reaches every output at once
            self._direct = True
            self.feedthrough = {out: frozenset(self.inputs) for out in self.outputs}
        # scheduled execution: the clocks that tick at t = 0 are activated with the inputs there
        self.initial_feedthrough = self.feedthrough if model.scheduled else model.initial_reads
        self._step = 0.0
        self._period = Fraction(0)
        self.integration: Integration | None = None
        """How a model-exchange FMU is integrated between the hits, once the block has its period."""

    @classmethod
    def override_path(cls, parts: list[str]) -> list[str]:
        """``--set plant.k=2`` sets the FMU variable ``k`` (``start_values.k``) when ``k`` is
        not a parameter of the block; the rest of the path is the variable's name, dots
        and all (``--set plant.body.m=2``: the variable ``body.m``)."""
        if parts[0] in cls.parameters():
            return parts
        return ["start_values", ".".join(parts)]

    @property
    def fmi_version(self) -> str:
        return self._model.md.fmiVersion

    @property
    def default_step(self) -> Fraction | None:
        """The FMU's DefaultExperiment stepSize, if it declares one."""
        return self._model.default_step

    @property
    def interface(self) -> str:
        """The interface the block runs: 'co-simulation' or 'model exchange'."""
        return self._model.interface

    @property
    def isolation(self) -> str:
        """Where the block's instances run: 'process' (each in a process of its own) or 'none'."""
        return self._model.isolation

    def describe(self) -> str:
        model, given = self._model, len(self._assignments)
        notes = [f"{given} start value{'s' if given != 1 else ''} set"] if given else []
        if model.exchange:
            if self.integration is not None:
                notes.append(self.integration.describe())
            states, indicators = model.states, model.indicators
            notes.append(f"{states} continuous state{'s' if states != 1 else ''}, {indicators} event "
                         f"indicator{'s' if indicators != 1 else ''}")
        elif model.fixed_step is not None:
            notes.append(f"fixed internal step {format_duration(model.fixed_step)}, informative")
        return (f"FMI {self.fmi_version} {model.interface} {model.shown}" + (f" ({'; '.join(notes)})" if notes else "")
                + f", runs {ISOLATIONS[model.isolation]}")

    def parameter_values(self) -> dict[str, Any]:
        """Every parameter variable (causality ``parameter``) with the value a run starts
        it with: the block's ``start_values`` over the modelDescription's start. Real and
        Float values as float, integers as int, Boolean as bool, String as str, an FMI 3
        array as a list. A parameter with neither is left out. For tools that model what
        the FMU simulates (a controller built for an exported plant)."""
        given = {a.vr: a.values for a in self._assignments}
        out: dict[str, Any] = {}
        for v in self._model.md.modelVariables:
            if v.causality != "parameter":
                continue
            values = given.get(v.valueReference)
            if values is None:
                values = start_of(v)
            if values:
                out[v.name] = values if v.dimensions else values[0]
        return out

    def element_labels(self, port: str) -> list[str] | None:
        """A vector port's elements by the FMU's own indices (``y[1]``, ``A[1,2]``), from 1."""
        spec = self._model.inputs.get(port) or self._model.outputs.get(port)
        return spec.labels if spec is not None else None

    def port_units(self, port: str) -> str | list[str] | None:
        """The unit the modelDescription gives the variable(s) behind a port (their own
        ``unit`` or their declared type's); None where it gives none."""
        spec = self._model.inputs.get(port) or self._model.outputs.get(port)
        return spec.units if spec is not None else None

    def input_rule(self, port: str) -> str | None:
        spec = self._model.inputs.get(port)
        return None if spec is None or spec.kind.name == "Float64" else spec.kind.input_rule()

    def output_rule(self, port: str) -> str | None:
        spec = self._model.outputs.get(port)
        return None if spec is None or spec.kind.name == "Float64" else spec.kind.output_rule()

    def port_hint(self, port: str) -> str | None:
        """Why ``port`` is not a port of this FMU, when it names one of its variables."""
        why = self._model.not_ports.get(port)
        return f"{why} ({self._model.shown})" if why else None

    def element_variables(self, port: str) -> list[str] | None:
        """The FMU variable behind each element of a port (``q[1]``, ``q[2]``, ...; a scalar's
        own name), as other tools name them (an SSD's connectors); None for an FMI 3
        array, whose elements are one variable."""
        if port in self._clock_ports:
            return [self._clock_ports[port]]
        spec = self._model.inputs.get(port) or self._model.outputs.get(port)
        if spec is None:
            raise KeyError(port)
        if len(spec.vrs) != spec.width:
            return None
        if spec.labels is None:
            return [spec.source]
        base = spec.source[:-len("[...]")] if spec.source.endswith("[...]") else spec.source
        return [f"{base}[{label}]" for label in spec.labels]

    def assigned_values(self) -> list[tuple[str, str, list]]:
        """The start values the block sets: (variable, FMI type, values), in the order given."""
        return [(a.name, a.kind, list(a.values)) for a in self._assignments]

    def variable_of(self, port: str) -> str:
        """The FMU variable (or vector ``x[...]``) behind a port, for messages and tools."""
        if port in self._clock_ports:
            return self._clock_ports[port]
        spec = self._model.inputs.get(port) or self._model.outputs.get(port)
        if spec is None:
            raise KeyError(port)
        return spec.source

    def bind(self, period: Fraction | None) -> None:
        """The period is the communication step (co-simulation) or the interval between the
        hits at which the inputs are set and the outputs read (model exchange); without one,
        the FMU's default step (DefaultExperiment stepSize) is used, and the diagram
        schedules the block at it. A co-simulation FMU that cannot vary its communication
        step takes only the step it declares; for model exchange the period must be a whole
        number of Euler sub-steps."""
        given = period is not None
        model = self._model
        if period is None:
            period = model.default_step
            if period is None and model.default_step_problem:
                raise ValueError(f"an FMU block needs a period, the interval between its hits, and {model.shown} "
                                 f"has no usable default: {model.default_step_problem}; add e.g. 'period: 1 ms'")
            if period is None:
                raise ValueError("an FMU block needs a period, the interval between its hits (the FMU "
                                 "declares no default step size: add e.g. 'period: 1 ms')")
        if model.exchange and self._solver == "euler" and self._substep is None and model.default_step_problem:
            raise ValueError(f"'solver: euler' takes its sub-step from the FMU's default step, and {model.shown} "
                             f"has no usable one: {model.default_step_problem}; add e.g. 'substep: 1 ms'")
        if model.exchange:
            self.integration = integration(self._solver, self._substep, model.default_step, self.tolerance, period)
            model.integration = self.integration
        elif model.scheduled:
            check_period(model.clocks, period, model.shown)
        else:
            self._check_step(period, given)
        super().bind(period)
        self._period = period
        self._step = float(period)

    def _check_step(self, period: Fraction, given: bool) -> None:
        """ValueError if the co-simulation FMU says it cannot vary its communication step
        (canHandleVariableCommunicationStepSize false) and the period is not the step it
        declares (its DefaultExperiment stepSize, else its fixed internal step)."""
        model = self._model
        declared = model.default_step or model.fixed_step
        if model.can_vary_step or declared is None or abs(period - declared) <= SAME_STEP * declared:
            return
        which = "period" if given else "default step"
        source = "DefaultExperiment stepSize" if model.default_step else "fixedInternalStepSize"
        raise ValueError(f"the {which} {format_duration(period)} is not the step {format_duration(declared)} of "
                         f"{model.shown} (its {source}), which cannot vary its communication step "
                         f"(canHandleVariableCommunicationStepSize is false); use 'period: {format_duration(declared)}'")

    def is_stateful(self) -> bool:  # without instantiating the FMU, as initial_state() would
        return True

    def initial_state(self) -> FMUState:
        return FMUState(self._model)

    def _start(self, t: float, state: FMUState, inputs: Mapping[str, Signal]) -> None:
        """The run's first call: take an instance (loading the FMU) and initialise it at
        ``t`` with the inputs it has now (connected ones are computed first when the FMU's
        initial outputs depend on them, see ``initial_feedthrough``)."""
        inst = state.acquire()
        try:
            inst.start(t, self._assignments, self.tolerance, inputs)
            state.time = t
            state.outputs = inst.read(t)
        except BlockError:
            inst.broken = True
            interrupt.check()
            raise
        except Exception as exc:
            raise self._failure(inst, f"initialising the FMU at t={t:.9g} s failed: {_reason(exc)}") from None
        interrupt.check()

    def output(self, t: float, state: FMUState, inputs: Mapping[str, Signal]) -> dict[str, Signal]:
        if self._model.scheduled:
            return self._activated(t, state, inputs)
        if state.time is None:
            self._start(t, state, inputs)
        elif self._direct and state.ended is None:
            inst = state.instance
            self.step_calls(inst, t, self._read_through, t, state, inst, inputs)
        return state.outputs

    def _read_through(self, t: float, state: FMUState, inst: Instance, inputs: Mapping[str, Signal]) -> None:
        """``feedthrough``: the outputs at ``t`` once the inputs of ``t`` are set."""
        inst.write(inputs, t)
        state.outputs = inst.read(t)

    def _activated(self, t: float, state: FMUState, inputs: Mapping[str, Signal]) -> dict[str, Signal]:
        """Scheduled execution: the outputs at the hit ``t`` once the inputs of ``t`` are set
        and the clocks that tick there activated, in priority order."""
        if state.time is None:
            self._start(t, state, inputs)
        if state.clocks.activated != t:
            self.step_calls(state.instance, t, self._activate, t, state, inputs)
        return state.outputs

    def _activate(self, t: float, state: FMUState, inputs: Mapping[str, Signal]) -> None:
        inst = state.instance
        inst.arm()
        inst.write(inputs, t)
        exact = round(t / self._step) * self._period
        ticked = inst.activate(self._model.clocks, state.clocks, t, exact, self._period, inputs)
        interrupt.check()
        state.outputs = {**inst.read(t), **ticked}
        state.time = state.clocks.activated = t

    def update(self, t: float, state: FMUState, inputs: Mapping[str, Signal]) -> FMUState:
        if self._model.scheduled:  # the partitions ran at the hit's outputs: scheduled execution has no step
            return state
        if state.time is None:
            self._start(t, state, inputs)
        inst = state.instance
        h = self._step
        if inst.broken:
            raise BlockError(f"{self._model.shown}: the FMU instance failed earlier and cannot step")
        if state.ended is not None:
            raise BlockError(f"{self._model.shown}: the FMU ended the simulation at t={state.ended:.9g} s "
                             "and cannot step further")
        if abs(t - state.time) > 1e-9 * max(h, abs(t)):
            raise BlockError(f"{self._model.shown}: asked to step from t={t:.9g} s, but the FMU is at "
                             f"t={state.time:.9g} s (the block must fire every period)")
        self.step_calls(inst, t, self._step_from, t, state, inst, inputs)
        return state

    def _step_from(self, t: float, state: FMUState, inst: Instance, inputs: Mapping[str, Signal]) -> None:
        inst.arm()
        self.stepped(t, state, inst, inst.step(inputs, t, self._step))

    def stepped(self, t: float, state: FMUState, inst: Instance, outcome: tuple[bool, bool, float]) -> None:
        """The rest of a step from ``t`` once doStep returned ``outcome`` (terminate
        requested, returned early, last successful time): a noted Ctrl-C raised, a request
        to terminate as EndRun, an early return a failure, else the outputs at ``t + h``."""
        terminate, early, last = outcome
        h = self._step
        interrupt.check()
        if terminate:
            state.time = state.ended = last
            state.outputs = inst.read(last)
            short = f" (its step to t={t + h:.9g} s stopped at t={last:.9g} s)" if last < t + h - 1e-9 * h else ""
            raise EndRun(f"{self._model.shown} requested to terminate the simulation{short}", state)
        if early:
            inst.broken = True
            raise BlockError(f"{self._model.shown}: doStep at t={t:.9g} s (step {h:.9g} s) returned early "
                             f"at t={last:.9g} s, which co-simulation here does not allow{inst.log_text()}")
        state.time = t + h
        state.outputs = inst.read(state.time)

    def step_calls(self, inst: Instance, t: float, calls: Callable[..., None], *args: Any) -> None:
        """``calls(*args)``: calls into the FMU for the step from ``t``, whose failure
        (other than the block's own errors, EndRun and Ctrl-C) breaks the instance and
        becomes a BlockError with the FMU's log (``_failure``)."""
        try:
            calls(*args)
        except (BlockError, EndRun):
            raise
        except Exception as exc:
            raise self._failure(inst, _reason(exc, t, self._step)) from None

    def loop_remedy(self, name: str) -> str | None:
        if not self._direct:
            return None
        return (f"or set 'feedthrough: false' on FMU block '{name}', whose modelDescription declares the "
                "outputs on the loop dependent on its inputs (its outputs then come from before its "
                "inputs are set: the Jacobi exchange)")

    def kernel(self) -> Kernel | None:
        """The steady step in C (``blocks.fmu.compiled_step``) when every port is Float64; an FMU
        with ports of other types, read with ``feedthrough``, or run by scheduled execution,
        runs in Python."""
        return None if self._direct or self._model.scheduled else fmu_kernel(self)

    def _failure(self, inst: Instance, what: str) -> BlockError:
        """The error of a failed call into the FMU, which breaks the instance: ``what`` with
        the FMU's name and recent log. A failure that comes with Ctrl-C is the interrupt,
        raised here instead."""
        inst.broken = True
        interrupt.check()
        return BlockError(f"{self._model.shown}: {what}{inst.log_text()}")

    def finish(self, state: FMUState) -> None:
        """The run is over: terminate its instance now, so that a crash there fails it."""
        state.finish()

    def close(self) -> None:
        """Free the pooled FMU instances and, once no run holds one, the extracted files."""
        self._model.close()


def _reason(exc: BaseException, t: float | None = None, h: float | None = None) -> str:
    """What failed, for a failure's message: the FMI function, when, and its status."""
    function = getattr(exc, "function", None)
    status = getattr(exc, "status", None)
    if function is None:
        return str(exc) if isinstance(exc, (BlockError, SolverError)) else f"{type(exc).__name__}: {exc}"
    label = status_name(status)
    if isinstance(exc, CallFailed):
        return f"{function} at t={exc.time:.9g} s returned status '{label}'"
    if function.endswith("DoStep") and t is not None:
        return f"{function} at t={t:.9g} s (step {h:.9g} s) returned status '{label}'"
    return f"{function} returned status '{label}'"
