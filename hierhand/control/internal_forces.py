"""Internal ("grasping") forces of a planar multi-finger grasp (Yoshikawa and Nagai).

``f_i`` is the force fingertip ``i`` applies to the object at contact point ``p_i``.
The grasp matrix ``G`` maps the stacked contact forces to the object wrench
``w = G f`` (force x, force y, moment z about ``center``). Internal forces are those
with ``G f = 0``: they squeeze the object without moving it, and the grasping reflex
scales them until every contact is inside its friction cone with a safety margin.

Conventions: points are ``(k, 2)`` arrays, stacked force vectors are ``(2k,)`` in the
order ``f1x, f1y, f2x, f2y, ...``.

``project_internal`` and ``internal_directions`` (the centroid squeeze) are the reflex's
own law: they call its C (``hierhand/csrc/reflex.c``). The rest is Python because no
block runs it: ``grasp_matrix`` states the convention, ``internal_directions`` with an
explicit ``focus`` is the focus-point form the reflex does not use, and
``friction_scale`` / ``required_scale_from_sensors`` are the static friction-cone
analysis whose fixed point the reflex's integral loop seeks.
"""

from __future__ import annotations

import math

import numpy as np

from blocks.arrays import flat_float64

from .. import _native

__all__ = [
    "grasp_matrix",
    "internal_directions",
    "project_internal",
    "friction_scale",
    "required_scale_from_sensors",
]

# Two points closer than this (relative to the size of their coordinates) are treated
# as coincident: their difference is then round-off, not a direction.
_COINCIDENT_RTOL = 1e-12


def _points(points: np.ndarray, name: str = "points") -> np.ndarray:
    p = np.asarray(points, dtype=float)
    if p.ndim != 2 or p.shape[1] != 2:
        raise ValueError(f"{name} must have shape (k, 2), got {p.shape}")
    if not np.all(np.isfinite(p)):
        raise ValueError(f"{name} must be finite")
    return p


def _center(center: np.ndarray) -> np.ndarray:
    """The moment point as a (2,) array (``ValueError`` for another shape)."""
    return np.asarray(center, dtype=float).reshape(2)


def grasp_matrix(points: np.ndarray, center: np.ndarray) -> np.ndarray:
    """(3, 2k) grasp matrix: contact ``i`` contributes columns ``[I2; (-r_iy, r_ix)]``.

    ``r_i = p_i - center``; the third row is the z moment ``r_i x f_i`` about ``center``.
    """
    p = _points(points)
    r = p - _center(center)
    k = p.shape[0]
    g = np.zeros((3, 2 * k))
    g[0, 0::2] = 1.0
    g[1, 1::2] = 1.0
    g[2, 0::2] = -r[:, 1]
    g[2, 1::2] = r[:, 0]
    return g


def internal_directions(points: np.ndarray, focus: np.ndarray | None = None) -> np.ndarray:
    """(k, 2) unit-scale internal ("squeeze") forces, largest magnitude 1.

    Every contact pushes toward a common focus point, so all lines of action meet there
    (zero moment) and the magnitudes are chosen so the forces cancel (zero force):

    - ``k = 2``: ``f1 = e``, ``f2 = -e`` with ``e = (p2 - p1) / |p2 - p1|``.
    - ``k = 3``: the "focus" form. The unit directions ``u_i = (c - p_i)/|c - p_i|``
      toward the focus ``c`` form a 2x3 matrix whose null space gives the magnitudes
      ``a_i`` (``a_1 = u_2 x u_3``, ``a_2 = u_3 x u_1``, ``a_3 = u_1 x u_2``); they all have
      the same sign when ``c`` is strictly inside the contact triangle.

    With the default focus, the centroid, the null-space magnitudes reduce to
    ``a_i ~ |c - p_i|``, i.e. ``f_i ~ c - p_i`` (because ``sum_i (c - p_i) = 0``), and
    that closed form is what is evaluated, by the grasping reflex's C (it is the reflex's
    fallback squeeze). It covers every ``k >= 2`` (for ``k = 2`` it
    is exactly ``+-e``) and it stays a valid internal set when three contacts are
    collinear, where the null space is two-dimensional and the focus construction has no
    unique answer: it is the limit of the focus form as the triangle flattens (the middle
    contact then pushes gently toward the centroid). Degenerate cases raise
    ``ValueError``: fewer than two contacts, or all contacts at one point (no direction
    exists).

    An explicit ``focus`` is supported for ``k = 3`` only and must lie strictly inside the
    contact triangle (``ValueError`` otherwise, including for collinear contacts).
    """
    p = _points(points)
    k = p.shape[0]
    if k < 2:
        raise ValueError(f"internal forces need at least two contacts, got {k}")
    if focus is None:
        g = np.empty((k, 2))
        _native.centroid_squeeze(flat_float64(p), _COINCIDENT_RTOL, g)
        return g
    if k != 3:
        raise ValueError(f"an explicit focus point needs exactly three contacts, got {k}")
    return _focus_form(p, np.asarray(focus, dtype=float).reshape(2))


