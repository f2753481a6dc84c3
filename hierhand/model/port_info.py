"""What the hand blocks' ports carry: the unit of each port and the names of its elements.

One table for the plant and the blocks that read or drive it, so that ``plant.q`` and
``reflex.q`` say the same: joint vectors are named ``finger.joint`` (``thumb.1`` ...
``middle.3``, joints counted from the palm), per-finger vectors by finger (``thumb``,
``fore``, ``middle``), tip poses ``finger.x``, ``finger.y``, ``finger.phi``. Units are SI;
``"1"`` marks a dimensionless value (a ratio, a 0/1 flag, a unit vector, a share).
"""

from __future__ import annotations

from typing import Callable, Sequence

Names = Sequence[str]

JOINT_AXES = ("1", "2", "3")
POSE = ("x", "y", "theta")
WRENCH = ("fx", "fy", "torque")


def joints(names: Names) -> list[str]:
    """``thumb.1``, ``thumb.2``, ``thumb.3``, ``fore.1``, ...: one per joint, finger by finger."""
    return [f"{n}.{j}" for n in names for j in JOINT_AXES]


def fingers(names: Names) -> list[str]:
    return [str(n) for n in names]


def tips(names: Names) -> list[str]:
    """x, y of the tip centre and phi, the absolute angle of link 3, finger by finger."""
    return [f"{n}.{c}" for n in names for c in ("x", "y", "phi")]


def normals(names: Names) -> list[str]:
    return [f"{n}.{c}" for n in names for c in ("x", "y")]


# port -> (unit, or one per element for a three-finger hand; element names from the finger names)
PORTS: dict[str, tuple[str | list[str], Callable[[Names], list[str]]]] = {
    "q": ("rad", joints),
    "q_ref": ("rad", joints),
    "qd": ("rad/s", joints),
    "tau": ("N m", joints),
    "tau_g": ("N m", joints),
    "tau_m": ("N m", joints),
    "tau_ff": ("N m", joints),
    "tau_g_eff": ("N m", joints),
    "tip": (["m", "m", "rad"] * 3, tips),
    "fn": ("N", fingers),
    "ft": ("N", fingers),
    "force": ("N", fingers),
    "ratio": ("1", fingers),
    "contact": ("1", fingers),
    "active": ("1", fingers),
    "share": ("1", fingers),
    "normal": ("1", normals),
    "obj": (["m", "m", "rad"], lambda names: list(POSE)),
    "obj_vel": (["m/s", "m/s", "rad/s"], lambda names: ["vx", "vy", "omega"]),
    "f_ext": (["N", "N", "N m"], lambda names: list(WRENCH)),
    "support": (["N", "N", "N m"], lambda names: list(WRENCH)),
    "y": (["N", "N", "N m"], lambda names: list(WRENCH)),  # ObjectSupport: the plant's f_ext
}

NUMBERED = ("f1", "f2", "f3")
"""Finger names for a block that does not know the hand's (the Suppresser): fingers in the
hand's order."""


def port_units(port: str) -> str | list[str] | None:
    entry = PORTS.get(port)
    return None if entry is None else entry[0]


def element_labels(port: str, names: Names) -> list[str] | None:
    entry = PORTS.get(port)
    return None if entry is None else entry[1](names)


class DescribesHandPorts:
    """Mixin for hand blocks: ``port_units`` and ``element_labels`` from the table above,
    with the finger names of ``self.hand`` (``NUMBERED`` for a block without a hand)."""

    def port_units(self, port: str) -> str | list[str] | None:
        return port_units(port) if port in self.inputs or port in self.outputs else None

    def element_labels(self, port: str) -> list[str] | None:
        if port not in self.inputs and port not in self.outputs:
            return None
        hand = getattr(self, "hand", None)
        return element_labels(port, hand.names if hand is not None else NUMBERED)
