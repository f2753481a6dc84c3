"""FMU import: an FMI 2.0 or 3.0 co-simulation FMU as a block, through fmpy's low-level API.

In a diagram::

    blocks:
      plant:
        type: FMU
        period: 10 ms                          # the communication step size (required)
        params:
          path: fmus/first_order.fmu           # relative to the diagram's folder
          start_values: {a: 0.9, "z[2]": 1.0, gains: [1, 2, 3]}
    connections:
      - ctrl.y -> plant.u
      - plant.y -> ctrl.u

Ports. Every input variable (causality ``input``) and output variable (causality
``output``) of type Real (FMI 2) or Float64/Float32 (FMI 3) becomes a float64 port.
Scalars named ``x[1]``, ``x[2]``, ... (and ``A[1,1]``, ``A[1,2]``, ... row-major) form
one vector port ``x``; an FMI 3 array variable is one port of its flattened size. The
indices must start at 1 and have no gaps; the vector's elements keep them in
``signals.csv`` (``plant.x[1]``, ``plant.A[1,2]``). Port names are the variable (or
vector) names with every character other than letters, digits and ``_`` replaced by
``_`` (``body.v[2]`` -> port ``body_v``). Integer, Boolean and String inputs/outputs are
not ports; give inputs of those types fixed values with ``start_values``.

Co-simulation semantics. The block has no feedthrough: ``output(t)`` returns the FMU
outputs at communication point ``t`` (read after the previous ``doStep``), and
``update(t)`` sets the inputs seen at ``t`` and calls ``doStep(t, period)``. Inputs are
therefore held over each communication step and an output never depends on the input of
the same instant, which makes the diagram free of algebraic loops through FMUs and the
result independent of the evaluation order (the usual Jacobi co-simulation scheme). The
first output, at the block's first hit ``t0`` (its offset), is the FMU's initial output
after initialisation with start time ``t0``.

Loading and running. Loading a diagram reads only the archive's member list and its
modelDescription.xml (``fmu_info.read_description``): ``hierhand validate`` and ``graph``
never run an FMU's code. The archive is extracted and the binary loaded when a run first
needs an instance, at the block's first ``output`` or ``update``.

State. The FMU instance is external mutable state: ``initial_state()`` hands each run its
own ``FMUState``, which takes an instance from the block's pool (reset), or instantiates
one if every pooled one is in use, at the run's first call. When the run's state is
garbage collected (or ``close()``d) the instance is terminated and returned to the pool;
instances are freed when the block goes away, at process exit, or by ``FMU.close()``. An
instance that failed is freed, never reused. The state cannot be copied or checkpointed
(FMU get/set state is not used).

Errors. Problems with the file, its modelDescription and a period the FMU cannot step
are raised at load time (ValueError, which the diagram loader reports as
``file:line: block 'x' (FMU): ...``). A binary that does not load or instantiate, and a
failing ``doStep``, raise ``BlockError`` naming the FMU, the time and the status, with the
FMU's recent log messages; the executor keeps the results up to that point. Ctrl-C inside
an FMU call is a KeyboardInterrupt, never an FMU failure (see ``fmu_interrupt``).
"""

from __future__ import annotations

import collections
import difflib
import itertools
import logging
import math
import os
import re
import shutil
import tempfile
import threading
import weakref
import zipfile
from collections.abc import Mapping
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np

from blocks import fmu_interrupt
from blocks.block import Block, BlockError, Signal
from blocks.fmu_archive import ArchiveError, extract_archive
from blocks.fmu_info import MODEL_DESCRIPTION, read_description
from blocks.timebase import format_duration

log = logging.getLogger("blocks.fmu")

LOG_LINES = 20
"""How many of an instance's most recent FMU log messages are kept for error messages."""

ERROR_LOG_LINES = 8
"""How many of them an error message quotes."""

STEP_TOLERANCE = Fraction(1, 10**6)
"""How far (in internal steps) a period may miss a whole multiple of an FMU's fixed internal
step; the exported hand plant accepts the same."""

_STATUS = ("ok", "warning", "discard", "error", "fatal", "pending")
_INDEXED = re.compile(r"^(?P<base>.*[^\s])\[(?P<index>\s*\d+\s*(?:,\s*\d+\s*)*)\]$")
_NOT_IDENT = re.compile(r"[^A-Za-z0-9_]")

# Variable types whose values a port carries, by FMI major version.
_PORT_TYPES = {2: ("Real",), 3: ("Float64", "Float32")}

_INT_RANGES = {
    "Int8": (-2**7, 2**7 - 1), "UInt8": (0, 2**8 - 1),
    "Int16": (-2**15, 2**15 - 1), "UInt16": (0, 2**16 - 1),
    "Int32": (-2**31, 2**31 - 1), "UInt32": (0, 2**32 - 1),
    "Int64": (-2**63, 2**63 - 1), "UInt64": (0, 2**64 - 1),
    "Integer": (-2**31, 2**31 - 1), "Enumeration": (-2**31, 2**31 - 1),
}


