"""The hand file: YAML (or a dict) describing three fingers, the object and the contact law.

Loading is strict so that a typo never silently becomes a default: unknown keys are
rejected and every field is checked, and all problems of a file are reported at once,
each naming its field (``fingers[1].links[2].mass must be > 0``). Top-level sections are
optional and default to the shipped hand (``default_hand.yaml`` beside this module);
``object`` and ``contact`` may be partial, their missing keys taken from the default.

This module checks the file's shape (sections, keys, lists, numbers); what values a
hand's numbers may take (positive masses, mu_d <= mu_s, ...) is judged by the C core
(``hand_params.c``), the same check an exported FMU applies to its parameters.

A hand file is read like a diagram (``blocks.diagram_file.yaml_source``: the same limits, and the line
of every key), so each problem is reported at the line of the field it names; the
diagram loader does the same for a plant's params file through ``ParameterError``.
"""

from __future__ import annotations

import functools
import math
import re
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any, Mapping

import numpy as np
import yaml

from blocks import Issue, ParameterError
from blocks.diagram_file.yaml_source import YamlSourceError, line_at, load_yaml, read_yaml_file

from .. import _native
from .hand_vector import hand_file_path, hand_vector, parameter_names

DEFAULT_HAND_FILE = Path(__file__).with_name("default_hand.yaml")

N_FINGERS = 3
N_LINKS = 3

SECTIONS = ("gravity", "fingers", "object", "contact")
FINGER_KEYS = ("name", "base", "base_angle", "links", "damping", "armature", "tip_radius", "q0")
LINK_KEYS = ("length", "mass", "com", "inertia")
OBJECT_KEYS = ("mass", "inertia", "size", "pos", "angle", "surface_spacing")
OBJECT_OPTIONAL = ("inertia",)
CONTACT_KEYS = ("k_n", "c_n", "k_t", "c_t", "mu_s", "mu_d")


class HandFileError(ParameterError):
    """A hand file (or the plant's parameters) is invalid; ``errors`` lists every problem.

    ``fields`` names the hand-file field of each problem (``fingers[1].links[2].mass``,
    "" for the hand as a whole), which the diagram loader turns into a line of the
    diagram or params file (``problems``); ``lines`` holds those lines for a hand file
    read from disk (``load_hand``), None where unknown.
    """

    def __init__(self, errors: list[str], source: str | None = None, fields: list[str] | None = None,
                 lines: list[int | None] | None = None):
        self.errors = list(errors)
        self.source = source
        self.fields = list(fields) if fields is not None else [""] * len(self.errors)
        self.lines = list(lines) if lines is not None else [None] * len(self.errors)
        where = f" {source}" if source else ""
        text = "\n".join(f"  - {e}" for e in self.errors)
        super().__init__([(field_path(f), e) for f, e in zip(self.fields, self.errors)],
                         f"invalid hand file{where}:\n{text}")

    def located(self, data: Any) -> "HandFileError":
        """This error with the line of each problem's field in ``data`` (a hand file as
        ``read_hand_file`` returns it)."""
        return HandFileError(self.errors, self.source, self.fields,
                             [line_at(data, path)[0] for path, _ in self.problems])

    def issues(self) -> list[Issue]:
        """One ``file:line: problem`` per problem."""
        return [Issue(self.source or "hand file", line, error) for error, line in zip(self.errors, self.lines)]


_FIELD_PART = re.compile(r"([^.\[\]]+)|\[(\d+)\]")


def field_path(field: str) -> tuple:
    """A hand-file field as keys and indices: ``fingers[1].links[2].mass`` -> ("fingers", 1, "links", 2, "mass")."""
    return tuple(int(index) if index else key for key, index in _FIELD_PART.findall(field))


@dataclass(frozen=True)
class LinkParams:
    """One link: length to the next joint (or to the tip centre), mass, COM and inertia."""

    length: float
    mass: float
    com_along: float
    com_across: float
    inertia: float


