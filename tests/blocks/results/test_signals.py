"""Results: indexing, save/load round trip, CSV on the union time grid, atomic files."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

import blocks
from blocks import Results, ResultsError


def two_rate_results() -> Results:
    """a.y (width 1) every 1 ms; b.y (width 2) every 2 ms, both from t = 0 to 3 ms."""
    signals = {
        "a.y": (np.array([0.0, 0.001, 0.002, 0.003]), np.array([[0.5], [1.5], [2.5], [3.5]])),
        "b.y": (np.array([0.0, 0.002]), np.array([[10.0, 11.0], [20.0, 21.0]])),
    }
    info = {"diagram": "two-rate", "status": "complete", "t_end": 0.003,
            "parameters": {"a": {"k": 1.0}}}
    return Results(signals, info)


def read_csv(path):
    with open(path, newline="", encoding="utf-8") as f:
        rows = list(csv.reader(f))
    return rows[0], [[float(x) for x in row] for row in rows[1:]]


def test_indexing_returns_times_and_values():
    r = two_rate_results()
    t, v = r["b.y"]
    np.testing.assert_array_equal(t, [0.0, 0.002])
    np.testing.assert_array_equal(v, [[10.0, 11.0], [20.0, 21.0]])
    assert "a.y" in r and "nope.y" not in r
    assert sorted(r) == ["a.y", "b.y"]
    assert len(r) == 2


def test_unknown_signal_keyerror_lists_logged_signals():
    r = two_rate_results()
    with pytest.raises(KeyError) as info:
        r["nope.y"]
    text = str(info.value)
    assert "nope.y" in text
    assert "a.y" in text and "b.y" in text


def test_status_and_complete():
    r = two_rate_results()
    assert r.complete and r.status == "complete"
    failed = Results({}, {"status": "failed at t=0.5 s: block 'x' (Gain) output: boom"})
    assert not failed.complete


def test_save_load_round_trip(tmp_path):
    r = two_rate_results()
    r.save(tmp_path / "run")
    back = Results.load(tmp_path / "run")
    assert sorted(back) == sorted(r)
    for name in r:
        t0, v0 = r[name]
        t1, v1 = back[name]
        np.testing.assert_array_equal(t1, t0)
        np.testing.assert_array_equal(v1, v0)
        assert v1.dtype == np.float64 and v1.shape == v0.shape
    for key, value in r.info.items():
        assert back.info[key] == value
    assert back.complete


def test_save_load_round_trip_exact_floats(tmp_path):
    rng = np.random.default_rng(7)
    values = rng.standard_normal((50, 3)) * 1e-300
    times = np.arange(50) * 1 / 10_000
    r = Results({"x.q": (times, values)}, {"status": "complete"})
    r.save(tmp_path)
    back = Results.load(tmp_path)
    np.testing.assert_array_equal(back["x.q"][0], times)
    np.testing.assert_array_equal(back["x.q"][1], values)


def test_npz_layout_is_the_documented_one(tmp_path):
    two_rate_results().save(tmp_path)
    with np.load(tmp_path / "signals.npz") as data:
        assert set(data.files) == {"a.y", "time:a.y", "b.y", "time:b.y"}
        assert data["b.y"].shape == (2, 2)
        np.testing.assert_array_equal(data["time:a.y"], [0.0, 0.001, 0.002, 0.003])


def test_run_json_is_valid_json_with_signal_summary(tmp_path):
    two_rate_results().save(tmp_path)
    info = json.loads((tmp_path / "run.json").read_text(encoding="utf-8"))
    assert info["diagram"] == "two-rate"
    assert info["status"] == "complete"
    assert info["signals"]["b.y"] == {"width": 2, "samples": 2}


def test_failed_status_survives_round_trip(tmp_path):
    status = "failed at t=0.002 s: block 'a' (Gain) output: boom"
    r = Results({"a.y": (np.array([0.0, 0.001]), np.array([[1.0], [2.0]]))}, {"status": status})
    r.save(tmp_path)
    back = Results.load(tmp_path)
    assert back.status == status
    assert not back.complete


def test_csv_is_held_on_the_union_grid(tmp_path):
    two_rate_results().save(tmp_path, csv=True)
    header, rows = read_csv(tmp_path / "signals.csv")
    assert header == ["time", "a.y", "b.y[0]", "b.y[1]"]
    # By hand: b.y holds its 0 ms value at 1 ms and its 2 ms value at 3 ms.
    assert rows == [
        [0.0, 0.5, 10.0, 11.0],
        [0.001, 1.5, 10.0, 11.0],
        [0.002, 2.5, 20.0, 21.0],
        [0.003, 3.5, 20.0, 21.0],
    ]


def test_csv_grid_includes_samples_of_the_slower_signal_between_fast_ones(tmp_path):
    # Rates that are not multiples: 2 ms and 3 ms. The union grid is 0, 2, 3, 4, 6 ms.
    r = Results({
        "f.y": (np.array([0.0, 0.002, 0.004, 0.006]), np.array([[1.0], [2.0], [3.0], [4.0]])),
        "s.y": (np.array([0.0, 0.003, 0.006]), np.array([[-1.0], [-2.0], [-3.0]])),
    }, {"status": "complete"})
    r.save(tmp_path, csv=True)
    header, rows = read_csv(tmp_path / "signals.csv")
    assert header == ["time", "f.y", "s.y"]
    assert rows == [
        [0.0, 1.0, -1.0],
        [0.002, 2.0, -1.0],
        [0.003, 2.0, -2.0],
        [0.004, 3.0, -2.0],
        [0.006, 4.0, -3.0],
    ]


def test_csv_of_a_simulated_two_rate_diagram(tmp_path):
    text = """