def _focus_form(p: np.ndarray, c: np.ndarray) -> np.ndarray:
    d = c - p
    dist = np.hypot(d[:, 0], d[:, 1])
    scale = max(float(np.max(np.abs(p))), float(np.max(np.abs(c))), np.finfo(float).tiny)
    if np.any(dist <= _COINCIDENT_RTOL * scale):
        raise ValueError("the focus point coincides with a contact point")
    u = d / dist[:, None]
    a = np.array(
        [
            u[1, 0] * u[2, 1] - u[1, 1] * u[2, 0],
            u[2, 0] * u[0, 1] - u[2, 1] * u[0, 0],
            u[0, 0] * u[1, 1] - u[0, 1] * u[1, 0],
        ]
    )
    if a.sum() < 0:
        a = -a
    # The null vector vanishes (to round-off) when the directions are collinear, and has
    # mixed signs when the focus is outside the triangle: no squeezing set exists then.
    if not np.all(a > 1e-9 * np.max(np.abs(a))) or np.max(np.abs(a)) < 1e-12:
        raise ValueError(
            "the focus point must lie strictly inside the triangle of three non-collinear contacts"
        )
    return u * (a / a.max())[:, None]


def project_internal(points: np.ndarray, center: np.ndarray, f: np.ndarray) -> np.ndarray:
    """(2k,) internal part ``(I - G^+ G) f`` of the stacked contact forces ``f``.

    This is the general projection onto the null space of the grasp matrix; it removes
    the part of ``f`` that would accelerate the object. ``G G^T`` is solved in closed form
    about the points' centroid (the reflex's solve, ``hierhand/csrc/reflex.c``); when all
    points coincide the moment equation is dropped, as ``numpy.linalg.pinv`` drops it.
    The result does not depend on ``center`` (checked for shape only).
    """
    p = _points(points)
    _center(center)  # its shape only: the projection does not depend on it
    f = np.asarray(f, dtype=float).reshape(-1)
    if f.shape[0] != 2 * p.shape[0]:
        raise ValueError(f"f must have shape ({2 * p.shape[0]},), got {f.shape}")
    out = np.empty(f.shape[0])
    if out.size:
        _native.project_internal(flat_float64(p), flat_float64(f), out)
    return out


