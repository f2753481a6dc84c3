"""The reflex's compiled law against its numpy oracle (``oracles.reflex_*``).

The oracle projects with ``numpy.linalg.pinv``, falls back to the centroid squeeze and
maps forces through ``Hand.point_jacobian`` at the contact points; ``GraspReflex`` must
agree with it to round-off on random 2- and 3-contact grasps, approaching fingers, fingers
held in part and the fallback included.
"""

from __future__ import annotations

import numpy as np
import pytest

from hierhand.control.grasp_reflex import GraspReflex
from hierhand.control.reflex_law import pack_params, reflex_directions, reflex_output, reflex_update
from hierhand.layouts import REFLEX_GIVEN as G, REFLEX_PARAMS as P
from hierhand.model import Hand

from . import oracles


def make_reflex(grasp):
    reflex = GraspReflex(hand=Hand.default(), grasp=grasp, ki=50.0, min_force=3.0, approach_force=0.5)
    reflex.bind(0.001)
    return reflex


def random_case(rng, reflex, k, inward: bool):
    """A state and inputs with ``k`` fingers in the grasp (touching or approaching)."""
    hand = reflex.hand
    q = hand.q0 + rng.normal(scale=0.2, size=9)
    tip = hand.tip_poses(q)
    tip[:, :2] = rng.uniform(-0.05, 0.05, size=(3, 2)) + [0.0, 0.06]
    chosen = rng.permutation(3)[:k]
    fn = np.zeros(3)
    # [scale, handed over (3), hold (3): whole, or in part for some fingers]
    state = np.concatenate(([rng.uniform(0.0, 10.0)], np.zeros(3), np.where(rng.random(3) < 0.5, 1.0,
                                                                            rng.uniform(0.0, 1.0, 3))))
    initial = reflex.initial
    for i in chosen:
        if initial[i] and rng.random() < 0.3:
            continue  # still approaching: listed in 'grasp', not handed over, not touching
        fn[i] = rng.uniform(0.1, 8.0)
        state[1 + i] = rng.choice([0.0, 1.0])  # held when it last touched, or handed over
    for i in set(range(3)) - set(chosen):
        state[1 + i] = 1.0 if initial[i] else rng.choice([0.0, 1.0])  # out of the grasp
    centre = tip[chosen, :2].mean(axis=0)
    normal = np.zeros((3, 2))
    for i in range(3):
        if inward:  # roughly toward the centroid, as contact normals of a held object are
            d = centre - tip[i, :2] + rng.normal(scale=0.01, size=2)
        else:
            d = rng.normal(size=2)
        normal[i] = d / np.linalg.norm(d)
    inputs = {"q": q, "tip": tip.ravel(), "fn": fn, "ft": rng.normal(scale=2.0, size=3),
              "normal": normal.ravel(), "share": rng.uniform(0.4, 1.2, size=3)}
    return state, inputs


@pytest.mark.parametrize("k", [2, 3])
def test_compiled_directions_forces_and_ports_match_the_oracle(k):
    rng = np.random.default_rng(1234 + k)
    seen = {"fallback": 0, "projection": 0, "approaching": 0}
    for trial in range(600):
        reflex = make_reflex(["thumb", "fore", "middle"] if trial % 2 else ["thumb", "fore"])
        state, inputs = random_case(rng, reflex, k, inward=trial % 3 != 0)
        g_ref, grasp_ref, touching_ref, fallback = oracles.reflex_directions(
            reflex, state, inputs["tip"], inputs["normal"], inputs["fn"])
        g, grasp, touching = reflex.directions(state, inputs["tip"], inputs["normal"], inputs["fn"])
        assert grasp.tolist() == grasp_ref.tolist() and touching.tolist() == touching_ref.tolist()
        np.testing.assert_allclose(g, g_ref, rtol=0, atol=1e-11)
        if grasp.sum() >= 2:
            seen["fallback" if fallback else "projection"] += 1
            seen["approaching"] += int(np.any(grasp & ~touching))

        f_ref, _ = oracles.reflex_forces(reflex, state, inputs)
        f, grasp_f = reflex.forces(state, inputs)
        assert grasp_f.tolist() == grasp_ref.tolist()
        np.testing.assert_allclose(f, f_ref, rtol=1e-11, atol=1e-11 * max(1.0, state[0]))

        out, out_ref = reflex.output(0.0, state, inputs), oracles.reflex_output(reflex, state, inputs)
        assert set(out) == set(out_ref)
        for port, value in out_ref.items():
            assert out[port].shape == value.shape and out[port].dtype == np.float64
            np.testing.assert_allclose(out[port], value, rtol=1e-10, atol=1e-12 * max(1.0, state[0]))

        new = reflex.update(0.0, state.copy(), inputs)
        np.testing.assert_allclose(new, oracles.reflex_update(reflex, state, inputs), rtol=1e-10, atol=1e-12)
    assert min(seen.values()) > 10, seen  # every branch exercised