def _fmpy():
    """fmpy, imported on first use (it takes a fifth of a second) with a clear error if missing."""
    try:
        import fmpy
        import fmpy.fmi2
        import fmpy.fmi3
        import fmpy.model_description
    except ImportError as exc:  # pragma: no cover - fmpy is a dependency
        raise ValueError(f"FMU blocks need fmpy ({exc}); install it with 'pip install fmpy'") from None
    return fmpy


# -- the model: what the modelDescription says, checked once per block -------------------


@dataclass
class _Port:
    """One port: the FMU variables (value references) behind it, in port order."""

    name: str
    kind: str                 # the FMI type: Real, Float64 or Float32
    vrs: list[int]
    width: int
    source: str               # the variable or vector name in the FMU, for messages
    labels: list[str] | None = None  # a vector's indices in the FMU: "1", "2", ... or "1,1", ...


@dataclass
class _Group:
    """Ports of one FMI type read or written with one call: values laid out port by port."""

    kind: str
    vrs: list[int]
    count: int
    slices: list[tuple[str, int, int]] = field(default_factory=list)


@dataclass
class _Assignment:
    """A start value to set: one variable (scalar or FMI 3 array) and its converted values."""

    name: str
    kind: str
    vr: int
    values: list


def _port_name(base: str) -> str:
    name = _NOT_IDENT.sub("_", base)
    return "_" + name if not name or name[0].isdigit() else name


def _variable_width(v: Any) -> int:
    shape = getattr(v, "shape", None) or ()
    return int(math.prod(shape)) if v.dimensions else 1


def _group_variables(variables: list, what: str, fmu: str) -> dict[str, _Port]:
    """Ports from variables: ``x[i]`` (and ``x[i,j]``) scalars become one vector per base name."""
    bases: dict[str, list[tuple[tuple[int, ...] | None, Any]]] = {}
    for v in variables:
        m = None if v.dimensions else _INDEXED.match(v.name)
        if m:
            index = tuple(int(i) for i in m.group("index").split(","))
            bases.setdefault(m.group("base"), []).append((index, v))
        else:
            bases.setdefault(v.name, []).append((None, v))
    ports: dict[str, _Port] = {}
    origin: dict[str, str] = {}
    for base, items in bases.items():
        if len(items) == 1 and items[0][0] is None:
            v = items[0][1]
            width = _variable_width(v)
            if width < 1:
                raise ValueError(f"{what} '{v.name}' of {fmu} is an array of size 0")
            port = _Port(_port_name(base), v.type, [v.valueReference], width, v.name)
        else:
            if any(index is None for index, _ in items):
                raise ValueError(f"{what}s of {fmu}: '{base}' is both a variable and the vector "
                                 f"{base}[...]; cannot make one port of them")
            ranks = {len(index) for index, _ in items}
            if len(ranks) > 1:
                raise ValueError(f"{what}s of {fmu}: '{base}[...]' mixes indices of different "
                                 "dimensions")
            items.sort(key=lambda item: item[0])
            indices = [index for index, _ in items]
            dups = [i for i, j in itertools.pairwise(indices) if i == j]
            if dups:
                raise ValueError(f"{what}s of {fmu}: '{base}[{','.join(map(str, dups[0]))}]' "
                                 "occurs twice")
            shape = tuple(max(index[d] for index in indices) for d in range(len(indices[0])))
            expected = list(itertools.product(*(range(1, n + 1) for n in shape)))
            if indices != expected:
                missing = sorted(set(expected) - set(indices))
                found = ", ".join(f"{base}[{','.join(map(str, i))}]" for i in indices[:6])
                more = ", ..." if len(indices) > 6 else ""
                if missing:
                    detail = f"{base}[{','.join(map(str, missing[0]))}] is missing"
                else:
                    detail = "indices must start at 1"
                raise ValueError(f"{what}s of {fmu}: the elements of vector '{base}' must be numbered "
                                 f"1..n without gaps, but {detail} (found {found}{more})")
            kinds = {v.type for _, v in items}
            if len(kinds) > 1:
                raise ValueError(f"{what}s of {fmu}: vector '{base}' mixes the types "
                                 f"{', '.join(sorted(kinds))}")
            port = _Port(_port_name(base), items[0][1].type, [v.valueReference for _, v in items],
                         len(items), f"{base}[...]", [",".join(map(str, index)) for index in indices])
        if port.name in ports:
            raise ValueError(f"{what}s of {fmu}: '{origin[port.name]}' and '{port.source}' both map to "
                             f"the port name '{port.name}'")
        ports[port.name] = port
        origin[port.name] = port.source
    return ports


def _groups(ports: dict[str, _Port]) -> list[_Group]:
    groups: dict[str, _Group] = {}
    for port in ports.values():
        g = groups.setdefault(port.kind, _Group(port.kind, [], 0))
        g.vrs.extend(port.vrs)
        g.slices.append((port.name, g.count, g.count + port.width))
        g.count += port.width
    return list(groups.values())


