"""The two methods that integrate a model-exchange FMU between the block's hits.

``Integration`` is what the diagram chose (``solver``, ``tolerance``, ``substep``), checked
against the block's period. ``ContinuousCalls`` is one instance's continuous-time
functions (setTime, setContinuousStates, the derivatives, the event indicators,
completedIntegratorStep) with their buffers, laid out in the int64 table that the C
loops of ``blocks/csrc/fmu_me_integration.c`` read. The solvers integrate from one time to another,
stopping at the first state event, step event or request to terminate, and say which:

- ``Euler``: forward Euler with a fixed sub-step on the grid of the hit interval (the
  period a whole number of sub-steps), in C; a state event (an event indicator changing
  sign, as fmpy's Euler detects it) is located by bisection to ``tolerance`` times the
  sub-step, on the Euler step's straight line;
- ``CVode``: SUNDIALS' CVode as fmpy ships it (``sundials``), BDF with a dense linear
  solver, relative tolerance ``tolerance`` and absolute tolerances ``tolerance`` times the
  states' nominal values, as fmpy's own ME simulation uses it (which also bounds its step
  by a 50th of the simulated time, which a block does not know); its right-hand side and root function are the C functions of fmu_me_integration.c, so no Python
  runs inside the integration, and its root finding locates state events.

At a state event both hand the FMU, before event mode, a time and states at which the
indicator has changed its sign strictly, as FMI asks (``ContinuousCalls.past_crossing``):
a located crossing whose indicator is exactly 0 (Euler's bisection can land there, and
CVode's root finding, or an indicator that reaches 0 at a hit, where CVode sees no root)
moves on along the derivatives by an ulp or so, so an event handler that reads the
state's sign, as generated code does, sees the event.

Both call completedIntegratorStep (when the FMU needs it) after each step they take,
Euler's sub-steps and each CVode call. A call into the FMU that fails raises
``CallFailed`` (function, status, time), a failing CVode ``SolverError``.
"""

from __future__ import annotations

import ctypes
import functools
import math
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

import numpy as np

from blocks.engine.kernel import address
from ..timebase import format_duration
from . import interrupt
from .native import native
from .instance import function_address
from .model import duration_parameter
from .sundials import CV_NORMAL, CV_ROOT_RETURN

SOLVERS = ("cvode", "euler")
DEFAULT_TOLERANCE = 1e-5
"""The relative tolerance where neither the diagram nor the FMU's DefaultExperiment gives one (fmpy's)."""
MAX_NUM_STEPS = 100_000
"""How many internal steps CVode may take within one call (up to the next hit or event)."""
MAX_NUDGES = 64
"""How many times the step past a located state event may double before it stops trying."""


class CallFailed(Exception):
    """A call into the FMU returned a status worse than warning while it integrated."""

    def __init__(self, function: str, status: int, time: float):
        super().__init__(f"{function} returned status {status} at t={time:.9g} s")
        self.function, self.status, self.time = function, status, time


class SolverError(Exception):
    """The integration itself failed (CVode, or events that do not settle)."""


@dataclass(frozen=True)
class Integration:
    """How the block integrates a model-exchange FMU: ``solver`` ('cvode' or 'euler'),
    the relative ``tolerance``, Euler's ``substeps`` per period (1 for CVode) and the
    ``period`` between hits."""

    solver: str
    tolerance: float
    substeps: int
    period: Fraction

    def describe(self) -> str:
        if self.solver == "euler":
            step = format_duration(self.period / self.substeps) if self.substeps > 1 else "the period"
            return f"euler, sub-step {step}, state events located to {self.tolerance:g} of it"
        return f"cvode, tolerance {self.tolerance:g}"


def solver_choice(solver: Any, substep: Any) -> tuple[str, Fraction | None]:
    """The ``solver`` and ``substep`` parameters checked (ValueError naming the value):
    the solver's name and the sub-step, if given."""
    if solver is not None and solver not in SOLVERS:
        raise ValueError(f"parameter 'solver' must be one of {', '.join(SOLVERS)}, got {solver!r}")
    solver = solver or "cvode"
    if substep is None:
        return solver, None
    if solver != "euler":
        raise ValueError("parameter 'substep' is the fixed step of 'solver: euler'; CVode chooses its own "
                         "steps (drop 'substep', or add 'solver: euler')")
    return solver, duration_parameter("substep", substep)