def test_the_squeeze_is_internal_at_the_contact_points():
    """(I - G^+ G) n at the contact points (tip centre plus radius along the normal), and its
    blend toward a two-finger squeeze for a finger held in part: zero net force and zero
    moment about any point, so the squeeze neither pushes nor turns the object."""
    rng = np.random.default_rng(7)
    reflex = make_reflex(["thumb", "fore", "middle"])
    radius = reflex.hand.tip_radius
    partly = 0
    for _ in range(200):
        state, inputs = random_case(rng, reflex, 3, inward=True)
        inputs["fn"][:] = 2.0
        partly += int(np.any(state[4:7] < 1.0))
        g, grasp, _ = reflex.directions(state, inputs["tip"], inputs["normal"], inputs["fn"])
        p = inputs["tip"].reshape(3, 3)[:, :2] + radius[:, None] * inputs["normal"].reshape(3, 2)
        np.testing.assert_allclose(g.sum(axis=0), 0.0, atol=1e-12)
        r = p - p.mean(axis=0)
        assert abs(np.sum(r[:, 0] * g[:, 1] - r[:, 1] * g[:, 0])) < 1e-13
    assert partly > 50


def coincident_tips(reflex, normal=(1.0, 0.0), point=(0.02, 0.06)) -> np.ndarray:
    """Tip poses whose contact points (tip centre plus radius along ``normal``) coincide at ``point``."""
    tips = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 3.0], [0.05, 0.05, 2.6]])
    for i in (0, 1):
        tips[i, :2] = np.asarray(point) - reflex.hand.tip_radius[i] * np.asarray(normal)
    return tips.ravel()


