"""Internal forces, the projection onto them, and the friction-cone scaling."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st

from hierhand.control import (
    friction_scale,
    grasp_matrix,
    internal_directions,
    project_internal,
    required_scale_from_sensors,
)

from . import oracles

coord = st.floats(-0.1, 0.1, allow_nan=False)
point = st.tuples(coord, coord)
angle = st.floats(-math.pi, math.pi, allow_nan=False)


def net_wrench(points: np.ndarray, forces: np.ndarray, center: np.ndarray) -> np.ndarray:
    """Total force and z moment about ``center``, written out without the grasp matrix."""
    r = points - center
    moment = np.sum(r[:, 0] * forces[:, 1] - r[:, 1] * forces[:, 0])
    return np.array([forces[:, 0].sum(), forces[:, 1].sum(), moment])


def triangle_quality(p: np.ndarray) -> float:
    """Twice the area over the squared longest side: 0 for collinear, ~0.87 equilateral."""
    a, b = p[1] - p[0], p[2] - p[0]
    area2 = abs(a[0] * b[1] - a[1] * b[0])
    longest = max(np.sum((p[i] - p[j]) ** 2) for i, j in ((0, 1), (1, 2), (0, 2)))
    return area2 / longest if longest > 0 else 0.0


def unit(theta: float) -> np.ndarray:
    return np.array([math.cos(theta), math.sin(theta)])


def rot90(v: np.ndarray) -> np.ndarray:
    return np.array([-v[1], v[0]])


# -- grasp matrix -------------------------------------------------------------------


@given(st.lists(point, min_size=1, max_size=4), point, st.data())
def test_grasp_matrix_maps_forces_to_the_object_wrench(pts, center, data):
    p = np.array(pts)
    f = np.array(data.draw(st.lists(st.tuples(coord, coord), min_size=len(pts), max_size=len(pts)))) * 50
    g = grasp_matrix(p, np.array(center))
    assert g.shape == (3, 2 * len(pts))
    np.testing.assert_allclose(g @ f.ravel(), net_wrench(p, f, np.array(center)), atol=1e-14)


def test_grasp_matrix_columns():
    g = grasp_matrix([[1.0, 2.0]], [0.5, 0.5])
    np.testing.assert_array_equal(g, [[1, 0], [0, 1], [-1.5, 0.5]])


# -- internal directions ------------------------------------------------------------


@settings(max_examples=200)
@given(point, point, point)
def test_two_contacts_squeeze_along_the_line_between_them(p1, p2, center):
    p = np.array([p1, p2])
    assume(np.linalg.norm(p[1] - p[0]) > 1e-4)
    f = internal_directions(p)
    e = (p[1] - p[0]) / np.linalg.norm(p[1] - p[0])
    np.testing.assert_allclose(f, [e, -e], atol=1e-12)
    np.testing.assert_allclose(net_wrench(p, f, np.array(center)), 0.0, atol=1e-12)


@settings(max_examples=200)
@given(point, point, point, point)
def test_three_contacts_focus_form_cancels_and_points_at_the_centroid(p1, p2, p3, center):
    p = np.array([p1, p2, p3])
    assume(triangle_quality(p) > 1e-3)
    f = internal_directions(p)
    np.testing.assert_allclose(net_wrench(p, f, np.array(center)), 0.0, atol=1e-12)
    np.testing.assert_allclose(np.max(np.linalg.norm(f, axis=1)), 1.0, rtol=1e-12)
    to_c = p.mean(axis=0) - p
    cross = to_c[:, 0] * f[:, 1] - to_c[:, 1] * f[:, 0]
    np.testing.assert_allclose(cross, 0.0, atol=1e-12)
    assert np.all(np.einsum("ij,ij->i", to_c, f) > 0)


@settings(max_examples=200)
@given(point, point, point)
def test_null_space_focus_at_the_centroid_equals_the_closed_form(p1, p2, p3):
    p = np.array([p1, p2, p3])
    assume(triangle_quality(p) > 1e-3)
    np.testing.assert_allclose(internal_directions(p, focus=p.mean(axis=0)), internal_directions(p), atol=1e-9)


@settings(max_examples=200)
@given(point, point, point, st.floats(0.05, 1.0), st.floats(0.05, 1.0), st.floats(0.05, 1.0), point)
def test_any_interior_focus_gives_positive_squeezing_forces(p1, p2, p3, b1, b2, b3, center):
    p = np.array([p1, p2, p3])
    assume(triangle_quality(p) > 1e-2)
    bary = np.array([b1, b2, b3]) / (b1 + b2 + b3)
    focus = bary @ p
    f = internal_directions(p, focus=focus)
    np.testing.assert_allclose(net_wrench(p, f, np.array(center)), 0.0, atol=1e-9)
    np.testing.assert_allclose(np.max(np.linalg.norm(f, axis=1)), 1.0, rtol=1e-12)
    assert np.all(np.einsum("ij,ij->i", focus - p, f) > 0)


@settings(max_examples=100)
@given(point, angle, st.lists(st.floats(-0.05, 0.05), min_size=3, max_size=3), point)
def test_collinear_contacts_fall_back_to_a_valid_internal_set(origin, theta, offsets, center):
    assume(max(offsets) - min(offsets) > 1e-4)
    p = np.array(origin) + np.outer(offsets, unit(theta))
    f = internal_directions(p)
    np.testing.assert_allclose(net_wrench(p, f, np.array(center)), 0.0, atol=1e-12)
    np.testing.assert_allclose(np.max(np.linalg.norm(f, axis=1)), 1.0, rtol=1e-12)
    np.testing.assert_allclose(project_internal(p, np.array(center), f.ravel()), f.ravel(), atol=1e-9)


@pytest.mark.parametrize(
    "points, message",
    [
        (np.zeros((0, 2)), "at least two"),
        ([[0.0, 0.0]], "at least two"),
        ([[0.01, 0.02], [0.01, 0.02]], "coincide"),
        ([[0.01, 0.02]] * 3, "coincide"),
        ([[0.0, 0.0, 0.0]], "shape"),
        ([[0.0, np.nan], [1.0, 0.0]], "finite"),
    ],
)
def test_degenerate_contact_sets_are_rejected(points, message):
    with pytest.raises(ValueError, match=message):
        internal_directions(np.array(points))


def test_two_coincident_of_three_contacts_still_squeeze():
    p = np.array([[0.0, 0.0], [0.0, 0.0], [0.03, 0.0]])
    f = internal_directions(p)
    np.testing.assert_allclose(f, [[0.5, 0.0], [0.5, 0.0], [-1.0, 0.0]], atol=1e-15)


@pytest.mark.parametrize(
    "points, focus, message",
    [
        ([[0, 0], [1, 0], [0, 1]], [1.0, 1.0], "strictly inside"),
        ([[0, 0], [1, 0], [2, 0]], [1.0, 0.0], "coincides"),
        ([[0, 0], [1, 0], [3, 0]], [2.0, 0.0], "strictly inside"),
        ([[0, 0], [1, 0], [0, 1]], [0.0, 0.0], "coincides"),
        ([[0, 0], [1, 0]], [0.5, 0.0], "exactly three"),
    ],
)
def test_bad_focus_points_are_rejected(points, focus, message):
    with pytest.raises(ValueError, match=message):
        internal_directions(np.array(points, dtype=float), focus=np.array(focus))


# -- projection ---------------------------------------------------------------------


@settings(max_examples=200)
@given(st.integers(2, 3), st.data(), point)
def test_internal_set_is_invariant_under_the_projection(k, data, center):
    p = np.array(data.draw(st.lists(point, min_size=k, max_size=k)))
    assume(triangle_quality(p) > 1e-3 if k == 3 else np.linalg.norm(p[1] - p[0]) > 1e-3)
    f = internal_directions(p).ravel()
    np.testing.assert_allclose(project_internal(p, np.array(center), f), f, atol=1e-9)


@settings(max_examples=200)
@given(st.integers(2, 3), st.data(), point)
def test_projection_removes_the_wrench_and_is_idempotent(k, data, center):
    p = np.array(data.draw(st.lists(point, min_size=k, max_size=k)))
    assume(triangle_quality(p) > 1e-3 if k == 3 else np.linalg.norm(p[1] - p[0]) > 1e-3)
    f = np.array(data.draw(st.lists(st.floats(-5, 5), min_size=2 * k, max_size=2 * k)))
    pf = project_internal(p, np.array(center), f)
    np.testing.assert_allclose(net_wrench(p, pf.reshape(k, 2), np.array(center)), 0.0, atol=1e-9)
    np.testing.assert_allclose(project_internal(p, np.array(center), pf), pf, atol=1e-9)
    if k == 2:
        e = internal_directions(p).ravel()
        np.testing.assert_allclose(pf, (pf @ e) / (e @ e) * e, atol=1e-9)


@pytest.mark.parametrize("k", [1, 2, 3, 5])
def test_projection_and_squeeze_match_the_oracle(k):
    """The closed-form solve against numpy.linalg.pinv, and the centroid squeeze, on random
    grasps, collinear ones and points a nanometre apart included."""
    rng = np.random.default_rng(100 + k)
    for trial in range(500):
        p = rng.uniform(-0.1, 0.1, (k, 2))
        if trial % 5 == 1:  # collinear
            p = p[0] + np.outer(rng.uniform(-0.05, 0.05, k), unit(rng.uniform(-math.pi, math.pi)))
        elif trial % 5 == 2:  # within a nanometre of each other
            p = p[0] + rng.normal(0.0, 1e-9, (k, 2))
        f = rng.normal(0.0, 5.0, 2 * k)
        # both are round-off of the forces times the conditioning, size over spread of the points
        spread = float(np.max(np.abs(p - p.mean(axis=0)))) if k > 1 else math.inf  # one contact: no moment arm
        atol = 1e-13 * np.max(np.abs(f)) * max(1.0, float(np.max(np.abs(p))) / spread)
        np.testing.assert_allclose(project_internal(p, rng.uniform(-0.1, 0.1, 2), f), oracles.project_internal(p, f),
                                   rtol=0, atol=atol)
        if k >= 2 and trial % 5 != 2:
            np.testing.assert_allclose(internal_directions(p), oracles.internal_directions(p), rtol=0, atol=1e-14)
    assert project_internal(np.zeros((0, 2)), [0.0, 0.0], np.zeros(0)).shape == (0,)


def test_projection_rejects_a_wrong_force_length():
    with pytest.raises(ValueError, match=r"shape \(4,\)"):
        project_internal([[0, 0], [1, 0]], [0, 0], np.zeros(6))


# -- friction scaling ---------------------------------------------------------------


def cone_ratios(s: float, g: np.ndarray, l: np.ndarray, n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Tangential and normal components of ``s g + l`` per contact (n unit)."""
    f = s * g + l
    t = np.column_stack([-n[:, 1], n[:, 0]])
    return np.einsum("ij,ij->i", t, f), np.einsum("ij,ij->i", n, f)