def integration(solver: str, substep: Fraction | None, default_step: Fraction | None, tolerance: float,
                period: Fraction) -> Integration:
    """The Integration of a block with this period. Euler's sub-step is ``substep``, which
    must divide the period (ValueError), or else the FMU's default step made to divide
    it (the largest sub-step not above it; the period where it declares none)."""
    if solver == "euler" and substep is not None:
        count = period / substep
        if count < 1 or count.denominator != 1:
            near = period / max(1, math.ceil(count))
            raise ValueError(f"the period {format_duration(period)} is not a whole multiple of the sub-step "
                             f"{format_duration(substep)}; use a sub-step that divides it, e.g. "
                             f"'substep: {format_duration(near)}'")
        substeps = int(count)
    elif solver == "euler" and default_step is not None:
        substeps = max(1, math.ceil(period / default_step))
    else:
        substeps = 1
    return Integration(solver, tolerance, substeps, period)


@functools.cache
def layout() -> dict[str, Any]:
    """The C functions and the table's layout (fmu_me_integration.h), from blocks._native."""
    found = native()
    if found is None:
        raise SolverError("model exchange needs the compiled extension blocks._native, which is not built "
                          "(reinstall with 'pip install -e .')")
    return found["model_exchange"]


class ContinuousCalls:
    """An instance's continuous-time FMU functions and buffers, in the table fmu_me_integration.c reads.

    ``x`` holds the states, ``z`` the event indicators where the last step started; the
    FMU functions are the instance's own (``functions``: name -> ctypes function), called
    from C by the solvers and from here between their steps.
    """

    def __init__(self, component: int, major: int, functions: dict[str, Any], nx: int, nz: int,
                 completed: bool):
        self.layout = layout()
        slots = self.layout["slots"]
        self.nx, self.nz, self.major = nx, nz, major
        prefix = f"fmi{major}"
        derivatives = "GetDerivatives" if major == 2 else "GetContinuousStateDerivatives"
        self.names = {"set_time": "SetTime", "set_states": "SetContinuousStates", "get_derivatives": derivatives,
                      "get_indicators": "GetEventIndicators", "completed": "CompletedIntegratorStep"}
        self.names = {k: prefix + v for k, v in self.names.items()}
        self.functions = {k: functions[v] for k, v in self.names.items()}
        self.get_states = functions[f"{prefix}GetContinuousStates"]
        self.get_nominals = functions[f"{prefix}GetNominalsOfContinuousStates"]
        self.component = component
        self.needs_completed = completed
        self.table = np.zeros(slots["size"], dtype=np.int64)
        self.values = np.zeros(self.layout["values"]["size"])
        self.x, self.dx, self.x_start = (np.zeros(max(nx, 1)) for _ in range(3))
        self.z, self.z_new = (np.zeros(max(nz, 1)) for _ in range(2))
        self.nominals = np.ones(max(nx, 1))
        table = {"component": component, "version": major, "nx": nx, "nz": nz, "values": address(self.values),
                 "x": address(self.x), "dx": address(self.dx), "x_start": address(self.x_start),
                 "z": address(self.z), "z_new": address(self.z_new),
                 "completed": self._address("completed") if completed else 0}
        table.update({k: self._address(k) for k in ("set_time", "set_states", "get_derivatives", "get_indicators")})
        for name, value in table.items():
            self.table[slots[name]] = value
        self.address = address(self.table)
        """The table's address, the C loops' context."""
        self.reached = self.layout["values"]["reached"]
        self._failed = slots["failed"]
        self._x = self.x.ctypes.data_as(ctypes.POINTER(ctypes.c_double))
        self._z = self.z.ctypes.data_as(ctypes.POINTER(ctypes.c_double))
        self._z_new = self.z_new.ctypes.data_as(ctypes.POINTER(ctypes.c_double))
        self._dx = self.dx.ctypes.data_as(ctypes.POINTER(ctypes.c_double))
        self._nominals = self.nominals.ctypes.data_as(ctypes.POINTER(ctypes.c_double))
        flag = ctypes.c_bool if major == 3 else ctypes.c_int
        self._flags = (flag(), flag())
        self._flag_refs = tuple(ctypes.byref(f) for f in self._flags)

    def _address(self, name: str) -> int:
        return function_address(self.functions[name])

    def check(self, name: str, status: int, t: float) -> None:
        if status > 1:
            raise CallFailed(self.names.get(name, name), status, t)

    def failure(self, default: BaseException) -> BaseException:
        """The exception for a C loop that returned a failure: the FMU call it recorded,
        else ``default``."""
        code = int(self.table[self._failed])
        if not code:
            return default
        name = next(k for k, v in self.layout["calls"].items() if v == code)
        status = int(self.table[self.layout["slots"]["failed_status"]])
        return CallFailed(self.names[name], status, float(self.values[self.layout["values"]["failed_time"]]))

    def clear_failure(self) -> None:
        self.table[self._failed] = 0

    def read(self, t: float) -> None:
        """The FMU's states (and their nominal values) and event indicators into the buffers."""
        if self.nx:
            self.check(f"fmi{self.major}GetContinuousStates", self.get_states(self.component, self._x, self.nx), t)
            self.check(f"fmi{self.major}GetNominalsOfContinuousStates",
                       self.get_nominals(self.component, self._nominals, self.nx), t)
        if self.nz:
            self.check("get_indicators", self.functions["get_indicators"](self.component, self._z, self.nz), t)

    def place(self, t: float) -> None:
        """The FMU at time ``t`` with the states of ``x``."""
        self.check("set_time", self.functions["set_time"](self.component, t), t)
        if self.nx:
            self.check("set_states", self.functions["set_states"](self.component, self._x, self.nx), t)

    def indicators_now(self, t: float) -> np.ndarray:
        """The event indicators where the FMU is (at ``t``), in ``z_new``."""
        self.check("get_indicators", self.functions["get_indicators"](self.component, self._z_new, self.nz), t)
        return self.z_new[:self.nz]

    def crossed_now(self, t: float) -> dict[int, float]:
        """The indicators that changed sign (to zero or across it) from ``z`` to where the
        FMU is now, each with the sign it is heading for (+1 or -1)."""
        if not self.nz:
            return {}
        z, now = self.z[:self.nz], self.indicators_now(t)
        return {i: (1.0 if z[i] < 0.0 else -1.0) for i in range(self.nz)
                if (z[i] < 0.0 <= now[i]) or (z[i] > 0.0 >= now[i])}

    def past_crossing(self, t: float, heading: dict[int, float], limit: float) -> float:
        """The FMU at a located state event ``t`` moved just past the crossing, as FMI
        requires of the state event mode sees: to the first time at or after ``t`` at which
        every indicator of ``heading`` (index: +1 or -1) has that sign, strictly (an
        indicator exactly 0 has not changed its domain, and an event handler that reads a
        state's sign would see no event). The states move on along their derivatives at
        ``t``, a step of an ulp or so doubled until the signs are there (at most
        ``MAX_NUDGES`` times, never past ``limit``). Returns the time the FMU is left at."""
        if not heading or self._past(heading, t):
            return t
        nx = self.nx
        x0 = self.x[:nx].copy()
        if nx:
            self.check("get_derivatives", self.functions["get_derivatives"](self.component, self._dx, nx), t)
        slope = self.dx[:nx].copy()
        delta, now = max(abs(t), 1.0) * 2.0**-52, t
        for _ in range(MAX_NUDGES):
            now = min(t + delta, limit)
            if now <= t:
                return t
            self.x[:nx] = x0 + (now - t) * slope
            self.place(now)
            if self._past(heading, now) or now >= limit:
                return now
            delta *= 2.0
        return now

    def _past(self, heading: dict[int, float], t: float) -> bool:
        now = self.indicators_now(t)
        return all(now[i] * sign > 0.0 for i, sign in heading.items())

    def completed(self, t: float) -> str:
        """completedIntegratorStep after a step to ``t`` (if the FMU needs it): 'reached',
        'step_event' or 'terminate'."""
        if not self.needs_completed:
            return "reached"
        status = self.functions["completed"](self.component, True, *self._flag_refs)
        self.check("completed", status, t)
        enter, terminate = (bool(f.value) for f in self._flags)
        return "terminate" if terminate else "step_event" if enter else "reached"