def _convert(kind: str, value: Any, name: str) -> Any:
    """One start value converted to the variable's type, or ValueError."""
    if kind in ("Real", "Float64", "Float32"):
        if isinstance(value, bool) or not isinstance(value, (int, float, np.number)):
            raise ValueError(f"start value of '{name}' must be a number, got {value!r}")
        return float(value)
    if kind in _INT_RANGES:
        if isinstance(value, (float, np.floating)) and float(value).is_integer():
            value = int(value)
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
            raise ValueError(f"start value of '{name}' must be an integer ({kind}), got {value!r}")
        lo, hi = _INT_RANGES[kind]
        if not lo <= int(value) <= hi:
            raise ValueError(f"start value of '{name}' is out of range for {kind}: {value!r}")
        return int(value)
    if kind == "Boolean":
        if isinstance(value, (bool, np.bool_)) or value in (0, 1):
            return bool(value)
        raise ValueError(f"start value of '{name}' must be true or false, got {value!r}")
    if kind == "String":
        if not isinstance(value, str):
            raise ValueError(f"start value of '{name}' must be text, got {value!r}")
        return value
    raise ValueError(f"start values of {kind} variables such as '{name}' are not supported")


def _start_of(v: Any) -> list | None:
    """A variable's modelDescription start, converted to its type (None if it has none,
    or one that does not read as its type)."""
    if v.start is None:
        return None
    text = str(v.start)
    if v.type == "String":
        return [text]
    try:
        if v.type == "Boolean":
            return [{"true": True, "false": False, "1": True, "0": False}[x] for x in text.split()]
        if v.type in _INT_RANGES:
            return [int(x) for x in text.split()]
        return [float(x) for x in text.split()]
    except (KeyError, ValueError):
        return None


def _settable(v: Any) -> str | None:
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


@dataclass
class _Binary:
    """What an instance needs to know about its FMU (kept apart from the pool, so that
    pooled instances do not keep the pool's owner alive)."""

    shown: str
    major: int
    identifier: str
    guid: str
    dir: Path
    library: Path
    in_groups: list[_Group]
    out_groups: list[_Group]


