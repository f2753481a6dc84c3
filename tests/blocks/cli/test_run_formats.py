"""``run``'s result formats and logging options: --mat, --csv-digits, --decimate."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from scipy.io import loadmat

from blocks import Results
from blocks.cli import PROGRAM
from blocks.cli.program import main

TOY = Path(__file__).resolve().parents[3] / "diagrams" / "toy.yaml"


def run(*args) -> int:
    return main(PROGRAM, ["run", str(TOY), "-q", "--t-end", "20 ms", *map(str, args)])


def test_mat_holds_what_signals_npz_holds(tmp_path):
    assert run("-o", tmp_path, "--mat") == 0
    t, y = Results.load(tmp_path)["plant.y"]
    signal = loadmat(tmp_path / "signals.mat", simplify_cells=True)["signals"]["plant"]["y"]
    np.testing.assert_array_equal(signal["time"], t)
    np.testing.assert_array_equal(signal["values"], y[:, 0])


def test_decimate_keeps_every_nth_sample_and_run_json_says_so(tmp_path):
    assert run("-o", tmp_path / "all") == 0
    assert run("-o", tmp_path / "tenth", "--decimate", 10) == 0
    t, y = Results.load(tmp_path / "all")["plant.y"]
    t10, y10 = Results.load(tmp_path / "tenth")["plant.y"]
    np.testing.assert_array_equal(t10, t[::10])
    np.testing.assert_array_equal(y10, y[::10])
    info = json.loads((tmp_path / "tenth" / "run.json").read_text())
    assert info["decimate"] == {"plant.y": 10} and "decimate" not in Results.load(tmp_path / "all").info


def test_csv_digits_sets_the_csv_precision(tmp_path):
    assert run("-o", tmp_path, "--csv", "--csv-digits", 3) == 0
    rows = (tmp_path / "signals.csv").read_text().splitlines()
    assert rows[0] == "time,plant.y"
    assert all(len(v.lstrip("-").replace(".", "").split("e")[0].lstrip("0")) <= 3
               for row in rows[1:] for v in row.split(","))


@pytest.mark.parametrize("args, message", [
    (("--csv", "--csv-digits", 0), "--csv-digits: CSV digits must be a whole number from 1 to 17 (17 keeps every double), got 0"),
    (("--csv-digits", 5), "--csv-digits sets the precision of signals.csv: add --csv"),
    (("--decimate", 0), "--decimate must be a positive whole number, got 0"),
])
def test_bad_format_options_are_one_line_exit_2_and_nothing_is_written(tmp_path, capsys, args, message):
    assert run("-o", tmp_path / "out", *args) == 2
    err = capsys.readouterr().err
    assert err == f"blocks: error: {message}\n"
    assert not (tmp_path / "out").exists()
