"""Results as a MATLAB MAT file: what scipy (and so MATLAB) reads back from it."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.io import loadmat

import blocks
from blocks import Results
from blocks.results.mat import MatNameError, mat_paths

DIAGRAM = """
name: mat-run
time: {t_end: 3 ms}
blocks:
  mixed: {type: "python:tests.blocks.blockdefs:Labelled", period: 1 ms,
          params: {labels: [x, y, theta], units: [m, m, rad]}}
  plain: {type: "python:tests.blocks.blockdefs:Labelled", period: 2 ms, params: {width: 2}}
log: [mixed.y, plain.y]
"""


def read(path):
    return loadmat(path, simplify_cells=True)


def test_mat_file_holds_each_signal_with_times_units_and_element_names(tmp_path):
    r = blocks.simulate(blocks.loads_diagram(DIAGRAM, trust=True))
    assert r.complete, r.status
    r.save_mat(tmp_path / "run.mat")
    data = read(tmp_path / "run.mat")
    mixed, plain = data["signals"]["mixed"]["y"], data["signals"]["plain"]["y"]
    np.testing.assert_array_equal(mixed["time"], r["mixed.y"][0])
    np.testing.assert_array_equal(mixed["values"], r["mixed.y"][1])
    assert list(mixed["units"]) == ["m", "m", "rad"] and list(mixed["elements"]) == ["x", "y", "theta"]
    assert mixed["name"] == "mixed.y"
    np.testing.assert_array_equal(plain["time"], [0.0, 0.002])
    assert [np.size(u) for u in plain["units"]] == [0, 0]  # '' (MATLAB's empty char array): no unit and list(plain["elements"]) == ["0", "1"]
    assert data["run"]["diagram"] == "mat-run" and data["run"]["status"] == "complete"
    assert data["run"]["t_end"] == pytest.approx(0.003)
    assert json.loads(data["run"]["info_json"])["units"] == {"mixed.y": ["m", "m", "rad"]}


def test_values_keep_their_shape_and_every_bit(tmp_path):
    rng = np.random.default_rng(3)
    values = rng.standard_normal((1, 4)) * 1e-300
    Results({"a.q": (np.array([0.5]), values)}, {"status": "complete"}).save_mat(tmp_path / "one.mat")
    q = loadmat(tmp_path / "one.mat")["signals"]["a"][0, 0]["q"][0, 0]  # as MATLAB sees it: no squeezing
    assert q["values"][0, 0].shape == (1, 4) and q["time"][0, 0].shape == (1, 1)
    np.testing.assert_array_equal(q["values"][0, 0], values)


def test_a_subsystem_block_is_a_nested_struct_and_a_leading_underscore_gets_an_x(tmp_path):
    r = Results({"ctrl.reflex.tau": (np.array([0.0]), np.array([[1.0]])),
                 "ctrl._aux.y": (np.array([0.0]), np.array([[2.0]]))}, {"status": "complete"})
    r.save(tmp_path, mat=True)
    signals = read(tmp_path / "signals.mat")["signals"]
    assert signals["ctrl"]["reflex"]["tau"]["values"] == 1.0
    assert signals["ctrl"]["x_aux"]["y"]["name"] == "ctrl._aux.y"


def test_names_that_meet_in_matlab_are_refused(tmp_path):
    r = Results({"a._b": (np.array([0.0]), np.array([[1.0]])),
                 "a.x_b": (np.array([0.0]), np.array([[2.0]]))}, {"status": "complete"})
    with pytest.raises(MatNameError, match="signal 'a.x_b' cannot be written to a MAT file: its MATLAB "
                                           "name 'a.x_b' is taken by signal 'a._b'"):
        r.save_mat(tmp_path / "refused.mat")
    assert list(tmp_path.iterdir()) == []


def test_save_with_mat_writes_signals_mat_and_a_later_save_without_removes_it(tmp_path):
    r = Results({"a.y": (np.array([0.0]), np.array([[1.0]]))}, {"status": "complete"})
    r.save(tmp_path, mat=True)
    assert (tmp_path / "signals.mat").is_file()
    r.save(tmp_path)
    assert not (tmp_path / "signals.mat").exists()


def test_a_name_matlab_cannot_take_is_refused_naming_the_signal():
    with pytest.raises(MatNameError, match="signal 'a.y-z' cannot be written to a MAT file: 'y-z' is not a MATLAB name"):
        mat_paths(["a.y-z"])