@dataclass(frozen=True)
class FingerParams:
    name: str
    base: tuple[float, float]
    base_angle: float
    links: tuple[LinkParams, LinkParams, LinkParams]
    damping: tuple[float, float, float]
    armature: tuple[float, float, float]
    tip_radius: float
    q0: tuple[float, float, float]


@dataclass(frozen=True)
class ObjectParams:
    """The grasped square: its inertia defaults to a uniform plate, m (a^2 + b^2) / 12."""

    mass: float
    inertia: float
    size: tuple[float, float]
    pos: tuple[float, float]
    angle: float
    surface_spacing: float


@dataclass(frozen=True)
class ContactParams:
    k_n: float
    c_n: float
    k_t: float
    c_t: float
    mu_s: float
    mu_d: float


@dataclass(frozen=True)
class HandParams:
    """A validated hand file."""

    gravity: tuple[float, float]
    fingers: tuple[FingerParams, FingerParams, FingerParams]
    object: ObjectParams
    contact: ContactParams

    def to_dict(self) -> dict[str, Any]:
        """The hand file form of these parameters (``com`` always as ``[along, across]``)."""
        d = asdict(self)
        for finger in d["fingers"]:
            for link in finger["links"]:
                link["com"] = [link.pop("com_along"), link.pop("com_across")]
        return _lists(d)

    @property
    def vector(self) -> np.ndarray:
        """The hand's numbers in the C core's order (read-only; computed once per hand,
        shared by equal hands: every point of a sweep loads the same one)."""
        return _hand_vector(self)


@functools.lru_cache(maxsize=64)
def _hand_vector(params: HandParams) -> np.ndarray:
    vector = hand_vector(params.to_dict())
    vector.flags.writeable = False
    return vector