name: two-rate
time: {t_end: 4 ms}
blocks:
  fast: {type: Ramp, period: 1 ms, params: {slope: 1000.0}}
  slow: {type: ZeroOrderHold, period: 2 ms}
connections:
  - fast.y -> slow.u
log: [fast.y, slow.y]
"""
    d = blocks.loads_diagram(text, filename="two.yaml", base_dir=tmp_path)
    r = blocks.simulate(d)
    assert r.complete
    r.save(tmp_path, csv=True)
    header, rows = read_csv(tmp_path / "signals.csv")
    assert header == ["time", "fast.y", "slow.y"]
    # fast.y = 1000 t at 0..4 ms; slow.y samples it at 0, 2, 4 ms and holds.
    expected = [[0.0, 0.0, 0.0], [0.001, 1.0, 0.0], [0.002, 2.0, 2.0], [0.003, 3.0, 2.0],
                [0.004, 4.0, 4.0]]
    assert len(rows) == len(expected)
    for got, want in zip(rows, expected):
        assert got == pytest.approx(want, rel=1e-12, abs=1e-12)


def test_save_leaves_no_temporary_files(tmp_path):
    out = tmp_path / "run"
    r = two_rate_results()
    r.save(out, csv=True)
    r.save(out, csv=True)            # saving again replaces the files in place
    assert sorted(p.name for p in out.iterdir()) == ["run.json", "signals.csv", "signals.npz"]


def test_save_creates_missing_folders(tmp_path):
    out = tmp_path / "a" / "b" / "c"
    two_rate_results().save(out)
    assert (out / "signals.npz").is_file() and (out / "run.json").is_file()
    assert not (out / "signals.csv").exists()


def test_failed_save_keeps_the_previous_file_and_no_temporary_file(tmp_path):
    good = two_rate_results()
    good.save(tmp_path, csv=True)
    before = (tmp_path / "signals.csv").read_bytes()
    # Values that are not (samples, width) cannot be saved: refused inside the staging folder.
    bad = Results({"a.y": (np.array([0.0, 1.0]), np.array([1.0, 2.0]))}, {"status": "complete"})
    with pytest.raises(ValueError, match=r"^signal 'a\.y' cannot be saved: its values must be an array "
                       r"of shape \(samples, width\), got shape \(2,\)$"):
        bad.save(tmp_path, csv=True)
    assert (tmp_path / "signals.csv").read_bytes() == before
    leftovers = [p.name for p in tmp_path.iterdir() if p.name.startswith(".") or p.suffix == ".tmp"]
    assert leftovers == []


def test_load_of_a_folder_without_results_is_a_results_error(tmp_path):
    with pytest.raises(ResultsError) as info:
        Results.load(tmp_path)
    assert str(tmp_path) in str(info.value)


def test_load_of_a_corrupt_npz_is_a_results_error(tmp_path):
    (tmp_path / "signals.npz").write_bytes(b"not a zip file")
    with pytest.raises(ResultsError):
        Results.load(tmp_path)


def test_value_at_is_zero_order_hold():
    r = two_rate_results()
    assert r.value_at("b.y", 0.0).tolist() == [10.0, 11.0]
    assert r.value_at("b.y", 0.0019).tolist() == [10.0, 11.0]
    assert r.value_at("b.y", 0.002).tolist() == [20.0, 21.0]
    assert r.value_at("b.y", 1.0).tolist() == [20.0, 21.0]
    with pytest.raises(ValueError):
        r.value_at("b.y", -1.0)


def test_empty_results_round_trip(tmp_path):
    r = Results({}, {"status": "complete"})
    r.save(tmp_path, csv=True)
    back = Results.load(tmp_path)
    assert len(back) == 0
    header, rows = read_csv(tmp_path / "signals.csv")
    assert header == ["time"] and rows == []


def test_held_values_are_the_last_sample_at_or_before_each_time():
    res = Results({"a.y": (np.array([0.1, 0.3]), np.array([[1.0], [2.0]]))}, {})
    held = res.held("a.y", np.array([0.0, 0.1, 0.2, 0.3, 0.9]))
    np.testing.assert_array_equal(held[1:, 0], [1.0, 1.0, 2.0, 2.0])
    assert np.isnan(held[0, 0])  # before the first sample


LABELLED = """
time: {t_end: 2 ms}
blocks:
  named: {type: "python:tests.blocks.blockdefs:Labelled", period: 1 ms, params: {labels: LABELS}}
  plain: {type: "python:tests.blocks.blockdefs:Labelled", period: 1 ms, params: {width: 2}}