class _Model:
    """What an FMU's modelDescription says, and the pool of its instances.

    Reading the model touches only the archive's member list and modelDescription.xml;
    the archive is extracted (and the binary loaded, by ``_Instance``) when the first
    instance is acquired, that is when a run starts.
    """

    def __init__(self, path: Path, shown: str):
        self.path = path
        self.shown = shown
        self.lock = threading.Lock()
        self.extract_lock = threading.Lock()
        self.idle: list[_Instance] = []
        self.live = 0
        self.closed = False
        self.dir: Path | None = None
        self.binary: _Binary | None = None
        self._dirs: list[str] = []
        self._cleanup = weakref.finalize(self, _remove_model, self.idle, self._dirs)
        self._read(path, shown)

    def _read(self, path: Path, shown: str) -> None:
        fmpy = _fmpy()
        description = read_description(path, shown)
        self.description = description
        md = self.md = description.md
        major = md.fmiMajorVersion if md.fmiVersion else 0
        if major not in (2, 3):
            raise ValueError(f"{shown} is an FMI {md.fmiVersion} FMU; the FMU block supports FMI 2.0 "
                             "and 3.0")
        self.major = major
        if md.coSimulation is None:
            others = [k for k, v in (("model exchange", md.modelExchange),
                                     ("scheduled execution", md.scheduledExecution)) if v is not None]
            raise ValueError(f"{shown} has no co-simulation interface (it provides only "
                             f"{' and '.join(others) or 'no interface'}); the FMU block runs "
                             "co-simulation FMUs, so export the model for co-simulation")
        cs = md.coSimulation
        self.identifier = cs.modelIdentifier
        self.once_per_process = bool(cs.canBeInstantiatedOnlyOncePerProcess)
        if cs.needsExecutionTool:
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
        self.guid = md.guid or ""
        de = md.defaultExperiment
        self.default_step = _fraction_or_none(de.stepSize if de else None)
        self.default_tolerance = _float_or_none(de.tolerance if de else None)
        self.variables = {v.name: v for v in md.modelVariables}
        kinds = _PORT_TYPES[major]
        ports = [v for v in md.modelVariables if v.type in kinds and v.alias is None]
        ins = [v for v in ports if v.causality == "input"]
        outs = [v for v in ports if v.causality == "output"]
        self.inputs = _group_variables(ins, "input", shown)
        self.outputs = _group_variables(outs, "output", shown)
        self.in_groups = _groups(self.inputs)
        self.out_groups = _groups(self.outputs)
        indexed: dict[str, list[tuple[tuple[int, ...], Any]]] = {}
        for v in md.modelVariables:
            m = None if v.dimensions else _INDEXED.match(v.name)
            if m and m.group("base") not in self.variables:
                index = tuple(int(i) for i in m.group("index").split(","))
                indexed.setdefault(m.group("base"), []).append((index, v))
        self.vectors = {b: [v for _, v in sorted(items, key=lambda i: i[0])]
                        for b, items in indexed.items()}

    # -- start values -------------------------------------------------------------------

    def assignments(self, start_values: Mapping[str, Any]) -> list[_Assignment]:
        """Start values checked and converted to the variables' types (ValueError naming the name)."""
        out: list[_Assignment] = []
        for name, value in start_values.items():
            if not isinstance(name, str):
                raise ValueError(f"start_values keys must be variable names, got {name!r}")
            if name in self.variables:
                targets = [self.variables[name]]
            elif name in self.vectors:
                targets = self.vectors[name]
            else:
                raise ValueError(self._unknown(name))
            for v in targets:
                why = _settable(v)
                if why:
                    raise ValueError(f"cannot set a start value for '{v.name}' of {self.shown}: {why}")
            widths = [_variable_width(v) for v in targets]
            total = sum(widths)
            seq = isinstance(value, (list, tuple, np.ndarray))
            values = list(np.asarray(value, dtype=object).ravel()) if seq else [value] * total
            if len(values) != total:
                raise ValueError(f"start value of '{name}' must have {total} entries (one per element), "
                                 f"got {len(values)}")
            pos = 0
            for v, w in zip(targets, widths):
                converted = [_convert(v.type, x, v.name) for x in values[pos:pos + w]]
                pos += w
                out.append(_Assignment(v.name, v.type, v.valueReference, converted))
        return out

    def input_starts(self, assignments: list[_Assignment]) -> dict[str, np.ndarray]:
        """The value each input port holds when unconnected: its start values (those of
        ``start_values`` over those of the modelDescription; 0 where there is none)."""
        given = {a.vr: a.values for a in assignments}
        by_vr = {v.valueReference: v for v in self.variables.values()
                 if v.causality == "input" and v.alias is None}
        out = {}
        for port in self.inputs.values():
            values: list[float] = []
            for vr in port.vrs:
                v = by_vr[vr]
                width = _variable_width(v)
                start = given.get(vr)
                if start is None:
                    try:
                        start = [float(x) for x in str(v.start).split()] if v.start is not None else []
                    except ValueError:
                        start = []
                if len(start) not in (1, width):
                    start = [0.0]
                values.extend(start if len(start) == width else start * width)
            out[port.name] = np.array(values, dtype=float)
        return out

    def _unknown(self, name: str) -> str:
        settable = [n for n, v in self.variables.items() if not _settable(v)]
        settable += [b for b, vs in self.vectors.items() if all(not _settable(v) for v in vs)]
        close = difflib.get_close_matches(name, settable, n=1) or difflib.get_close_matches(
            name, list(self.variables) + list(self.vectors), n=1)
        hint = f"did you mean '{close[0]}'? " if close else ""
        shown = ", ".join(sorted(settable)[:12]) + (", ..." if len(settable) > 12 else "")
        return (f"unknown variable '{name}' in start_values: {self.shown} has no such variable "
                f"({hint}settable variables: {shown or 'none'})")

    # -- the pool -----------------------------------------------------------------------

    def acquire(self) -> _Instance:
        with self.lock:
            if self.closed:
                raise BlockError(f"{self.shown}: the FMU block was closed")
            inst = self.idle.pop() if self.idle else None
            if inst is None and self.once_per_process and self.live:
                raise BlockError(f"{self.shown} can be instantiated only once per process, and its "
                                 "instance is in use by another run")
            self.live += 1
        if inst is None:
            try:
                inst = _Instance(self._extracted())
            except BaseException:
                with self.lock:
                    self.live -= 1
                raise
        return inst

    def _extracted(self) -> _Binary:
        """What an instance needs, extracting the archive the first time (a run starts)."""
        with self.extract_lock:
            if self.binary is None:
                folder = Path(tempfile.mkdtemp(prefix="blocks-fmu-"))
                self._dirs.append(str(folder))
                try:
                    extract_archive(self.path, folder)
                    xml = (folder / MODEL_DESCRIPTION).read_bytes()
                except (ArchiveError, OSError, zipfile.BadZipFile, EOFError) as exc:
                    shutil.rmtree(folder, ignore_errors=True)
                    raise BlockError(f"{self.shown}: extracting the FMU failed: {exc}") from None
                if xml != self.description.xml:
                    shutil.rmtree(folder, ignore_errors=True)
                    raise BlockError(f"{self.shown} has changed since the diagram was loaded; load it again")
                self.dir = folder
                self.binary = _Binary(self.shown, self.major, self.identifier, self.guid, folder,
                                      folder / self.library, self.in_groups, self.out_groups)
        return self.binary

    def release(self, inst: _Instance) -> None:
        """Take an instance back from a run: terminate and pool it, or free it if it failed."""
        if inst.started and not inst.broken:
            inst.started = False
            try:
                _arm(inst.model.major)
                inst.slave.terminate()
            except Exception:
                inst.broken = True
            fmu_interrupt.deliver()
        with self.lock:
            self.live -= 1
            keep = not inst.broken and not self.closed
            if keep:
                self.idle.append(inst)
        if not keep:
            inst.free()

    def close(self) -> None:
        with self.lock:
            self.closed = True
            idle, self.idle[:] = list(self.idle), []
            live = self.live
        for inst in idle:
            inst.free()
        if not live:
            self._cleanup()


