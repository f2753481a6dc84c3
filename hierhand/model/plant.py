"""``HandPlant``: the hand/object plant as a block (penalty contact, 0.1 ms typical).

The state is one flat float64 vector (layout ``STATE`` of ``hierhand/csrc/layouts.h``): joint angles
and rates, object pose and velocity, and the contact bookkeeping (per finger and surface
point an in-contact flag and an anchor). Copying it checkpoints a run. ``views(state)``
names its parts. All physics runs in the C core (``hierhand/csrc``, through
``hierhand._native``): ``update``, ``output`` and ``advance`` are one native call each,
and ``advance`` equals n times ``update`` then ``output``, bit for bit.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Any, Mapping

import numpy as np

from blocks.arrays import float_array
from blocks.block import Block, BlockError
from blocks.engine.kernel import Kernel, KernelRecord

from .. import _native
from ..layouts import OUTPUT, PLANT_INPUTS, PLANT_RECORD, PLANT_STATUS, STATE, WRENCH, port_columns, ports
from ..records import KERNELS, context_of, hand_segment, hand_tunables, inertia_follows, record
from .hand import Hand
from .handfile import SECTIONS, default_hand_dict, merge_with_default, parse_hand
from .port_info import DescribesHandPorts

_PORT_SLICES = port_columns(OUTPUT)  # (port, its columns in a row)
_PORT_COLUMNS = [(name, (slice(None), sl)) for name, sl in _PORT_SLICES]  # ready-made 2-D indices
_ZERO3 = np.zeros(3)
_ZERO3.flags.writeable = False
_advance, _step, _output = _native.advance, _native.step, _native.output
_KERNEL_FUNCTIONS = {phase: KERNELS[f"HandPlant.{phase}"] for phase in ("output", "update", "advance")}


def anchor_offset(npts: int) -> int:
    """Where the anchors start in the state, after the touching flags (its length: ``Model.state_size``)."""
    return STATE.TOUCH + 3 * npts


@dataclass(frozen=True)
class StateViews:
    """Named views into a plant state vector (writing through them changes the state)."""

    q: np.ndarray  # (9,)
    qd: np.ndarray  # (9,)
    obj: np.ndarray  # (3,) x, y, theta
    obj_vel: np.ndarray  # (3,) vx, vy, omega
    window: np.ndarray  # (3, 4, 2) per finger and edge: first, last point that may touch
    touching: np.ndarray  # (3, n_points) 1.0 where the point holds an anchor on the tip
    anchor: np.ndarray  # (3, n_points, 2) anchors in the link-3 frame, from the tip centre


@dataclass(frozen=True)
class ContactWrenches:
    """Contact forces of a state, per finger (rows thumb, fore, middle)."""

    on_object: np.ndarray  # (3, 2) force the fingertip applies to the object
    object_moment: np.ndarray  # (3,) its moment about the object's centre
    on_finger: np.ndarray  # (3, 2) force the object applies to the fingertip
    finger_moment: np.ndarray  # (3,) its moment about the tip centre
    point: np.ndarray  # (3, 2) normal-force-weighted contact point (NaN without contact)
    fn: np.ndarray  # (3,) summed normal force
    ft: np.ndarray  # (3,) summed tangential force
    tip: np.ndarray  # (3, 3) tip centre x, y and link-3 angle


class HandPlant(DescribesHandPorts, Block):
    """Three-fingered planar hand grasping a square object, with the paper's contact law;
    the diagram's one hand, which the other blocks use by naming this block (hand: plant).

    Parameters are the hand file's sections (``gravity``, ``fingers``, ``object``,
    ``contact``), each defaulting to the shipped hand. This is the one place a diagram
    gives its hand: the controllers and the object support refer to this block
    (``hand: plant``) and model the same ``Hand``. The period is the integration step
    of a semi-implicit Euler scheme (``hierhand/csrc/plant.c`` says why not explicit Euler).

    Inputs: ``tau`` (9 joint torques), ``f_ext`` (fx, fy, torque on the object; zero when
    unconnected). Outputs of the state at a hit: ``q``, ``qd``, ``tip`` (x, y, phi per
    finger, phi the absolute angle of link 3), ``fn`` and ``ft`` (per finger, the normal
    and tangential forces of its contact points summed, as a fingertip force sensor
    reports them; ``ft`` is the force on the object along the tip's counter-clockwise
    tangent), ``ratio`` (|ft| / fn, 0 without contact), ``contact`` (1.0 while fn > 0),
    ``obj`` (x, y, theta), ``obj_vel``, ``normal`` (per finger the unit vector from the tip
    centre to its normal-force-weighted contact point: the direction of the normal force on
    the object, zero without contact). Summing per point keeps ``ratio <= mu_s`` exact.

    Parameters
    ----------
    gravity : list of 2 floats
        [gx, gy] in m/s^2 (default [0, -9.81])
    fingers : list of 3 mappings
        the three fingers, each with base, base_angle, links, damping, armature,
        tip_radius, q0
    object : mapping
        mass, inertia, size, pos, angle, surface_spacing (keys not given keep the default)
    contact : mapping
        k_n, c_n, k_t, c_t, mu_s, mu_d (keys not given keep the default)
    """

    samples_continuous_time = True

    type_name = "HandPlant"
    feedthrough = False

    def __init__(self, gravity=None, fingers=None, object=None, contact=None):  # noqa: A002 - hand file name
        sections = {"gravity": gravity, "fingers": fingers, "object": object, "contact": contact}
        self.hand = Hand(parse_hand(merge_with_default(sections), "HandPlant parameters"))
        self._given = tuple(key for key in SECTIONS if sections[key] is not None)
        given_inertia = isinstance(object, Mapping) and "inertia" in object
        self._inertia_may_follow = not given_inertia
        """Whether the object's inertia follows its mass and size when they change (the
        diagram does not give it)."""
        self._inertia_derived = object is not None and not given_inertia
        """Whether it was computed from them here."""
        self.inputs = dict(PLANT_INPUTS)
        self.input_defaults = {"f_ext": _ZERO3}
        self.outputs = dict(ports(OUTPUT))
        self.n_points = self.hand.n_points
        self._state_shape = (self.hand.native.state_size,)
        self._model: _native.Model | None = None  # the hand packed with its step, once bound
        self.dt: float | None = None

    @classmethod
    def param_default(cls, name: str) -> Any:
        """``gravity`` and ``fingers`` replace the default hand's as a whole, so a ``--set``
        path into them (``plant.fingers.1.links.0.length``) starts from the default hand's;
        ``object`` and ``contact`` are merged key by key, so one starts empty and the keys
        it does not give keep following the default (an object's inertia its mass)."""
        return default_hand_dict()[name] if name in ("gravity", "fingers") else None

    def describe(self) -> str:
        """Where the hand comes from: the built-in default hand, or which sections the
        diagram gives."""
        if not self._given:
            return "hand: the built-in default hand"
        if len(self._given) == len(SECTIONS):
            return "hand: all from the diagram"
        return f"hand: {', '.join(self._given)} from the diagram, the rest from the built-in default hand"

    @classmethod
    def from_hand(cls, hand: Hand) -> "HandPlant":
        """A plant for an already loaded ``Hand``."""
        return cls(**hand.params.to_dict())

    def bind(self, period) -> None:
        if period is None:
            raise ValueError("HandPlant needs an explicit period (its integration step, e.g. '0.1 ms')")
        dt = float(period)
        if not dt > 0:
            raise ValueError(f"HandPlant period must be > 0, got {period}")
        self.period = period
        self.dt = dt
        self._model = self.hand.native.with_dt(dt)

    # -- state ------------------------------------------------------------------------

    def initial_state(self) -> np.ndarray:
        state = np.empty(self._state_shape)
        _native.initial_state(self.hand.native, state)
        return state

    def views(self, state: np.ndarray) -> StateViews:
        n = self.n_points
        a = anchor_offset(n)
        return StateViews(
            q=state[STATE.slice("Q")],
            qd=state[STATE.slice("QD")],
            obj=state[STATE.slice("OBJ")],
            obj_vel=state[STATE.slice("OBJ_VEL")],
            window=state[STATE.slice("WINDOW")].reshape(3, 4, 2),
            touching=state[STATE.TOUCH:a].reshape(3, n),
            anchor=state[a : a + 6 * n].reshape(3, n, 2),
        )

    # -- the block contract -------------------------------------------------------------

    # Fast paths: the native call checks the arrays it is given (float64, C-contiguous,
    # their lengths) and every value for finiteness, reporting by code; anything it
    # refuses goes through ``_arguments``, which converts inputs or names the problem.

    def output(self, t: float, state: np.ndarray, inputs: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
        row = np.empty(OUTPUT.size)
        try:
            code, _, which = _output(self._model, state, row)
        except (TypeError, ValueError):
            self._check_state(state)
            raise
        if code:
            raise self._error(code, which, t)
        return {name: row[sl] for name, sl in _PORT_SLICES}

    def update(self, t: float, state: np.ndarray, inputs: Mapping[str, np.ndarray]) -> np.ndarray:
        tau, f_ext = inputs["tau"], inputs.get("f_ext", _ZERO3)
        try:
            code, done, which = _step(self._model, state, tau, f_ext)
        except (TypeError, ValueError):
            tau, f_ext = self._arguments(state, inputs)
            code, done, which = _step(self._model, state, tau, f_ext)
        if code:
            raise self._error(code, which, t, step=True)
        return state

    def advance(self, t: float, state: np.ndarray, inputs: Mapping[str, np.ndarray], n: int):
        tau, f_ext = inputs["tau"], inputs.get("f_ext", _ZERO3)
        rows = np.empty((n, OUTPUT.size))
        try:
            code, done, which = _advance(self._model, state, tau, f_ext, rows)
        except (TypeError, ValueError):
            tau, f_ext = self._arguments(state, inputs)
            code, done, which = _advance(self._model, state, tau, f_ext, rows)
        if code:
            written = max(done - 1, 0)  # the state after update ``done`` is the bad one: no row for it
            error = self._error(code, which, t + written * self.dt, step=True)
            error.rows = {name: rows[:written][index] for name, index in _PORT_COLUMNS}
            raise error
        return state, {name: rows[index] for name, index in _PORT_COLUMNS}

    def kernel(self) -> Kernel | None:
        """The C step functions (kernel type ``HandPlant``, ``hierhand/csrc/kernel_types.c``):
        the native calls of ``output``, ``update`` and ``advance``; None before ``bind``.
        Its ``bind`` builds each run a context of its own from the record (the model and
        the scratch the steps write), so runs in several threads share nothing and run
        without the GIL. The output row's ports lie one after the other in the order of
        ``outputs``, and the inputs are ``tau``, ``f_ext``, as the kernel convention wants.
        The record, ``[dt, hand segment]``, makes every number of the hand tunable in an
        exported FMU; the object's inertia follows its mass and size there as it does in
        a diagram (unless the diagram gives the inertia)."""
        if self.dt is None:
            return None
        rec = self.kernel_record()
        return Kernel(context=0, bind=functools.partial(self._bound_kernel, rec), nogil=True, record=rec,
                      **_KERNEL_FUNCTIONS)

    def kernel_record(self) -> KernelRecord:
        """``[dt, hand segment]`` (``PLANT_RECORD``) with the hand's numbers as tunables."""
        return record("HandPlant", [self.dt], hand_segment(self.hand, self._inertia_derived),
                      tunables=hand_tunables(PLANT_RECORD.SEGMENT),
                      follows=inertia_follows(PLANT_RECORD.SEGMENT) if self._inertia_may_follow else ())

    def _bound_kernel(self, rec: KernelRecord, state: np.ndarray) -> Kernel:
        """``Kernel.bind``: the kernel of one run, stepping ``state`` in a context of its own."""
        self._check_state(state)
        ctx = context_of(rec)
        return Kernel(context=ctx.address, owners=(ctx,), error=self._kernel_error, nogil=True, record=rec,
                      **_KERNEL_FUNCTIONS)

    def _kernel_error(self, code: int, which: int, t: float, phase: str) -> BlockError:
        """The kernel's failure as the Python methods raise it (``t``: the failing step's
        time, for an advance the executor's, which counts the rows completed)."""
        return self._error(code, which, t, step=phase in ("update", "advance"))

    def _arguments(self, state: np.ndarray, inputs: Mapping[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        """(tau, f_ext) as the native calls take them; a state they cannot take, or an
        input of the wrong width, is a ``BlockError`` naming it."""
        self._check_state(state)
        f_ext = inputs.get("f_ext")
        return _port_vector(inputs["tau"], 9, "tau"), _ZERO3 if f_ext is None else _port_vector(f_ext, 3, "f_ext")

    # -- inspection -------------------------------------------------------------------

    def contact_wrenches(self, state: np.ndarray) -> ContactWrenches:
        """The contact forces of ``state`` (the same evaluation the step uses)."""
        self._check_state(state)
        tips = np.empty((3, 3))
        w = np.empty((3, WRENCH.size))
        code, _, which = _native.contact(self._model, state, tips, w)
        if code:
            raise self._error(code, which, None)
        on_obj = w[:, [WRENCH.OBJ_FX, WRENCH.OBJ_FY]].copy()
        fn = w[:, WRENCH.FN].copy()
        with np.errstate(invalid="ignore", divide="ignore"):
            point = np.where(fn[:, None] > 0, w[:, [WRENCH.FN_PX, WRENCH.FN_PY]] / fn[:, None], np.nan)
        return ContactWrenches(
            on_object=on_obj,
            object_moment=w[:, WRENCH.OBJ_M].copy(),
            on_finger=-on_obj,
            finger_moment=-w[:, WRENCH.TIP_M],
            point=point,
            fn=fn,
            ft=w[:, WRENCH.FT].copy(),
            tip=tips,
        )

    # -- helpers ----------------------------------------------------------------------

    def _check_state(self, state: Any) -> None:
        if not (isinstance(state, np.ndarray) and state.dtype == np.float64 and state.shape == self._state_shape
                and state.flags.c_contiguous and state.flags.writeable):
            raise BlockError(
                f"HandPlant state must be the float64 vector of shape {self._state_shape} made by initial_state()"
            )
        if self._model is None:
            raise BlockError("HandPlant is not bound to a period; call bind(period) first")

    def _error(self, code: int, which: int, t: float | None, step: bool = False) -> BlockError:
        """The error for a native failure code. ``t`` is the time of the state that was
        evaluated, or with ``step`` the time of the step that failed: the executor's failure
        time, so that a run's status names one time (the bad state is the one after it)."""
        names = self.hand.names
        when = "in the given state" if t is None else f"in the step at t={t:.10g} s" if step else f"at t={t:.10g} s"
        if code == PLANT_STATUS.ERR_PENETRATION:
            r = self.hand.tip_radius[which]
            return BlockError(
                f"HandPlant: contact penetration deeper than the fingertip radius {when}: "
                f"the {names[which]} tip centre is inside the object (radius {r * 1e3:g} mm); "
                "the contact is too soft for the forces or the step too large",
                port="contact",
            )
        status = PLANT_STATUS
        in_joint = code in (status.ERR_Q, status.ERR_QD, status.ERR_TAU)
        joint = f"{names[which // 3]} joint {which % 3 + 1}" if in_joint else ""
        what = {
            status.ERR_Q: ("q", f"joint angle q[{which}] ({joint})"),
            status.ERR_QD: ("qd", f"joint velocity qd[{which}] ({joint})"),
            status.ERR_OBJ: ("obj", f"object pose obj[{which}] ({('x', 'y', 'theta')[which % 3]})"),
            status.ERR_OBJ_VEL: ("obj_vel", f"object velocity obj_vel[{which}] ({('vx', 'vy', 'omega')[which % 3]})"),
            status.ERR_TAU: ("tau", f"input torque tau[{which}] ({joint})"),
            status.ERR_F_EXT: ("f_ext", f"input f_ext[{which}]"),
        }
        port, quantity = what[code]
        return BlockError(f"HandPlant: non-finite value {when}: {quantity} is not finite", port=port)


def _port_vector(x: Any, n: int, name: str) -> np.ndarray:
    """Input ``name`` as the float64 vector of width ``n`` the core takes; else a BlockError naming it."""
    try:
        return float_array(x, name, width=n, finite=False, what="input")
    except ValueError as exc:
        raise BlockError(f"HandPlant {exc}", port=name) from None