class Euler:
    """Forward Euler with ``integration.substeps`` sub-steps per hit interval, in C."""

    def __init__(self, calls: ContinuousCalls, integration: Integration):
        self.calls = calls
        self.substeps = integration.substeps
        calls.values[calls.layout["values"]["locate"]] = integration.tolerance * float(integration.period) / self.substeps
        signature = ctypes.CFUNCTYPE(ctypes.c_long, ctypes.c_void_p, ctypes.c_double, ctypes.c_double,
                                     ctypes.c_double, ctypes.c_double, ctypes.c_long)
        self._euler = signature(calls.layout["euler"])
        self.outcomes = {v: k for k, v in calls.layout["outcomes"].items()}
        self._context = ctypes.c_void_p(calls.address)

    def start(self, t: float) -> None:
        """At ``t``, after initialisation or an event: the states and indicators read."""
        self.calls.read(t)

    def integrate(self, start: float, stop: float, hit: tuple[float, float]) -> tuple[float, str]:
        """From ``start`` to ``stop`` within the hit interval ``hit``: the time reached and
        'reached', 'state_event', 'step_event' or 'terminate'."""
        calls = self.calls
        outcome = self.outcomes[self._euler(self._context, start, stop, hit[0], hit[1], self.substeps)]
        interrupt.check()
        if outcome == "failed":
            raise calls.failure(SolverError("the Euler integration failed"))
        reached = float(calls.values[calls.reached])
        if outcome in ("state_event", "step_event"):
            reached = calls.past_crossing(reached, calls.crossed_now(reached), beyond(stop, hit))
        return reached, outcome

    def close(self) -> None:
        """Nothing to free."""


