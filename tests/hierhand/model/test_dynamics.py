"""Finger dynamics against independent formulas: M, bias, Jacobians, energy."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hierhand.model import Hand, load_hand
from hierhand.model.handfile import default_hand_dict

from .sim import make_plant

angles = st.lists(st.floats(-3.0, 3.0), min_size=9, max_size=9).map(np.array)
rates = st.lists(st.floats(-20.0, 20.0), min_size=9, max_size=9).map(np.array)


def hand_with_offsets():
    """The default hand with COMs off the link axes and a slanted gravity."""
    data = default_hand_dict()
    data["gravity"] = [2.0, -9.0]
    for f, finger in enumerate(data["fingers"]):
        for i, link in enumerate(finger["links"]):
            link["com"] = [link["com"] * (0.8 + 0.1 * i), 0.002 * (f - 1) + 0.001 * i]
    return load_hand(data)


def com_positions_and_jacobians(hand, q):
    """Closed form: COM of link i and its Jacobian, column j = z x (p_c - joint_j)."""
    out = []
    for f, finger in enumerate(hand.params.fingers):
        joint = np.array(finger.base, dtype=float)
        joints, theta = [], finger.base_angle
        for i, link in enumerate(finger.links):
            theta += q[3 * f + i]
            u = np.array([np.cos(theta), np.sin(theta)])
            w = np.array([-u[1], u[0]])
            joints.append(joint.copy())
            pc = joint + link.com_along * u + link.com_across * w
            jac = np.zeros((2, 9))
            for j in range(i + 1):
                d = pc - joints[j]
                jac[:, 3 * f + j] = [-d[1], d[0]]
            jw = np.zeros(9)
            jw[3 * f : 3 * f + i + 1] = 1.0
            out.append((link.mass, link.inertia, pc, jac, jw))
            joint = joint + link.length * u
    return out


def mass_matrix_reference(hand, q):
    m = np.diag([a for f in hand.params.fingers for a in f.armature]).astype(float)
    for mass, inertia, _, jac, jw in com_positions_and_jacobians(hand, q):
        m += mass * jac.T @ jac + inertia * np.outer(jw, jw)
    return m


def potential(hand, q):
    g = np.array(hand.params.gravity)
    return -sum(mass * g @ pc for mass, _, pc, _, _ in com_positions_and_jacobians(hand, q))


@settings(max_examples=50)
@given(q=angles)
def test_mass_matrix_is_symmetric_positive_definite(q):
    m = Hand.default().mass_matrix(q)
    assert np.allclose(m, m.T, rtol=0, atol=1e-14 * np.abs(m).max())
    assert np.linalg.eigvalsh(0.5 * (m + m.T)).min() > 0.9e-4  # at least the armature


@settings(max_examples=50)
@given(q=angles)
def test_mass_matrix_equals_sum_of_link_kinetic_energies(q):
    hand = hand_with_offsets()
    ref = mass_matrix_reference(hand, q)
    assert np.allclose(hand.mass_matrix(q), ref, rtol=0, atol=1e-12 * np.abs(ref).max())


@settings(max_examples=30)
@given(q=angles, qd=rates)
def test_bias_is_coriolis_plus_gravity_plus_damping(q, qd):
    """h = Mdot qd - 1/2 d(qd' M qd)/dq + dV/dq + D qd, derivatives by central differences."""
    hand = hand_with_offsets()
    eps = 1e-6
    mdot = np.zeros((9, 9))
    dkin = np.zeros(9)
    dpot = np.zeros(9)
    for k in range(9):
        e = np.zeros(9)
        e[k] = eps
        mp, mm = mass_matrix_reference(hand, q + e), mass_matrix_reference(hand, q - e)
        mdot += (mp - mm) / (2 * eps) * qd[k]
        dkin[k] = 0.5 * qd @ ((mp - mm) / (2 * eps)) @ qd
        dpot[k] = (potential(hand, q + e) - potential(hand, q - e)) / (2 * eps)
    damping = np.array([d for f in hand.params.fingers for d in f.damping])
    ref = mdot @ qd - dkin + dpot + damping * qd
    assert np.allclose(hand.bias(q, qd), ref, rtol=1e-6, atol=1e-6 * np.abs(ref).max())


def two_link_hand():
    """Fingers whose third link is nearly massless, for the classic two-link formulas."""
    data = default_hand_dict()
    data["gravity"] = [1.5, -9.81]
    for finger in data["fingers"]:
        finger["armature"] = [0.0, 0.0, 0.0]
        finger["links"][2].update(mass=1e-15, inertia=1e-20)
    return load_hand(data)


def two_link_closed_form(finger, gravity, q1, q2, qd1, qd2):
    """Spong's two-link arm, with the base turned by base_angle and gravity any vector."""
    l1 = finger.links[0].length
    m1, m2 = finger.links[0].mass, finger.links[1].mass
    c1, c2 = finger.links[0].com_along, finger.links[1].com_along
    i1, i2 = finger.links[0].inertia, finger.links[1].inertia
    m11 = i1 + i2 + m1 * c1**2 + m2 * (l1**2 + c2**2 + 2 * l1 * c2 * np.cos(q2))
    m12 = i2 + m2 * (c2**2 + l1 * c2 * np.cos(q2))
    m22 = i2 + m2 * c2**2
    hc = m2 * l1 * c2 * np.sin(q2)
    cor = np.array([-hc * (2 * qd1 * qd2 + qd2**2), hc * qd1**2])
    t1 = finger.base_angle + q1
    t2 = t1 + q2
    gx, gy = gravity
    # dV/dq with V = -m g . p: the derivative of a point at angle t and radius c is c(-sin t, cos t)
    dp = lambda c, t: c * (-gx * np.sin(t) + gy * np.cos(t))  # noqa: E731
    grav = np.array([-(m1 * dp(c1, t1) + m2 * dp(l1, t1) + m2 * dp(c2, t2)), -m2 * dp(c2, t2)])
    damp = np.array(finger.damping[:2]) * [qd1, qd2]
    return np.array([[m11, m12], [m12, m22]]), cor + grav + damp


@settings(max_examples=50)
@given(q=angles, qd=rates)
def test_two_link_finger_matches_closed_form(q, qd):
    hand = two_link_hand()
    m = hand.mass_matrix(q)
    h = hand.bias(q, qd)
    for f, finger in enumerate(hand.params.fingers):
        ref_m, ref_h = two_link_closed_form(finger, hand.params.gravity, q[3 * f], q[3 * f + 1], qd[3 * f], qd[3 * f + 1])
        block = m[3 * f : 3 * f + 2, 3 * f : 3 * f + 2]
        assert np.allclose(block, ref_m, rtol=0, atol=1e-10 * np.abs(ref_m).max())
        assert np.allclose(h[3 * f : 3 * f + 2], ref_h, rtol=0, atol=1e-10 * np.abs(ref_h).max())


@settings(max_examples=30)
@given(q=angles)
def test_tip_jacobians_are_derivatives_of_tip_positions(q):
    hand = Hand.default()
    jac = hand.tip_jacobians(q)
    eps = 1e-7
    for k in range(9):
        e = np.zeros(9)
        e[k] = eps
        d = (hand.tip_positions(q + e) - hand.tip_positions(q - e)) / (2 * eps)
        f, j = divmod(k, 3)
        assert np.allclose(jac[f, :, j], d[f], atol=1e-8)
        for other in set(range(3)) - {f}:
            assert np.allclose(d[other], 0.0)


def test_tip_positions_follow_the_angle_convention():
    hand = Hand.default()
    q = np.zeros(9)
    q[3:6] = [0.3, 0.2, 0.1]
    fore = hand.params.fingers[1]
    angle = fore.base_angle
    expected = np.array(fore.base, dtype=float)
    for link, qi in zip(fore.links, q[3:6]):
        angle += qi
        expected += link.length * np.array([np.cos(angle), np.sin(angle)])
    assert np.allclose(hand.tip_positions(q)[1], expected, atol=1e-15)
    assert hand.tip_poses(q)[1, 2] == pytest.approx(fore.base_angle + 0.6)


def test_free_fingers_keep_their_energy_for_one_second():
    """No damping, gravity or contact: the semi-implicit step conserves energy to 1 %."""
    data = default_hand_dict()
    for finger in data["fingers"]:
        finger["damping"] = [0.0, 0.0, 0.0]
    plant = make_plant(gravity=[0.0, 0.0], fingers=data["fingers"], object={"pos": [1.0, 1.0]})
    hand = plant.hand
    state = plant.initial_state()
    views = plant.views(state)
    views.qd[:] = [4.0, -6.0, 8.0, -5.0, 7.0, 9.0, 3.0, 5.0, -7.0]

    def energy():
        return 0.5 * views.qd @ hand.mass_matrix(views.q) @ views.qd

    e0 = energy()
    zero = {"tau": np.zeros(9)}
    energies = []
    for k in range(100):
        state, rows = plant.advance(k * 0.01, state, zero, 100)
        assert not rows["contact"].any()
        energies.append(energy())
    assert views.qd @ views.qd > 1.0  # still moving
    assert np.max(np.abs(np.array(energies) / e0 - 1.0)) < 0.01
