"""What an FMU's modelDescription says, checked once, when a block is made.

``Model`` reads the archive's member list and modelDescription.xml (through
``description.read_description``; nothing is extracted, no code runs) and checks what the
FMU block needs before a diagram is accepted: FMI 2.0 or 3.0, the interface it runs
(co-simulation where the FMU offers it, else model exchange, or the one the diagram asks
for), no execution tool, a binary for this platform. It keeps what the block and its
instances use: the ports and their FMI-type groups, the variables that start values may
set, the default experiment, the co-simulation step rules (fixed internal step, whether
the communication step may vary) and the model-exchange sizes (continuous states, event
indicators). Problems are ValueErrors, which the diagram loader reports as
``file:line: block 'x' (FMU): ...``.
"""

from __future__ import annotations

import math
import sys
from fractions import Fraction
from pathlib import Path
from typing import Any

from ..limits import MAX_PORT_WIDTH
from ..timebase import positive_duration
from .description import read_description, shown_text, step_of
from .port_types import KINDS, NOT_PORTS
from .ports import direct_reads, group_variables, groups, initial_reads, port_name, variable_width, vectors


CO_SIMULATION = "co_simulation"
MODEL_EXCHANGE = "model_exchange"
SCHEDULED_EXECUTION = "scheduled_execution"
INTERFACES = {CO_SIMULATION: "co-simulation", MODEL_EXCHANGE: "model exchange",
              SCHEDULED_EXECUTION: "scheduled execution"}
"""The interfaces the block runs, by the name a diagram's ``interface`` parameter gives them,
in words."""

ISOLATIONS = {"process": "in a process of its own", "none": "in the run's process"}
"""Where the block's FMU instances run, by the name a diagram's ``isolation`` parameter gives it."""

IN_PROCESS_TOOLS = ("hierhand", "blocks")
"""The generation tools (the first word of the modelDescription's ``generationTool``) whose
FMUs run in the run's process unless the diagram says otherwise: this project's own exports
(``fmu export``: ``blocks`` names the diagram exports, ``hierhand`` the earlier plant
ones), whose binary is the C core the native blocks run. Every other FMU runs in a
process of its own by default, so that its crash or hang cannot take the run with it. (A modelDescription can claim any tool: this is a choice of speed, not of trust.)"""

PROCESS_ISOLATION = sys.platform.startswith("linux")
"""Whether FMUs can run in processes of their own here (the channel needs Linux)."""

DEFAULT_CALL_TIMEOUT = Fraction(600)
"""How long one call into an FMU in a process of its own may take by default (10 min):
far beyond any one step of a real FMU, so that only one that hangs reaches it."""


def import_fmpy():
    """fmpy, imported on first use (it takes a fifth of a second) with a clear error if missing."""
    try:
        import fmpy
        import fmpy.fmi2
        import fmpy.fmi3
        import fmpy.model_description
    except ImportError as exc:  # pragma: no cover - fmpy is a dependency
        raise ValueError(f"FMU blocks need fmpy ({exc}); install it with 'pip install fmpy'") from None
    return fmpy