def test_coincident_points_behave_as_the_oracle():
    reflex = make_reflex(["thumb", "fore"])
    state = reflex.initial_state()
    fn = np.array([2.0, 2.0, 0.0])
    # opposite normals at coincident contact points: the pseudo-inverse drops the moment
    # row, the pushes stay
    opposite = np.array([1.0, 0.0, -1.0, 0.0, 0.0, 0.0])
    tip = coincident_tips(reflex)
    tip[3:5] = np.array([0.02, 0.06]) + reflex.hand.tip_radius[1] * np.array([1.0, 0.0])
    g, _, _ = reflex.directions(state, tip, opposite, fn)
    np.testing.assert_allclose(g, oracles.reflex_directions(reflex, state, tip, opposite, fn)[0], atol=1e-15)
    tip = coincident_tips(reflex)
    # equal normals: nothing internal is left (the SVD's pinv leaves round-off, which the
    # oracle then normalises) and no squeeze direction exists: the fallback's error
    with pytest.raises(ValueError, match="all contact points coincide"):
        oracles.internal_directions(oracles.acting_points(reflex, tip, np.array([1.0, 0.0] * 3), [True] * 3)[:2])
    same = np.array([1.0, 0.0, 1.0, 0.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="^internal forces are undefined: all contact points coincide$"):
        reflex.directions(state, tip, same, fn)


def test_output_ports_are_fresh_and_update_needs_the_period():
    reflex = make_reflex(["thumb", "fore"])
    rng = np.random.default_rng(3)
    state, inputs = random_case(rng, reflex, 2, inward=True)
    a, b = reflex.output(0.0, state, inputs), reflex.output(0.0, state, inputs)
    for port in a:
        assert not np.shares_memory(a[port], b[port]) and not np.shares_memory(a[port], state)
    new = reflex.update(0.0, state, inputs)
    assert new is not state and new.shape == (7,)
    unbound = GraspReflex(hand=Hand.default())
    with pytest.raises(ValueError, match="explicit period"):
        unbound.update(0.0, unbound.initial_state(), inputs)


def test_kernel_takes_the_packed_parameters():
    reflex = make_reflex(["thumb", "fore"])
    state, inputs = random_case(np.random.default_rng(5), reflex, 2, inward=True)
    g, grasp, touching = reflex_directions(reflex._params, state, inputs["tip"], inputs["normal"], inputs["fn"])
    assert g.shape == (3, 2) and grasp.dtype == np.bool_ and touching.dtype == np.bool_
    with pytest.raises(ValueError, match="'tip' must have 9 entries"):
        reflex_directions(reflex._params, state, inputs["tip"][:6], inputs["normal"], inputs["fn"])


def test_coincident_points_are_an_error_of_every_entry_point():
    """The C law's status for coincident points becomes the oracle's ValueError in
    output and update too, not only in directions."""
    reflex = make_reflex(["thumb", "fore"])
    state = np.array([2.0, 1.0, 1.0, 0.0, 1.0, 1.0, 1.0])
    tip = coincident_tips(reflex)
    inputs = {"q": reflex.hand.q0, "tip": tip, "normal": np.array([1.0, 0.0, 1.0, 0.0, 0.0, 0.0]),
              "fn": np.array([2.0, 2.0, 0.0]), "ft": np.zeros(3)}
    message = "^internal forces are undefined: all contact points coincide$"
    with pytest.raises(ValueError, match=message):
        reflex.forces(state, inputs)
    with pytest.raises(ValueError, match=message):
        reflex.output(0.0, state, inputs)
    with pytest.raises(ValueError, match=message):
        reflex.update(0.0, state, inputs)


def test_the_period_is_checked_before_the_directions():
    """An unbound reflex's update names the missing period even where the directions
    would fail; output needs no period."""
    reflex = GraspReflex(hand=Hand.default())
    state = np.array([2.0, 1.0, 1.0, 0.0, 1.0, 1.0, 1.0])
    tip = coincident_tips(reflex)
    normal, fn, ft = np.array([1.0, 0.0, 1.0, 0.0, 0.0, 0.0]), np.array([2.0, 2.0, 0.0]), np.zeros(3)
    with pytest.raises(ValueError, match=r"^GraspReflex needs an explicit period \(the paper's is 1 ms\)$"):
        reflex_update(reflex._params, state, tip, normal, fn, ft)
    with pytest.raises(ValueError, match="all contact points coincide"):
        reflex_output(reflex.hand.native, reflex._params, state, reflex.hand.q0, tip, normal, fn)


@pytest.mark.parametrize("port, width", [("tip", 9), ("normal", 6), ("fn", 3), ("q", 9), ("ft", 3)])
def test_input_widths_are_checked_naming_the_port(port, width):
    reflex = make_reflex(["thumb", "fore"])
    state, inputs = random_case(np.random.default_rng(9), reflex, 2, inward=True)
    inputs[port] = np.zeros(width + 1)
    call = reflex.update if port == "ft" else reflex.output
    with pytest.raises(ValueError, match=f"^GraspReflex: input '{port}' must have {width} entries$"):
        call(0.0, state, inputs)
    inputs[port] = [0.0] * (width - 1)  # converted first, then refused for its width
    with pytest.raises(ValueError, match=f"^GraspReflex: input '{port}' must have {width} entries$"):
        call(0.0, state, inputs)
    with pytest.raises(ValueError, match=r"state must have 7 entries \[scale, handed\(3\), hold\(3\)\]"):
        reflex.update(0.0, np.zeros(3), random_case(np.random.default_rng(9), reflex, 2, inward=True)[1])


def test_packed_parameters_land_in_their_slots():
    """Every value at its own slot (layouts.h), including the coincidence tolerance that
    internal_forces defines."""
    from hierhand.control.internal_forces import _COINCIDENT_RTOL
    from hierhand.model.hand_vector import parameter_names

    given = np.zeros(G.size)
    given[G.THRESHOLD], given[G.APPROACH], given[G.KI], given[G.MIN_FORCE] = 0.05, 0.5, 50.0, 1.0
    given[G.SAFETY_RATIO], given[G.MARGIN], given[G.MAX_FORCE] = 0.6, 0.05, 30.0
    given[G.slice("GRASP")] = [1.0, 0.0, 1.0]
    given[G.RELEASE_SHARE], given[G.HOLD_SHARE], given[G.FOLLOW] = 0.75, 0.85, 0.0
    given[G.COINCIDENT_RTOL] = _COINCIDENT_RTOL
    hand = Hand.default().vector.copy()
    names = parameter_names()
    for f, radius in enumerate((0.009, 0.008, 0.007)):
        hand[names.index(f"fingers[{f + 1}].tip_radius")] = radius
    p = pack_params(given, hand, 0.001)
    assert p[P.COINCIDENT_RTOL] == _COINCIDENT_RTOL and p[P.RELEASE_SHARE] == 0.75 and p[P.FOLLOW] == 0.0
    assert p[P.HOLD_SHARE] == 0.85 and p[P.DT] == 0.001 and p[P.RATIO] == 0.6 / 1.05
    assert p[P.slice("TIP_RADIUS")].tolist() == [0.009, 0.008, 0.007]
    assert p[P.slice("INITIAL")].tolist() == [1.0, 0.0, 1.0] and p[P.KI] == 50.0
    given[G.KI] = -5.0
    with pytest.raises(ValueError, match=r"^parameter 'ki' must be a positive number, got -5.0$"):
        pack_params(given, hand, 0.001)