log: [named.y, plain.y]
"""


def labelled_run(labels: str) -> Results:
    return blocks.simulate(blocks.loads_diagram(LABELLED.replace("LABELS", labels), trust=True))


def test_csv_columns_use_the_element_labels_a_block_gives(tmp_path):
    r = labelled_run('["1,1", "1,2", "2,1"]')
    assert r.complete, r.status
    assert r.info["element_labels"] == {"named.y": ["1,1", "1,2", "2,1"]}
    r.save(tmp_path / "run", csv=True)
    header, rows = read_csv(tmp_path / "run" / "signals.csv")
    assert header == ["time", "named.y[1,1]", "named.y[1,2]", "named.y[2,1]", "plain.y[0]", "plain.y[1]"]
    assert rows[-1] == pytest.approx([0.002, 1.0, 2.0, 3.0, 1.0, 2.0])
    again = Results.load(tmp_path / "run")
    again.save(tmp_path / "again", csv=True)
    assert (tmp_path / "again" / "signals.csv").read_bytes() == (tmp_path / "run" / "signals.csv").read_bytes()


def test_without_element_labels_run_json_has_none():
    r = labelled_run("null")
    assert "element_labels" not in r.info


def test_element_labels_of_the_wrong_length_fail_the_run_at_its_start():
    r = labelled_run('["1", "2"]')
    assert r.status == ("failed at t=0 s: block 'named' (Labelled), signal named.y element_labels: "
                        "2 labels for the 3 elements of 'y'")
    assert len(r["named.y"][0]) == 0


UNITS = """
time: {t_end: 2 ms}
blocks:
  same: {type: "python:tests.blocks.blockdefs:Labelled", period: 1 ms, params: {units: N m}}
  mixed: {type: "python:tests.blocks.blockdefs:Labelled", period: 1 ms,
          params: {labels: [x, y, theta], units: UNITS}}
  plain: {type: "python:tests.blocks.blockdefs:Labelled", period: 1 ms, params: {width: 2}}