def _lists(x: Any) -> Any:
    if isinstance(x, dict):
        return {k: _lists(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_lists(v) for v in x]
    return x


_SafeLoader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
"""libyaml's parser where PyYAML has it: the plant and both controllers read the hand."""


@functools.cache
def _default_hand() -> dict[str, Any]:
    with open(DEFAULT_HAND_FILE, encoding="utf-8") as fh:
        return yaml.load(fh, Loader=_SafeLoader)


def default_hand_dict() -> dict[str, Any]:
    """The shipped default hand file as a plain dict (a fresh copy; the file is read once)."""
    return _fresh(_default_hand())


def _fresh(x: Any) -> Any:
    """A copy of YAML data (mappings, lists, scalars), several times faster than deepcopy."""
    if isinstance(x, dict):
        return {k: _fresh(v) for k, v in x.items()}
    if isinstance(x, list):
        return [_fresh(v) for v in x]
    return x


def read_hand_file(path: str | Path) -> dict[str, Any]:
    """A hand file's raw content, a mapping with the line of every key (see
    ``blocks.diagram_file.yaml_source``); HandFileError at the line where it cannot be read as one."""
    try:
        data = load_yaml(read_yaml_file(path))
    except YamlSourceError as exc:
        hint = f" (hint: {exc.hint})" if exc.hint else ""
        raise HandFileError([exc.message + hint], str(path), lines=[exc.line]) from None
    if data is None:
        data = {}
    if not isinstance(data, dict):
        raise HandFileError(["the file must be a mapping of sections " + ", ".join(SECTIONS)], str(path),
                            lines=[getattr(data, "line", 1)])
    return data


def merge_with_default(sections: Mapping[str, Any]) -> dict[str, Any]:
    """Fill the sections not given (``None`` counts as not given) from the default hand.

    ``gravity`` and ``fingers`` replace the default as a whole; ``object`` and ``contact``
    are merged key by key, except that a given ``object`` without ``inertia`` gets the plate
    inertia of its own mass and size rather than the default's number.
    """
    merged = default_hand_dict()
    for key, value in sections.items():
        if value is None:
            continue
        if key in ("object", "contact") and isinstance(value, Mapping):
            base = dict(merged[key])
            if key == "object" and "inertia" not in value:
                base.pop("inertia", None)
            base.update(value)
            merged[key] = base
        else:
            merged[key] = value
    return merged


def parse_hand(data: Mapping[str, Any], source: str | None = None) -> HandParams:
    """Validate a complete hand dict (every section present) into ``HandParams``."""
    check = _Checker()
    if not isinstance(data, Mapping):
        raise HandFileError(["the hand must be a mapping of sections " + ", ".join(SECTIONS)], source)
    check.unknown_keys(data, SECTIONS, "")
    for key in SECTIONS:
        if key not in data:
            check.error(key, "is missing")
    check.raise_errors(source)

    gravity = check.vector(data["gravity"], "gravity", 2)
    fingers = _parse_fingers(check, data["fingers"])
    obj = _parse_object(check, data["object"])
    contact = _parse_contact(check, data["contact"])
    check.raise_errors(source)
    params = HandParams(gravity=gravity, fingers=fingers, object=obj, contact=contact)
    derived = set() if "inertia" in data["object"] else {"object.inertia"}  # follows mass and size
    names = parameter_names()
    for i, text in _native.check_hand(params.vector):
        if names[i] not in derived:
            check.error(hand_file_path(names[i]), text)
    check.raise_errors(source)
    return params


def _parse_fingers(check: "_Checker", raw: Any) -> tuple[FingerParams, ...] | None:
    if not isinstance(raw, list) or len(raw) != N_FINGERS:
        check.error("fingers", f"must be a list of exactly {N_FINGERS} fingers (thumb, fore, middle)")
        return None
    fingers = []
    names: set[str] = set()
    for i, f in enumerate(raw):
        path = f"fingers[{i}]"
        if not isinstance(f, Mapping):
            check.error(path, "must be a mapping with keys " + ", ".join(FINGER_KEYS))
            fingers.append(None)
            continue
        if not check.keys(f, FINGER_KEYS, path):
            fingers.append(None)
            continue
        name = f["name"]
        if not isinstance(name, str) or not name.strip():
            check.error(f"{path}.name", "must be a non-empty string")
        elif name in names:
            check.error(f"{path}.name", f"'{name}' is used by another finger")
        names.add(str(name))
        links = _parse_links(check, f["links"], f"{path}.links")
        fingers.append(
            FingerParams(
                name=str(name),
                base=check.vector(f["base"], f"{path}.base", 2),
                base_angle=check.number(f["base_angle"], f"{path}.base_angle"),
                links=links,
                damping=check.vector(f["damping"], f"{path}.damping", N_LINKS),
                armature=check.vector(f["armature"], f"{path}.armature", N_LINKS),
                tip_radius=check.number(f["tip_radius"], f"{path}.tip_radius"),
                q0=check.vector(f["q0"], f"{path}.q0", N_LINKS),
            )
        )
    return None if any(f is None for f in fingers) else tuple(fingers)


def _parse_links(check: "_Checker", raw: Any, path: str) -> tuple[LinkParams, ...] | None:
    if not isinstance(raw, list) or len(raw) != N_LINKS:
        check.error(path, f"must be a list of exactly {N_LINKS} links (proximal to distal)")
        return None
    links = []
    for j, link in enumerate(raw):
        lpath = f"{path}[{j}]"
        if not isinstance(link, Mapping):
            check.error(lpath, "must be a mapping with keys " + ", ".join(LINK_KEYS))
            continue
        if not check.keys(link, LINK_KEYS, lpath):
            continue
        length = check.number(link["length"], f"{lpath}.length")
        com = link["com"]
        if isinstance(com, (list, tuple)):
            along, across = check.vector(com, f"{lpath}.com", 2)
        else:
            along, across = check.number(com, f"{lpath}.com"), 0.0
        links.append(
            LinkParams(
                length=length,
                mass=check.number(link["mass"], f"{lpath}.mass"),
                com_along=along,
                com_across=across,
                inertia=check.number(link["inertia"], f"{lpath}.inertia"),
            )
        )
    return tuple(links) if len(links) == N_LINKS else None


def _parse_object(check: "_Checker", raw: Any) -> ObjectParams | None:
    if not isinstance(raw, Mapping):
        check.error("object", "must be a mapping with keys " + ", ".join(OBJECT_KEYS))
        return None
    if not check.keys(raw, OBJECT_KEYS, "object", optional=OBJECT_OPTIONAL):
        return None
    mass = check.number(raw["mass"], "object.mass")
    size = check.vector(raw["size"], "object.size", 2)
    if "inertia" in raw:
        inertia = check.number(raw["inertia"], "object.inertia")
    else:
        inertia = _native.plate_inertia(mass, size[0], size[1])
    spacing = check.number(raw["surface_spacing"], "object.surface_spacing")
    return ObjectParams(
        mass=mass,
        inertia=inertia,
        size=size,
        pos=check.vector(raw["pos"], "object.pos", 2),
        angle=check.number(raw["angle"], "object.angle"),
        surface_spacing=spacing,
    )


def _parse_contact(check: "_Checker", raw: Any) -> ContactParams | None:
    if not isinstance(raw, Mapping):
        check.error("contact", "must be a mapping with keys " + ", ".join(CONTACT_KEYS))
        return None
    if not check.keys(raw, CONTACT_KEYS, "contact"):
        return None
    return ContactParams(*(check.number(raw[key], f"contact.{key}") for key in CONTACT_KEYS))


class _Checker:
    """Collects field errors; each check returns a usable value (0.0) even when it fails."""

    def __init__(self) -> None:
        self.errors: list[str] = []
        self.fields: list[str] = []

    def error(self, field: str, text: str) -> None:
        """A problem of ``field`` (``object.mass``), reported as "object.mass <text>"."""
        self.errors.append(f"{field} {text}")
        self.fields.append(field)

    def raise_errors(self, source: str | None) -> None:
        if self.errors:
            raise HandFileError(self.errors, source, self.fields)

    def unknown_keys(self, d: Mapping[str, Any], allowed: tuple[str, ...], path: str) -> None:
        for key in d:
            if key not in allowed:
                where = f"{path}.{key}" if path else str(key)
                self.error(where, f"is not a known key (allowed: {', '.join(allowed)})")

    def keys(self, d: Mapping[str, Any], allowed: tuple[str, ...], path: str, optional: tuple[str, ...] = ()) -> bool:
        """Check for unknown and missing keys; ``False`` if a required key is missing."""
        self.unknown_keys(d, allowed, path)
        missing = [k for k in allowed if k not in d and k not in optional]
        for k in missing:
            self.error(f"{path}.{k}", "is missing")
        return not missing

    def number(self, value: Any, path: str) -> float:
        """A finite number (its allowed range is the C core's check)."""
        # PyYAML reads 1e-4 (no dot) as a string, so numeric strings are accepted too.
        if isinstance(value, bool) or not isinstance(value, (int, float, str)):
            self.error(path, f"must be a number, got {value!r}")
            return 0.0
        try:
            x = float(value)
        except ValueError:
            self.error(path, f"must be a number, got {value!r}")
            return 0.0
        if not math.isfinite(x):
            self.error(path, f"must be finite, got {value!r}")
            return 0.0
        return x

    def vector(self, value: Any, path: str, n: int) -> tuple[float, ...]:
        if not isinstance(value, (list, tuple)) or len(value) != n:
            self.error(path, f"must be a list of {n} numbers, got {value!r}")
            return (0.0,) * n
        return tuple(self.number(v, f"{path}[{i}]") for i, v in enumerate(value))