def test_pinching_the_default_object_needs_mg_over_2_over_ratio():
    m, grav = 0.3, 9.81
    n = np.array([[1.0, 0.0], [-1.0, 0.0]])
    l = np.array([[0.0, m * grav / 2], [0.0, m * grav / 2]])
    s = friction_scale(n, l, n, ratio=0.6)
    assert s == pytest.approx(m * grav / 2 / 0.6, rel=1e-14)
    assert s == pytest.approx(2.4525, rel=1e-12)


@st.composite
def feasible_grasps(draw):
    """Contacts whose internal force is strictly inside the cone, so large s works."""
    k = draw(st.integers(1, 3))
    ratio = draw(st.floats(0.2, 1.0))
    n, g, l = [], [], []
    for _ in range(k):
        ni = unit(draw(angle))
        w = draw(st.floats(0.2, 2.0))
        beta = draw(st.floats(-0.9, 0.9)) * ratio * w
        n.append(ni)
        g.append(w * ni + beta * rot90(ni))
        l.append(np.array([draw(st.floats(-5, 5)), draw(st.floats(-5, 5))]))
    return np.array(g), np.array(l), np.array(n), ratio


@settings(max_examples=300)
@given(feasible_grasps())
@example((np.array([[1.0, 0.0]]), np.array([[3.0, 3.0]]), np.array([[1.0, 0.0]]), 0.9999999999999999))
def test_friction_scale_puts_the_binding_contact_exactly_at_the_ratio(grasp):
    g, l, n, ratio = grasp
    s = friction_scale(g, l, n, ratio)
    assert math.isfinite(s) and s >= 0
    ft, fn = cone_ratios(s, g, l, n)
    assert np.all(np.abs(ft) <= ratio * fn + 1e-12)
    if s > 0:
        binding = int(np.argmax(np.abs(ft) - ratio * fn))
        assume(fn[binding] > 1e-2)
        assert abs(ft[binding]) / fn[binding] == pytest.approx(ratio, abs=1e-12)
        # minimal: a smaller scale breaks the cone, unless s is round-off of the loads
        # (a contact already at the ratio without squeeze), where 1e-6 of s changes nothing
        assume(s > 1e-9 * max(1.0, float(np.abs(l).max())))
        ft_less, fn_less = cone_ratios(s * (1 - 1e-6), g, l, n)
        assert np.any(np.abs(ft_less) > ratio * fn_less)
    else:
        ft0, fn0 = cone_ratios(0.0, g, l, n)
        assert np.all(np.abs(ft0) <= ratio * fn0)