log: [same.y, mixed.y, plain.y]
"""


def units_run(units: str) -> Results:
    return blocks.simulate(blocks.loads_diagram(UNITS.replace("UNITS", units), trust=True))


def test_run_json_keeps_the_units_blocks_give_and_results_read_them_back(tmp_path):
    r = units_run("[m, m, rad]")
    assert r.complete, r.status
    assert r.info["units"] == {"same.y": "N m", "mixed.y": ["m", "m", "rad"]}
    r.save(tmp_path, csv=True)
    assert json.loads((tmp_path / "run.json").read_text())["units"] == r.info["units"]
    again = Results.load(tmp_path)
    assert again.units("same.y") == ["N m"] * 3 and again.unit("same.y") == "N m"
    assert again.units("mixed.y") == ["m", "m", "rad"] and again.unit("mixed.y") is None
    assert again.units("plain.y") is None and again.unit("plain.y") is None
    header, _ = read_csv(tmp_path / "signals.csv")  # the CSV's columns are as before: units live in run.json
    assert header[1:4] == ["same.y[0]", "same.y[1]", "same.y[2]"] and header[4:7] == ["mixed.y[x]", "mixed.y[y]",
                                                                                       "mixed.y[theta]"]


def test_a_list_of_one_unit_is_kept_as_that_unit():
    assert units_run("[m, m, m]").info["units"]["mixed.y"] == "m"


@pytest.mark.parametrize("units, problem", [
    ("[m, rad]", "2 units for the 3 elements of 'y'"),
    ("[m, 1, rad]", "the units of 'y' must be a string or a list of strings, got ['m', 1, 'rad']"),
])
def test_units_that_do_not_fit_the_port_fail_the_run_at_its_start(units, problem):
    r = units_run(units)
    assert r.status == f"failed at t=0 s: block 'mixed' (Labelled), signal mixed.y port_units: {problem}"


def test_results_without_units_in_run_json_have_none():
    r = two_rate_results()
    assert r.units("b.y") is None and r.unit("a.y") is None


def test_csv_numbers_are_the_shortest_text_that_reads_back_the_same_double(tmp_path):
    values = np.array([[0.001], [1 / 3], [1e-300], [-2.5e17], [np.nan], [np.inf]])
    r = Results({"x.y": (np.arange(6) * 0.001, values)}, {"status": "complete"})
    r.save(tmp_path, csv=True)
    lines = (tmp_path / "signals.csv").read_text().splitlines()
    assert lines[:3] == ["time,x.y", "0.0,0.001", "0.001,0.3333333333333333"]
    assert lines[4:] == ["0.003,-2.5e+17", "0.004,nan", "0.005,inf"]
    _, rows = read_csv(tmp_path / "signals.csv")
    np.testing.assert_array_equal([row[1] for row in rows], values[:, 0])


def test_csv_digits_rounds_to_that_many_significant_digits(tmp_path):
    r = Results({"x.y": (np.array([0.0, 0.001]), np.array([[1 / 3], [123456.789]]))}, {"status": "complete"})
    r.save(tmp_path, csv=True, csv_digits=4)
    assert (tmp_path / "signals.csv").read_text().splitlines() == ["time,x.y", "0,0.3333", "0.001,1.235e+05"]


@pytest.mark.parametrize("digits", [0, 18, 2.5, True, "6"])
def test_csv_digits_outside_1_to_17_is_refused(tmp_path, digits):
    with pytest.raises(ValueError, match="CSV digits must be a whole number from 1 to 17"):
        two_rate_results().save(tmp_path, csv=True, csv_digits=digits)