def _remove_model(idle: list, directories: list[str]) -> None:
    for inst in list(idle):
        inst.free()
    idle.clear()
    for directory in directories:
        shutil.rmtree(directory, ignore_errors=True)


def _fraction_or_none(text: Any) -> Fraction | None:
    try:
        value = Fraction(str(text).strip())
    except (TypeError, ValueError, ZeroDivisionError):
        return None
    return value if value > 0 else None


def _float_or_none(text: Any) -> float | None:
    try:
        value = float(text)
    except (TypeError, ValueError):
        return None
    return value if math.isfinite(value) and value > 0 else None


# -- log messages ------------------------------------------------------------------------
#
# FMI 2 loggers are variadic C functions, which ctypes cannot receive; fmpy's native proxy
# (fmpy.logging.addLoggerProxy) formats the message and forwards it to ONE process-wide
# Python callback. Ours dispatches on the componentEnvironment (a serial number per
# instance) to that instance's message buffer, and is re-armed before every FMU call that
# can log, in case other code installed its own. Messages of other FMUs (fmpy's default
# callbacks) are printed as fmpy prints them. FMI 3 passes formatted messages to a
# per-instance callback.

_fmi2_buffers: dict[int, tuple[collections.deque, str]] = {}
_fmi2_proxy: tuple | None = None
_serials = itertools.count(1)


def _record(buffer: collections.deque | None, status: int, category: bytes | None,
            message: bytes | None, who: str) -> None:
    label = _STATUS[status] if 0 <= status < len(_STATUS) else str(status)
    text = (message or b"").decode("utf-8", "replace").strip()
    cat = (category or b"").decode("utf-8", "replace")
    line = f"[{label}] {cat + ': ' if cat else ''}{text}"
    if buffer is not None:
        buffer.append(line)
    # Warnings are only seen here; errors also go into the BlockError of the failing call.
    log.log({0: logging.DEBUG, 1: logging.WARNING}.get(status, logging.INFO), "%s: %s", who, line)


@fmu_interrupt.callback
def _fmi2_log(env, instance_name, status, category, message) -> None:
    entry = _fmi2_buffers.get(env or 0)
    if entry is None:  # an FMU of other code using fmpy's default callbacks: do what fmpy does
        label = _STATUS[status].upper() if 0 <= status < len(_STATUS) else str(status)
        print(f"[{label}] {(message or b'').decode('utf-8', 'replace')}")
        return
    _record(entry[0], status, category, message, entry[1])


def _fmi2_arm():
    """Make fmpy's native logger proxy forward FMI 2 messages to ``_fmi2_log``; returns
    the ctypes callback to put into an instance's callback functions."""
    global _fmi2_proxy
    if _fmi2_proxy is None:
        from ctypes import byref

        from fmpy.fmi2 import fmi2CallbackFunctions, fmi2CallbackLoggerTYPE
        from fmpy.logging import addLoggerProxy

        callback = fmi2CallbackLoggerTYPE(_fmi2_log)
        scratch = fmi2CallbackFunctions()
        _fmi2_proxy = (addLoggerProxy, scratch, byref(scratch), callback)
    add, scratch, ref, callback = _fmi2_proxy
    scratch.logger = callback
    add(ref)
    return callback


def _arm(major: int) -> None:
    """Before a call into an FMU: the interrupt hook and, for FMI 2, our logger in place."""
    fmu_interrupt.arm()
    if major == 2:
        _fmi2_arm()


# -- one FMU instance --------------------------------------------------------------------