class Model:
    """What the modelDescription of the FMU at ``path`` says (``shown`` names it in messages)."""

    def __init__(self, path: Path, shown: str, interface: str | None = None):
        self.path = path
        self.shown = shown
        fmpy = import_fmpy()
        description = read_description(path, shown)
        self.description = description
        md = self.md = description.md
        major = md.fmiMajorVersion if md.fmiVersion else 0
        if major not in (2, 3):
            raise ValueError(f"{shown} is an FMI {md.fmiVersion} FMU; the FMU block supports FMI 2.0 "
                             "and 3.0")
        self.major = major
        chosen = self._interface(interface)
        self.exchange = chosen == MODEL_EXCHANGE
        """Whether the block runs the FMU's model-exchange interface (else co-simulation)."""
        self.scheduled = chosen == SCHEDULED_EXECUTION
        """Whether it runs FMI 3 scheduled execution (``scheduled``: its input clocks activated)."""
        element = md.modelExchange if self.exchange else md.scheduledExecution if self.scheduled else md.coSimulation
        self.clocks = ()
        if self.scheduled:
            from .clocks import fmu_clocks

            self.clocks = fmu_clocks(description.xml, shown)
        self.identifier = element.modelIdentifier
        self.once_per_process = bool(element.canBeInstantiatedOnlyOncePerProcess)
        if element.needsExecutionTool:
            raise ValueError(f"{shown} needs its execution tool (a tool-coupling FMU), which cannot "
                             "run here")
        platform = fmpy.platform if major == 2 else fmpy.platform_tuple
        library = f"binaries/{platform}/{self.identifier}{fmpy.sharedLibraryExtension}"
        if library not in description.files:
            found = description.platforms()
            has_sources = any(f.startswith("sources/") for f in description.files)
            detail = f"it has binaries for {', '.join(found)}" if found else "it has no binaries"
            if has_sources:
                detail += " and C sources (compile them first, e.g. with fmpy's compile_platform_binary)"
            raise ValueError(f"{shown} has no binary for this platform ({platform}/"
                             f"{library.rsplit('/', 1)[1]}); {detail}")
        self.library = library
        self.fixed_step = description.fixed_step()
        """The fixed internal step a co-simulation FMU declares (informative, not enforced)."""
        self.can_vary_step = bool(md.coSimulation.canHandleVariableCommunicationStepSize) \
            if md.coSimulation is not None else True
        self._check_sizes(md)
        self.states = md.numberOfContinuousStates if self.exchange else 0
        self.indicators = md.numberOfEventIndicators if self.exchange else 0
        self.completed_step = bool(md.modelExchange.needsCompletedIntegratorStep) if self.exchange else False
        self.guid = md.guid or ""
        de = md.defaultExperiment
        self.default_step: Fraction | None = None
        """The DefaultExperiment's stepSize, if the FMU gives a usable one."""
        self.default_step_problem: str | None = None
        """Why the FMU's stepSize is not usable (out of range, not a number), if it is not."""
        if de is not None and de.stepSize is not None:
            try:
                self.default_step = step_of(de.stepSize)
            except ValueError as exc:
                self.default_step_problem = f"its DefaultExperiment stepSize '{shown_text(de.stepSize)}' is {exc}"
        self.default_tolerance = float_or_none(de.tolerance if de else None)
        if self.scheduled:  # its hits are its periodic clocks' ticks
            from .clocks import clock_grid

            grid = clock_grid(self.clocks)
            if grid is not None:
                self.default_step, self.default_step_problem = grid, None
        self.variables = {v.name: v for v in md.modelVariables}
        kinds = KINDS[major]
        ports = [v for v in md.modelVariables if v.type in kinds]
        ins = [v for v in ports if v.causality == "input" and v.alias is None]
        outs = [v for v in ports if v.causality == "output"]
        self.inputs = group_variables(ins, "input", shown, major)
        self.outputs = group_variables(outs, "output", shown, major)
        self.not_ports = self._not_ports(md.modelVariables)
        self.initial_reads = initial_reads(md, self.inputs, self.outputs)
        self.direct_reads = direct_reads(md, self.inputs, self.outputs)
        self.in_groups = groups(self.inputs)
        self.out_groups = groups(self.outputs)
        self.vectors = vectors(md.modelVariables, self.variables)

    @property
    def default_isolation(self) -> str:
        """Where the FMU runs unless the diagram says: 'none' for the tools of
        IN_PROCESS_TOOLS (and where processes of their own are not available), else 'process'."""
        tool = (self.md.generationTool or "").split()
        return "none" if not PROCESS_ISOLATION or (tool and tool[0] in IN_PROCESS_TOOLS) else "process"

    @property
    def interface(self) -> str:
        """The interface the block runs, in words: 'co-simulation', 'model exchange' or
        'scheduled execution'."""
        return "model exchange" if self.exchange else "scheduled execution" if self.scheduled else "co-simulation"

    def _interface(self, asked: str | None) -> str:
        """The interface to run: ``asked`` (a value of ``INTERFACES``), else co-simulation
        where the FMU offers it, else model exchange; ValueError if the FMU lacks it."""
        md = self.md
        offered = [name for name, element in ((CO_SIMULATION, md.coSimulation), (MODEL_EXCHANGE, md.modelExchange),
                                              (SCHEDULED_EXECUTION, getattr(md, "scheduledExecution", None)))
                   if element is not None]
        if asked is None and offered:
            return offered[0]
        if asked in offered:
            return asked
        if not offered:
            raise ValueError(f"{self.shown} has no co-simulation, model-exchange or scheduled-execution interface")
        raise ValueError(f"{self.shown} has no {INTERFACES[asked]} interface (it provides only "
                         f"{INTERFACES[offered[0]]}); drop 'interface: {asked}' to run it as {INTERFACES[offered[0]]}")

    def _check_sizes(self, md: Any) -> None:
        """ValueError for an array variable, or a number of continuous states or event
        indicators, beyond MAX_PORT_WIDTH values: each is allocated (and an array's elements
        labelled) per run, so 10^9 of them would exhaust memory rather than fail."""
        for v in md.modelVariables:
            width = variable_width(v)
            if width > MAX_PORT_WIDTH:
                raise ValueError(f"variable '{v.name}' of {self.shown} is an array of {width} elements, more "
                                 f"than the limit of {MAX_PORT_WIDTH} the FMU block takes")
        for what, count in (("continuous states", md.numberOfContinuousStates),
                            ("event indicators", md.numberOfEventIndicators)):
            if not 0 <= count <= MAX_PORT_WIDTH:
                raise ValueError(f"{self.shown} declares {count} {what}, more than the limit of {MAX_PORT_WIDTH} "
                                 "the FMU block takes")

    def _not_ports(self, variables: list) -> dict[str, str]:
        """Why each variable that is not a port is not one, by the port name it would have."""
        why: dict[str, str] = {}
        for v in variables:
            name = port_name(v.name)
            if name in self.inputs or name in self.outputs:
                continue
            if v.type in NOT_PORTS:
                reason = f"'{v.name}' is {NOT_PORTS[v.type]}"
                if v.causality == "input" and v.type != "Clock":
                    reason += "; give it a value with start_values"
            elif v.alias is not None and v.causality == "input":
                reason = f"'{v.name}' is an alias of the input '{v.alias.name}'; connect that one"
            elif v.causality in ("parameter", "calculatedParameter", "structuralParameter"):
                reason = f"'{v.name}' is a {v.causality} of the FMU, not a port"
                if settable(v) is None:
                    reason += "; set it with start_values"
            elif v.causality in ("local", "independent"):
                reason = f"'{v.name}' is a {v.causality} variable of the FMU; only inputs and outputs are ports"
            else:
                continue
            why.setdefault(name, reason)
        return why