@settings(max_examples=100)
@given(st.lists(st.tuples(angle, st.floats(0.0, 5.0), st.floats(-0.99, 0.99)), min_size=1, max_size=3), st.data())
def test_friction_scale_is_zero_when_the_load_is_already_inside_the_cone(contacts, data):
    n = np.array([unit(th) for th, _, _ in contacts])
    l = np.array([a * unit(th) + b * 0.6 * a * rot90(unit(th)) for th, a, b in contacts])
    g = np.array(data.draw(st.lists(st.tuples(coord, coord), min_size=len(contacts), max_size=len(contacts))))
    assert friction_scale(g, l, n, 0.6) == 0.0


def test_friction_scale_is_inf_when_contacts_ask_for_incompatible_scales():
    n = np.array([[0.0, 1.0], [1.0, 0.0]])
    t = np.array([[-1.0, 0.0], [0.0, 1.0]])
    g = np.array([t[0], n[1]])  # contact 0: squeezing only adds slip, so s <= 0.6
    l = np.array([n[0], 5 * t[1] + n[1]])  # contact 1 needs s >= 5/0.6 - 1
    assert friction_scale(g, l, n, 0.6) == math.inf
    assert friction_scale(g[1:], l[1:], n[1:], 0.6) == pytest.approx(5 / 0.6 - 1, rel=1e-14)
    assert friction_scale(g[:1], l[:1], n[:1], 0.6) == 0.0