class _Instance:
    """One fmpy slave with its preallocated value buffers and its recent log messages."""

    def __init__(self, model: _Binary):
        fmpy = _fmpy()
        import ctypes

        self.model = model
        self.serial = next(_serials)
        self.messages: collections.deque[str] = collections.deque(maxlen=LOG_LINES)
        self.started = False
        self.used = False
        self.broken = False
        self.freed = False
        self.slave = None
        name = f"{model.identifier}#{self.serial}"
        kwargs = {"guid": model.guid, "modelIdentifier": model.identifier,
                  "unzipDirectory": str(model.dir), "instanceName": name}
        cwd = os.getcwd()
        try:  # fmpy changes into the binary's folder to load it, and not back if that fails
            if model.major == 2:
                slave = fmpy.fmi2.FMU2Slave(**kwargs)
            else:
                slave = fmpy.fmi3.FMU3Slave(**kwargs)
        except Exception as exc:
            raise BlockError(f"cannot load the binary of {model.shown} "
                             f"(binaries/{model.library.parent.name}/{model.library.name}): {exc}") from None
        finally:
            if os.getcwd() != cwd:
                os.chdir(cwd)
        self.slave = slave
        fmu_interrupt.arm()
        try:
            if model.major == 2:
                from fmpy.fmi2 import (
                    fmi2CallbackAllocateMemoryTYPE,
                    fmi2CallbackFreeMemoryTYPE,
                    fmi2CallbackFunctions,
                )
                from fmpy.logging import addLoggerProxy

                callbacks = fmi2CallbackFunctions()
                callbacks.logger = _fmi2_arm()
                # the C library's own functions: no Python (which Ctrl-C could break) in between
                callbacks.allocateMemory = ctypes.cast(fmpy.calloc, fmi2CallbackAllocateMemoryTYPE)
                callbacks.freeMemory = ctypes.cast(fmpy.free, fmi2CallbackFreeMemoryTYPE)
                callbacks.componentEnvironment = self.serial
                addLoggerProxy(ctypes.byref(callbacks))
                _fmi2_buffers[self.serial] = (self.messages, f"{model.shown} ({name})")
                slave.instantiate(callbacks=callbacks)
            else:
                messages, who = self.messages, f"{model.shown} ({name})"

                def log3(env, status, category, message):
                    _record(messages, status, category, message, who)

                slave.instantiate(logMessage=fmu_interrupt.callback(log3))
        except Exception as exc:
            _fmi2_buffers.pop(self.serial, None)
            slave.freeLibrary()
            fmu_interrupt.check()
            raise BlockError(f"{model.shown}: instantiating the FMU failed: {exc}{self.log_text()}") from None
        self._buffers(ctypes)

    def _buffers(self, ctypes) -> None:
        c_types = {"Real": ctypes.c_double, "Float64": ctypes.c_double, "Float32": ctypes.c_float}
        np_types = {"Real": np.float64, "Float64": np.float64, "Float32": np.float32}
        s = self.slave
        if self.model.major == 2:
            get = {"Real": s.fmi2GetReal}
            put = {"Real": s.fmi2SetReal}
        else:
            get = {"Float64": s.fmi3GetFloat64, "Float32": s.fmi3GetFloat32}
            put = {"Float64": s.fmi3SetFloat64, "Float32": s.fmi3SetFloat32}

        def plan(groups: list[_Group], table: dict):
            out = []
            for g in groups:
                vrs = (ctypes.c_uint * len(g.vrs))(*g.vrs)
                buf = (c_types[g.kind] * g.count)()
                view = np.frombuffer(buf, dtype=np_types[g.kind])
                out.append((table[g.kind], vrs, len(g.vrs), buf, g.count, view, g.slices))
            return out

        self.reads = plan(self.model.out_groups, get)
        self.writes = plan(self.model.in_groups, put)
        # doStep straight through the library's function, its status checked here: fmpy's
        # wrapper (and, for FMI 3, its fresh output arguments) cost more than the call
        if self.model.major == 2:
            self._do_step = s._functions["fmi2DoStep"]
            self._step_flags = ()
        else:
            self._do_step = s._functions["fmi3DoStep"]
            flags = [ctypes.c_bool(), ctypes.c_bool(), ctypes.c_bool(), ctypes.c_double()]
            self._step_flags = flags
            self._step_refs = [ctypes.byref(f) for f in flags]

    def log_text(self) -> str:
        if not self.messages:
            return " (the FMU logged no messages)"
        lines = list(self.messages)[-ERROR_LOG_LINES:]
        return "; FMU log: " + " | ".join(lines)

    # -- the life cycle -------------------------------------------------------------------

    def start(self, t: float, assignments: list[_Assignment], tolerance: float | None) -> None:
        """Reset if used before, set the start values and initialise at start time ``t``."""
        s = self.slave
        if self.used:
            s.reset()
        self.used = True
        self.messages.clear()
        _arm(self.model.major)
        setters = _setters(s, self.model.major)
        for a in assignments:
            setters[a.kind]([a.vr], a.values)
        if self.model.major == 2:
            s.setupExperiment(tolerance=tolerance, startTime=t)
            s.enterInitializationMode()
        else:
            s.enterInitializationMode(tolerance=tolerance, startTime=t)
        s.exitInitializationMode()
        self.started = True

    def read(self) -> dict[str, Signal]:
        """Fresh float64 outputs: one copy per group, each port a view of it."""
        out: dict[str, Signal] = {}
        component = self.slave.component
        for fn, vrs, nvr, buf, count, view, slices in self.reads:
            if self.model.major == 2:
                fn(component, vrs, nvr, buf)
            else:
                fn(component, vrs, nvr, buf, count)
            values = view.astype(np.float64)
            for name, a, b in slices:
                out[name] = values[a:b]
        return out

    def do_step(self, t: float, h: float) -> tuple[bool, bool, float]:
        """One doStep; (terminate requested, returned early, last successful time).
        Raises fmpy's FMICallException for an error status, as fmpy's own call does."""
        if self.model.major == 2:
            status = self._do_step(self.slave.component, t, h, 1)
        else:
            status = self._do_step(self.slave.component, t, h, True, *self._step_refs)
        if status > 1:
            from fmpy.fmi1 import FMICallException

            raise FMICallException(function=f"fmi{self.model.major}DoStep", status=status)
        if self.model.major == 2:
            return False, False, t + h
        _, terminate, early, last = self._step_flags
        return terminate.value, early.value, last.value

    def write(self, inputs: Mapping[str, Signal]) -> None:
        component = self.slave.component
        for fn, vrs, nvr, buf, count, view, slices in self.writes:
            for name, a, b in slices:
                view[a:b] = inputs[name]
            if self.model.major == 2:
                fn(component, vrs, nvr, buf)
            else:
                fn(component, vrs, nvr, buf, count)

    def free(self) -> None:
        if self.freed or self.slave is None:
            return
        self.freed = True
        try:
            _arm(self.model.major)
            self.slave.freeInstance()
        except Exception as exc:  # freeing must not raise from a finalizer
            log.debug("%s: freeing the FMU instance failed: %s", self.model.shown, exc)
        finally:
            _fmi2_buffers.pop(self.serial, None)
        fmu_interrupt.deliver()