class CVode:
    """CVode (fmpy's SUNDIALS 7): BDF, dense linear solver, root finding on the indicators."""

    def __init__(self, calls: ContinuousCalls, integration: Integration):
        from . import sundials

        try:
            self.cv = cv = sundials.functions()
        except RuntimeError as exc:
            raise SolverError(str(exc)) from None
        self.calls = calls
        calls.table[calls.layout["slots"]["array"]] = cv.array
        self.tolerance = integration.tolerance
        self.message: str | None = None
        self._handler = sundials.ErrorHandler(interrupt.callback(self._error))
        self.context = ctypes.c_void_p()
        self.memory = self.matrix = self.solver = None
        self.vectors: list[int] = []
        self.started = False
        self._return = ctypes.c_double()
        self._return_ref = ctypes.byref(self._return)
        self._roots = (ctypes.c_int * max(calls.nz, 1))()
        try:
            self._ok(cv.SUNContext_Create(sundials.SUN_COMM_NULL, ctypes.byref(self.context)), "SUNContext_Create")
            self._ok(cv.SUNContext_ClearErrHandlers(self.context), "SUNContext_ClearErrHandlers")
            self._ok(cv.SUNContext_PushErrHandler(self.context, self._handler, None), "SUNContext_PushErrHandler")
            n = max(calls.nx, 1)  # without states, CVode integrates one dummy state, as fmpy does
            self.abstol = np.zeros(n)
            self.y = self._vector(calls.x, n)
            self.atol = self._vector(self.abstol, n)
            self.memory = cv.CVodeCreate(sundials.CV_BDF, self.context)
            self.matrix = cv.SUNDenseMatrix(n, n, self.context)
            self.solver = cv.SUNLinSol_Dense(self.y, self.matrix, self.context)
            if not (self.memory and self.matrix and self.solver):
                raise SolverError(f"CVode could not be set up: {self.message or 'out of memory'}")
        except BaseException:
            self.close()
            raise

    def _setup(self, t: float) -> None:
        """CVode's first initialisation, at ``t``, and its settings."""
        cv, calls, memory = self.cv, self.calls, self.memory
        self._ok(cv.CVodeInit(memory, calls.layout["rhs"], t, self.y), "CVodeInit")
        self._ok(cv.CVodeSetUserData(memory, calls.address), "CVodeSetUserData")
        self._ok(cv.CVodeSVtolerances(memory, self.tolerance, self.atol), "CVodeSVtolerances")
        if calls.nz:
            self._ok(cv.CVodeRootInit(memory, calls.nz, calls.layout["roots"]), "CVodeRootInit")
        self._ok(cv.CVodeSetLinearSolver(memory, self.solver, self.matrix), "CVodeSetLinearSolver")
        self._ok(cv.CVodeSetMaxNumSteps(memory, MAX_NUM_STEPS), "CVodeSetMaxNumSteps")
        self._ok(cv.CVodeSetNoInactiveRootWarn(memory), "CVodeSetNoInactiveRootWarn")
        self.started = True

    def _vector(self, values: np.ndarray, n: int) -> int:
        vector = self.cv.N_VMake_Serial(n, address(values), self.context)
        if not vector:
            raise SolverError("CVode could not make its vectors")
        self.vectors.append(vector)
        return vector

    def _error(self, line, function, file, message, code, data, context) -> None:
        self.message = f"{(function or b'CVode').decode(errors='replace')}: {(message or b'').decode(errors='replace')}"

    def _ok(self, flag: int, what: str) -> None:
        if flag != 0:
            raise SolverError(f"{what} failed (flag {flag}){': ' + self.message if self.message else ''}")

    def _initial(self, t: float) -> None:
        """The states, their absolute tolerances (relative tolerance times their nominal
        values) and the indicators as the FMU has them at ``t``."""
        calls = self.calls
        calls.read(t)
        if calls.nx:
            self.abstol[:] = self.tolerance * np.abs(calls.nominals)
        else:
            calls.x[0] = 1.0
            self.abstol[0] = self.tolerance

    def start(self, t: float) -> None:
        """At ``t``, after initialisation or an event: CVode (re)started from the FMU's states."""
        self._initial(t)
        if not self.started:
            self._setup(t)
        else:
            self._ok(self.cv.CVodeReInit(self.memory, t, self.y), "CVodeReInit")

    def integrate(self, start: float, stop: float, hit: tuple[float, float]) -> tuple[float, str]:
        """CVode from ``start`` towards ``stop`` (one call, to the first root): the time
        reached and 'reached', 'state_event', 'step_event' or 'terminate'."""
        calls = self.calls
        calls.clear_failure()
        self.message = None
        flag = self.cv.CVode(self.memory, stop, self.y, self._return_ref, CV_NORMAL)
        interrupt.check()
        if flag < 0:
            raise calls.failure(SolverError(f"CVode failed at t={self._return.value:.9g} s (flag {flag})"
                                            f"{': ' + self.message if self.message else ''}"))
        reached = self._return.value if flag == CV_ROOT_RETURN else stop
        calls.place(reached)
        # an indicator that lands on 0 exactly at ``stop`` is no root to CVode, nor, once it
        # restarts from 0, the crossing that follows: a crossing all the same
        heading = self._heading() if flag == CV_ROOT_RETURN else calls.crossed_now(reached)
        if heading:
            reached = calls.past_crossing(reached, heading, beyond(stop, hit))
        outcome = calls.completed(reached)
        if outcome == "reached" and heading:
            outcome = "state_event"
        if calls.nz:
            calls.z[:calls.nz] = calls.indicators_now(reached)
        return reached, outcome

    def _heading(self) -> dict[int, float]:
        """The indicators CVode found a root of, each with the sign it is heading for."""
        self._ok(self.cv.CVodeGetRootInfo(self.memory, self._roots), "CVodeGetRootInfo")
        return {i: float(r) for i, r in enumerate(self._roots[:self.calls.nz]) if r}

    def close(self) -> None:
        """Free CVode's memory, its linear solver, matrix, vectors and context."""
        cv = self.cv
        if self.memory:
            cv.CVodeFree(ctypes.byref(ctypes.c_void_p(self.memory)))
            self.memory = None
        if self.solver:
            cv.SUNLinSolFree(self.solver)
            self.solver = None
        if self.matrix:
            cv.SUNMatDestroy(self.matrix)
            self.matrix = None
        for vector in self.vectors:
            cv.N_VDestroy(vector)
        self.vectors = []
        if self.context:
            cv.SUNContext_Free(ctypes.byref(self.context))
            self.context = ctypes.c_void_p()


def beyond(stop: float, hit: tuple[float, float]) -> float:
    """How far past ``stop`` a state event found at (or just before) it may be handed over:
    a billionth of the hit interval, which the block's time keeping counts as ``stop``."""
    return stop + 1e-9 * (hit[1] - hit[0])


def solver(calls: ContinuousCalls, integration: Integration) -> Euler | CVode:
    """The solver ``integration`` names, for the instance of ``calls``."""
    return (Euler if integration.solver == "euler" else CVode)(calls, integration)