def isolation_choice(model: Model, isolation: Any, call_timeout: Any) -> tuple[str, float]:
    """The ``isolation`` and ``call_timeout`` parameters checked (ValueError naming the
    value): where the instances run (default: ``model.default_isolation``), and the timeout
    of one call there in seconds."""
    if isolation is None:
        isolation = model.default_isolation
    elif isolation not in ISOLATIONS:
        raise ValueError(f"parameter 'isolation' must be one of {', '.join(ISOLATIONS)}, got {isolation!r}")
    elif isolation == "process" and not PROCESS_ISOLATION:
        raise ValueError("parameter 'isolation: process' needs Linux; use 'isolation: none' here")
    if call_timeout is None:
        return isolation, float(DEFAULT_CALL_TIMEOUT)
    if isolation != "process":
        raise ValueError("parameter 'call_timeout' is for FMUs that run in a process of their own "
                         f"('isolation: process'); {model.shown} runs in the run's process, where a call "
                         "cannot be timed out")
    return isolation, float(duration_parameter("call_timeout", call_timeout))


def duration_parameter(name: str, value: Any) -> Fraction:
    """A block parameter that is a positive duration (ValueError naming it)."""
    return positive_duration(value, f"parameter '{name}'")


def float_or_none(text: Any) -> float | None:
    """A positive finite float read from ``text``, or None."""
    try:
        value = float(text)
    except (TypeError, ValueError):
        return None
    return value if math.isfinite(value) and value > 0 else None


def settable(v: Any) -> str | None:
    """Why ``v`` cannot be given a start value, or None if it can."""
    if v.variability == "constant":
        return "it is a constant"
    if v.causality == "structuralParameter":
        return "it is a structural parameter (configuration mode is not supported)"
    if v.causality in ("calculatedParameter", "independent"):
        return f"it is computed by the FMU (causality={v.causality})"
    if v.causality in ("parameter", "input") or v.initial in ("exact", "approx"):
        return None
    return f"it is computed by the FMU (causality={v.causality}, initial={v.initial})"