def friction_scale(
    g: np.ndarray, l: np.ndarray, normals: np.ndarray, ratio: float = 0.6
) -> float:
    """Smallest ``s >= 0`` keeping every contact force ``s g_i + l_i`` inside the cone
    ``|t_i . F_i| <= ratio * n_i . F_i``.

    ``g`` (k, 2) is the internal force per contact, ``l`` (k, 2) the load share (the part
    of the contact force that carries the object), ``normals`` (k, 2) the inward contact
    normals, i.e. the direction of the normal force the finger applies (normalised
    here); ``t_i`` is ``n_i`` turned +90 degrees.

    Each contact gives two linear inequalities ``c s <= d`` in ``s``; their intersection
    is an interval, solved exactly. Returns ``0.0`` when ``s = 0`` already satisfies all of
    them and ``math.inf`` when no ``s >= 0`` does (e.g. a load whose tangential part the
    internal force cannot make up for, or two contacts asking for incompatible scales).
    Satisfying the cone implies ``n_i . F_i >= 0``: no contact pulls.
    """
    if not ratio > 0 or not math.isfinite(ratio):
        raise ValueError(f"ratio must be a positive finite number, got {ratio!r}")
    g = _points(g, "g")
    l = _points(l, "l")
    n = _points(normals, "normals")
    if not g.shape == l.shape == n.shape:
        raise ValueError(f"g, l and normals must have the same shape, got {g.shape}, {l.shape}, {n.shape}")
    norm = np.hypot(n[:, 0], n[:, 1])
    if np.any(norm == 0):
        raise ValueError("every contact normal must be non-zero")
    n = n / norm[:, None]
    t = np.column_stack([-n[:, 1], n[:, 0]])
    a_t = np.einsum("ij,ij->i", t, g)
    a_n = np.einsum("ij,ij->i", n, g)
    b_t = np.einsum("ij,ij->i", t, l)
    b_n = np.einsum("ij,ij->i", n, l)
    c = np.concatenate([a_t - ratio * a_n, -a_t - ratio * a_n])
    d = np.concatenate([ratio * b_n - b_t, ratio * b_n + b_t])
    lo, hi = 0.0, math.inf
    with np.errstate(over="ignore"):  # a bound beyond float range is no bound: +-inf is right
        for ci, di in zip(c, d):
            if ci > 0:
                hi = min(hi, di / ci)
            elif ci < 0:
                lo = max(lo, di / ci)
            elif di < 0:
                return math.inf
    return float(lo) if lo <= hi else math.inf


def required_scale_from_sensors(
    fn: np.ndarray,
    ft: np.ndarray,
    weights: np.ndarray,
    current_scale: float,
    ratio: float = 0.6,
) -> float:
    """Internal-force scale that brings the binding contact's ``|ft|/fn`` to ``ratio``,
    from measured fingertip forces (the grasping reflex's form).

    Assumption: contact ``i``'s internal force acts along its normal with magnitude
    ``scale * weights[i]``, so the measured normal force splits into
    ``fn_i = current_scale * w_i + (load part)`` while the tangential force ``ft_i`` is
    all load and does not change with the scale. Then the contact is at the safety
    ratio for ``s_i = (|ft_i| / ratio - (fn_i - current_scale * w_i)) / w_i`` and the
    answer is ``max_i s_i``, clipped at 0 because fingers can only push. This is exactly
    ``friction_scale`` when the internal direction is the contact normal.

    A contact with weight 0 cannot be helped by scaling: it is ignored while within the
    ratio and makes the answer ``math.inf`` otherwise. Negative weights (an internal force
    pulling along the normal) raise ``ValueError``. No contacts gives 0.
    """
    if not ratio > 0 or not math.isfinite(ratio):
        raise ValueError(f"ratio must be a positive finite number, got {ratio!r}")
    fn = np.asarray(fn, dtype=float).reshape(-1)
    ft = np.asarray(ft, dtype=float).reshape(-1)
    w = np.asarray(weights, dtype=float).reshape(-1)
    if not fn.shape == ft.shape == w.shape:
        raise ValueError(f"fn, ft and weights must have the same length, got {fn.shape}, {ft.shape}, {w.shape}")
    if np.any(w < 0):
        raise ValueError("weights must be >= 0 (internal forces push along the normal)")
    need = np.abs(ft) / ratio - (fn - current_scale * w)
    free = w == 0
    if np.any(need[free] > 0):
        return math.inf
    if np.all(free):
        return 0.0
    return max(0.0, float(np.max(need[~free] / w[~free])))