def _setters(slave: Any, major: int) -> dict[str, Any]:
    if major == 2:
        return {"Real": slave.setReal, "Integer": slave.setInteger, "Enumeration": slave.setInteger,
                "Boolean": slave.setBoolean, "String": slave.setString}
    names = ("Float32", "Float64", "Int8", "UInt8", "Int16", "UInt16", "Int32", "UInt32", "Int64",
             "UInt64", "Boolean", "String")
    table = {n: getattr(slave, "set" + n) for n in names}
    table["Enumeration"] = slave.setInt64
    return table


# -- the run state and the block ---------------------------------------------------------


class FMUState:
    """The run state of an FMU block: a handle to one FMU instance (external and mutable).

    ``instance`` is taken from the block's pool when the run first needs it (its first
    ``output`` or ``update``), so creating the state runs none of the FMU's code.
    ``time`` is the FMU's current communication point (None before initialisation) and
    ``outputs`` the FMU outputs there. ``close()`` gives the instance back to the block
    early; otherwise that happens when the state is garbage collected.
    """

    __slots__ = ("instance", "model", "time", "outputs", "_release", "__weakref__")

    def __init__(self, model: _Model):
        if model.closed:
            raise BlockError(f"{model.shown}: the FMU block was closed")
        self.instance: _Instance | None = None
        self.model = model
        self.time: float | None = None
        self.outputs: dict[str, Signal] | None = None
        self._release: weakref.finalize | None = None

    def acquire(self) -> _Instance:
        """The run's instance, taken from the pool (loading the FMU) on first use."""
        if self.instance is None:
            self.instance = self.model.acquire()
            self._release = weakref.finalize(self, self.model.release, self.instance)
        return self.instance

    def close(self) -> None:
        if self._release is not None:
            self._release()

    def __deepcopy__(self, memo):
        raise TypeError("the state of an FMU block is a live FMU instance and cannot be copied")

    def __repr__(self) -> str:
        return f"FMUState({self.model.shown}, t={self.time})"