def test_friction_scale_is_inf_when_the_internal_force_cannot_help():
    n = np.array([[1.0, 0.0]])
    pulling = np.array([[-1.0, 0.0]])
    on_cone_edge = np.array([[1.0, 0.6]])
    slipping = np.array([[1.0, 1.0]])
    assert friction_scale(pulling, slipping, n, 0.6) == math.inf
    assert friction_scale(on_cone_edge, slipping, n, 0.6) == math.inf
    assert friction_scale(on_cone_edge, np.array([[1.0, 0.5]]), n, 0.6) == 0.0


def test_friction_scale_normalises_the_normals():
    g = np.array([[1.0, 0.2], [-1.0, 0.1]])
    l = np.array([[0.1, 1.0], [0.3, 2.0]])
    n = np.array([[1.0, 0.0], [-1.0, 0.0]])
    assert friction_scale(g, l, 7 * n) == pytest.approx(friction_scale(g, l, n), rel=1e-14)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"ratio": 0.0}, "ratio"),
        ({"ratio": -0.6}, "ratio"),
        ({"ratio": math.inf}, "ratio"),
        ({"normals": np.array([[0.0, 0.0]])}, "non-zero"),
        ({"l": np.zeros((2, 2))}, "same shape"),
    ],
)
def test_friction_scale_rejects_bad_arguments(kwargs, message):
    args = {"g": np.array([[1.0, 0.0]]), "l": np.array([[0.0, 1.0]]), "normals": np.array([[1.0, 0.0]])}
    args.update(kwargs)
    with pytest.raises(ValueError, match=message):
        friction_scale(**args)


# -- sensor form --------------------------------------------------------------------


@settings(max_examples=300)
@given(
    st.lists(st.tuples(angle, st.floats(0.1, 3.0), st.floats(-5, 5), st.floats(-5, 5)), min_size=1, max_size=3),
    st.floats(0.0, 10.0),
    st.floats(0.2, 1.0),
)
def test_sensor_form_agrees_with_friction_scale_for_normal_internal_forces(contacts, s0, ratio):
    n = np.array([unit(th) for th, _, _, _ in contacts])
    w = np.array([c[1] for c in contacts])
    l = np.array([[c[2], c[3]] for c in contacts])
    g = w[:, None] * n
    ft, fn = cone_ratios(s0, g, l, n)
    expected = friction_scale(g, l, n, ratio)
    got = required_scale_from_sensors(fn, ft, w, s0, ratio)
    assert got == pytest.approx(expected, rel=1e-12, abs=1e-12)


def test_sensor_form_makes_the_binding_contact_hit_the_ratio():
    fn = np.array([2.0, 3.0])
    ft = np.array([1.5, -1.2])
    w = np.array([1.0, 1.0])
    s = required_scale_from_sensors(fn, ft, w, current_scale=1.0, ratio=0.6)
    assert s == pytest.approx(1.5 / 0.6 - 1.0, rel=1e-14)
    fn_new = fn + (s - 1.0) * w
    assert np.max(np.abs(ft) / fn_new) == pytest.approx(0.6, rel=1e-14)


def test_sensor_form_handles_free_contacts_and_clips_at_zero():
    assert required_scale_from_sensors([5.0, 5.0], [0.1, 0.1], [1.0, 1.0], 0.5) == 0.0
    assert required_scale_from_sensors([1.0, 2.0], [0.1, 1.8], [0.0, 1.0], 1.0) == pytest.approx(2.0, rel=1e-14)
    assert required_scale_from_sensors([1.0, 2.0], [0.9, 0.1], [0.0, 1.0], 1.0) == math.inf
    assert required_scale_from_sensors([], [], [], 1.0) == 0.0


@pytest.mark.parametrize(
    "args, message",
    [
        (([1.0], [0.1], [-1.0], 1.0), "weights"),
        (([1.0], [0.1, 0.2], [1.0], 1.0), "same length"),
        (([1.0], [0.1], [1.0], 1.0, 0.0), "ratio"),
    ],
)
def test_sensor_form_rejects_bad_arguments(args, message):
    with pytest.raises(ValueError, match=message):
        required_scale_from_sensors(*args)
