"""hierhand._native, the C core's Python face: strict C99 sources, argument checks, hostile states."""

from __future__ import annotations

import shutil
import subprocess
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

from blocks.engine import native_sources as framework_sources
from blocks.block import BlockError
from hierhand import _native, native_sources
from hierhand.model import Hand, HandPlant
from hierhand.layouts import OUTPUT, STATE

REPO = Path(__file__).resolve().parents[2]


FMU_C_FILES = sorted({p for fmi in framework_sources.FMI_WRAPPERS
                      for p in native_sources.fmu_sources(framework_sources.fmu_sources(fmi)) if p.endswith(".c")})
"""Every C file of hierhand's FMU binaries (FMI 2 and 3): the framework's and the hand's."""


@pytest.mark.parametrize("path", FMU_C_FILES)
def test_core_and_fmu_sources_are_strict_c99(path, tmp_path):
    compiler = shutil.which("gcc")
    if compiler is None:
        pytest.skip("gcc is not installed")
    done = subprocess.run([compiler, "-std=c99", "-pedantic-errors", "-Wall", "-Wextra", "-Werror", "-fPIC",
                           "-I", str(REPO / framework_sources.FMI_HEADERS), "-I", str(REPO / framework_sources.CSRC),
                           "-I", str(REPO / native_sources.CSRC), "-c", str(REPO / path),
                           "-o", str(tmp_path / "x.o")], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr


def bound_model() -> _native.Model:
    return Hand.default().native.with_dt(1e-4)


def test_a_model_without_a_step_cannot_step():
    model = Hand.default().native
    state = np.empty(model.state_size)
    _native.initial_state(model, state)
    with pytest.raises(ValueError, match="no step"):
        _native.advance(model, state, np.zeros(9), np.zeros(3), np.empty((1, OUTPUT.size)))
    with pytest.raises(ValueError, match="dt must be a positive"):
        model.with_dt(0.0)


@pytest.mark.parametrize("mutate, error, match", [
    (lambda a: a.update(state=a["state"].astype(np.float32)), TypeError, "state must hold float64"),
    (lambda a: a.update(state=a["state"][:-1].copy()), ValueError, "state must hold"),
    (lambda a: a.update(tau=np.zeros(8)), ValueError, "tau must hold 9 values, got 8"),
    (lambda a: a.update(tau=np.zeros(18)[::2]), TypeError, "tau must be a C-contiguous"),
    (lambda a: a.update(f_ext=[0.0, 0.0, 0.0]), TypeError, "f_ext must be a C-contiguous"),
    (lambda a: a.update(rows=np.empty(50)), ValueError, "whole output rows of 51"),
    (lambda a: a["rows"].setflags(write=False), TypeError, "rows must be a C-contiguous writable"),
    (lambda a: a.update(model=object()), TypeError, "model must be a hierhand._native.Model"),
])
def test_the_core_refuses_arrays_it_cannot_take(mutate, error, match):
    model = bound_model()
    args = {"model": model, "state": np.empty(model.state_size), "tau": np.zeros(9), "f_ext": np.zeros(3),
            "rows": np.empty((2, OUTPUT.size))}
    _native.initial_state(model, args["state"])
    mutate(args)
    with pytest.raises(error, match=match):
        _native.advance(args["model"], args["state"], args["tau"], args["f_ext"], args["rows"])


def test_check_hand_names_each_problem_by_its_index():
    hand = Hand.default().vector.copy()
    names = [name for name, *_ in _native.hand_parameters()]
    hand[names.index("object.mass")] = -1.0
    hand[names.index("fingers[2].damping[3]")] = -0.5
    hand[names.index("contact.k_t")] = np.nan
    problems = _native.check_hand(hand)
    assert problems == [(names.index("object.mass"), "must be > 0, got -1"),
                        (names.index("contact.k_t"), "must be finite, got nan"),
                        (names.index("fingers[2].damping[3]"), "must be >= 0, got -0.5")]
    with pytest.raises(ValueError, match="invalid hand: object.mass must be > 0, got -1 .3 problems"):
        _native.Model(hand)
    assert _native.check_hand(Hand.default().vector) == []


def test_too_many_surface_points_are_refused_before_any_memory_is_taken():
    hand = Hand.default().vector.copy()
    names = [name for name, *_ in _native.hand_parameters()]
    hand[names.index("object.surface_spacing")] = 1e-7
    [(index, text)] = _native.check_hand(hand)
    assert names[index] == "object.surface_spacing" and "2000000 surface points, more than the 100000" in text


@pytest.mark.parametrize("window", [1e9, -7.0, np.nan, np.inf])
def test_a_hostile_contact_window_in_the_state_cannot_write_outside_it(window):
    """States do not only come from the step (users, FMU states): the core clamps what it
    reads from them, so a wrong window is wrong physics at worst, never a crash."""
    model = bound_model()
    state = np.empty(model.state_size)
    _native.initial_state(model, state)
    state[STATE.slice("WINDOW")] = window
    before = state.copy()
    rows = np.empty((20, OUTPUT.size))
    code, done, _ = _native.advance(model, state, np.zeros(9), np.zeros(3), rows)
    assert code == 0 and done == 20
    assert np.isfinite(rows).all()
    np.testing.assert_array_equal(state[STATE.TOUCH:], before[STATE.TOUCH:])  # no finger touches: no anchor moved


def test_plant_converts_inputs_it_can_and_names_the_ones_it_cannot():
    plant = HandPlant()
    plant.bind(Fraction(1, 10000))
    state = plant.initial_state()
    state, rows = plant.advance(0.0, state, {"tau": [0] * 9, "f_ext": np.zeros(3, dtype=np.float32)}, 3)
    assert rows["q"].shape == (3, 9)
    with pytest.raises(BlockError, match="input 'tau' must have width 9") as info:
        plant.advance(0.0, state, {"tau": np.zeros(8), "f_ext": np.zeros(3)}, 3)
    assert info.value.port == "tau"
    with pytest.raises(BlockError, match="state must be the float64 vector"):
        plant.update(0.0, state[::2].copy(), {"tau": np.zeros(9)})
    unbound = HandPlant()
    with pytest.raises(BlockError, match="not bound"):
        unbound.output(0.0, unbound.initial_state(), {"tau": np.zeros(9)})