class FMU(Block):
    """An FMI 2.0 / 3.0 co-simulation FMU; its period is the communication step."""

    param_docs = {
        "path": "the .fmu file; in a diagram a relative path is resolved against the diagram's "
                "folder (from Python, against the current directory)",
        "start_values": "mapping of FMU variable names to start values (parameters, inputs, "
                        "variables with an exact/approx start); a vector 'x' for x[1], x[2], ... "
                        "or an FMI 3 array takes a list",
        "tolerance": "relative tolerance passed to the FMU's solver; default: the FMU's "
                     "DefaultExperiment tolerance, if any",
    }
    time_varying = True
    path_params = ("path",)

    def __init__(self, path: Any, start_values: Mapping[str, Any] | None = None,
                 tolerance: float | None = None):
        if not isinstance(path, (str, os.PathLike)) or not str(path).strip():
            raise ValueError(f"parameter 'path' must be the path of an .fmu file, got {path!r}")
        file = Path(path).expanduser()
        resolved = (file if file.is_absolute() else Path.cwd() / file).absolute()
        shown = f"FMU '{path}'"
        if not resolved.exists():
            raise ValueError(f"FMU file not found: looked at {resolved} (in a diagram, a relative path "
                             "is resolved against the diagram's folder; from Python, against the "
                             "current directory)")
        if resolved.is_dir():
            raise ValueError(f"{shown} is a folder; give the path of the .fmu file")
        if not zipfile.is_zipfile(resolved):
            raise ValueError(f"{shown} is not an FMU: not a zip archive")
        if start_values is None:
            start_values = {}
        if not isinstance(start_values, Mapping):
            raise ValueError("parameter 'start_values' must be a mapping of variable names to values, "
                             f"got {type(start_values).__name__}")
        if tolerance is not None:
            tolerance = _float_or_none(tolerance)
            if tolerance is None:
                raise ValueError("parameter 'tolerance' must be a positive number")
        self.path = resolved
        self._model = _Model(resolved, shown)
        model = self._model
        self._assignments = model.assignments(start_values)
        self.tolerance = tolerance if tolerance is not None else model.default_tolerance
        self.inputs = {p.name: p.width for p in model.inputs.values()}
        self.outputs = {p.name: p.width for p in model.outputs.values()}
        self.input_defaults = model.input_starts(self._assignments)
        self.feedthrough = False
        self._step = 0.0

    @property
    def fmi_version(self) -> str:
        return self._model.md.fmiVersion

    @property
    def default_step(self) -> Fraction | None:
        """The FMU's DefaultExperiment stepSize, if it declares one."""
        return self._model.default_step

    def describe(self) -> str:
        given = len(self._assignments)
        return (f"FMI {self.fmi_version} co-simulation {self._model.shown}"
                + (f" ({given} start value{'s' if given != 1 else ''} set)" if given else ""))

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
                values = _start_of(v)
            if values:
                out[v.name] = values if v.dimensions else values[0]
        return out

    def variable_of(self, port: str) -> str:
        """The FMU variable (or vector ``x[...]``) behind a port, for messages and tools."""
        spec = self._model.inputs.get(port) or self._model.outputs.get(port)
        if spec is None:
            raise KeyError(port)
        return spec.source

    def element_labels(self, port: str) -> list[str] | None:
        """A vector made of variables ``y[1]``, ``y[2]``, ... (``A[1,1]``, ...) keeps the
        FMU's indices ("1", "2", ... or "1,1", ...); FMI 3 arrays and scalars are numbered
        from 0."""
        spec = self._model.outputs.get(port)
        return None if spec is None else spec.labels

    def bind(self, period: Fraction | None) -> None:
        """The period is the communication step; without one, the FMU's default step
        (DefaultExperiment stepSize) is used, and the diagram schedules the block at it.
        An FMU with a fixed internal step needs a whole multiple of it."""
        given = period is not None
        if period is None:
            period = self._model.default_step
            if period is None:
                raise ValueError("an FMU block needs a period, its communication step size (the FMU "
                                 "declares no default step size: add e.g. 'period: 1 ms')")
        fixed = self._model.fixed_step
        if fixed is not None:
            count = period / fixed
            if count < 1 or abs(count - round(count)) > STEP_TOLERANCE:
                which = "period" if given else "default step (DefaultExperiment stepSize)"
                near = max(1, round(count)) * fixed
                raise ValueError(f"the {which} {format_duration(period)} is not a whole multiple of the "
                                 f"fixed internal step {format_duration(fixed)} of {self._model.shown}, "
                                 f"so the FMU would refuse every step; use a multiple of it, e.g. "
                                 f"'period: {format_duration(near)}'")
        super().bind(period)
        self._step = float(period)

    def is_stateful(self) -> bool:  # without instantiating the FMU, as initial_state() would
        return True

    def initial_state(self) -> FMUState:
        return FMUState(self._model)

    def _start(self, t: float, state: FMUState) -> None:
        """The run's first call: take an instance (loading the FMU) and initialise it at ``t``."""
        inst = state.acquire()
        try:
            inst.start(t, self._assignments, self.tolerance)
            state.time = t
            state.outputs = inst.read()
        except Exception as exc:
            inst.broken = True
            fmu_interrupt.check()  # a failure that comes with Ctrl-C is the interrupt
            raise BlockError(f"{self._model.shown}: initialising the FMU at t={t:.9g} s failed: "
                             f"{_reason(exc)}{inst.log_text()}") from None
        fmu_interrupt.check()

    def output(self, t: float, state: FMUState, inputs: Mapping[str, Signal]) -> dict[str, Signal]:
        if state.time is None:
            self._start(t, state)
        return state.outputs

    def update(self, t: float, state: FMUState, inputs: Mapping[str, Signal]) -> FMUState:
        if state.time is None:
            self._start(t, state)
        inst = state.instance
        h = self._step
        if inst.broken:
            raise BlockError(f"{self._model.shown}: the FMU instance failed earlier and cannot step")
        if abs(t - state.time) > 1e-9 * max(h, abs(t)):
            raise BlockError(f"{self._model.shown}: asked to step from t={t:.9g} s, but the FMU is at "
                             f"t={state.time:.9g} s (the block must fire every period)")
        try:
            _arm(inst.model.major)
            inst.write(inputs)
            terminate, early, last = inst.do_step(t, h)
            fmu_interrupt.check()
            if terminate or early:
                inst.broken = True
                what = "requested to terminate the simulation" if terminate else f"returned early at t={last:.9g} s"
                raise BlockError(f"{self._model.shown}: doStep at t={t:.9g} s (step {h:.9g} s) "
                                 f"{what}{inst.log_text()}")
            state.time = t + h
            state.outputs = inst.read()
        except BlockError:
            raise
        except Exception as exc:
            inst.broken = True
            fmu_interrupt.check()  # a failure that comes with Ctrl-C is the interrupt
            raise BlockError(f"{self._model.shown}: {_reason(exc, t, h)}{inst.log_text()}") from None
        return state

    def close(self) -> None:
        """Free the pooled FMU instances and, once no run holds one, the extracted files."""
        self._model.close()


def _reason(exc: BaseException, t: float | None = None, h: float | None = None) -> str:
    function = getattr(exc, "function", None)
    status = getattr(exc, "status", None)
    if function is None:
        return f"{type(exc).__name__}: {exc}" if not isinstance(exc, BlockError) else str(exc)
    label = _STATUS[status] if isinstance(status, int) and 0 <= status < len(_STATUS) else str(status)
    if function.endswith("DoStep") and t is not None:
        return f"{function} at t={t:.9g} s (step {h:.9g} s) returned status '{label}'"
    return f"{function} returned status '{label}'"
