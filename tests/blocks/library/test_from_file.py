"""FromFile: CSV and NPZ files, held and interpolated (against numpy.interp and a
searchsorted hold), a run's own signals.csv and signals.npz played back, the file listed
in Diagram.files and shipped by sweeps, and every bad file refused in one line."""

from __future__ import annotations

import zipfile

import numpy as np
import pytest

import blocks
from blocks.library import FromFile
from blocks.limits import MAX_DATA_BYTES

TIMES = np.array([0.0, 0.0025, 0.004, 0.004, 0.0071, 0.01])
VALUES = np.array([[1.0, -1.0], [2.0, 0.0], [3.0, 5.0], [-1.0, 2.0], [0.5, 0.5], [4.0, -4.0]])


def write_csv(path, header=True):
    lines = (["t,left,right"] if header else []) + [f"{t!r},{a!r},{b!r}" for t, (a, b) in zip(TIMES.tolist(), VALUES.tolist())]
    path.write_text("\n".join(lines) + "\n")
    return path


def held(t):
    i = np.searchsorted(TIMES, t, side="right") - 1
    return VALUES[np.clip(i, 0, None)]


def interpolated(t):
    """numpy.interp between the samples (at the duplicated time, the later row from it on)."""
    out = np.empty((len(t), 2))
    for k, tk in enumerate(t):
        i = max(int(np.searchsorted(TIMES, tk, side="right")) - 1, 0)
        if i == len(TIMES) - 1 or tk <= TIMES[0]:
            out[k] = VALUES[i]
        else:
            out[k] = [np.interp(tk, TIMES[i:i + 2], VALUES[i:i + 2, j]) for j in range(2)]
    return out


T = np.arange(-2, 14) * 1e-3  # from before the first sample to after the last


@pytest.mark.parametrize("header", [True, False])
def test_csv_held_and_interpolated(tmp_path, header):
    path = write_csv(tmp_path / "data.csv", header)
    for method, reference in (("hold", held), ("linear", interpolated)):
        block = FromFile(str(path), method=method)
        y = np.array([block.output(t, None, {})["y"] for t in T])
        np.testing.assert_allclose(y, reference(T), rtol=0, atol=1e-15)
    assert FromFile(str(path)).element_labels("y") == (["left", "right"] if header else None)


def test_npz_held(tmp_path):
    path = tmp_path / "data.npz"
    np.savez(path, time=TIMES, values=VALUES)
    block = FromFile(str(path))
    y = np.array([block.output(t, None, {})["y"] for t in T])
    np.testing.assert_array_equal(y, held(T))


def test_a_runs_signals_play_back(tmp_path):
    diagram = blocks.loads_diagram("""
blocks:
  src: {type: Sine, period: 1 ms, params: {amplitude: [1.0, 2.0], frequency: 5.0}}
log: [src.y]
""")
    results = blocks.simulate(diagram, t_end="0.2 s")
    results.write_files(tmp_path, csv=True)
    t, expected = results["src.y"]
    for name in ("signals.npz", "signals.csv"):
        block = FromFile(str(tmp_path / name), signal="src.y")
        assert block.outputs == {"y": 2}
        played = np.array([block.output(tk, None, {})["y"] for tk in t])
        np.testing.assert_allclose(played, expected, rtol=1e-15)
    assert FromFile(str(tmp_path / "signals.csv"), signal="src.y").element_labels("y") == ["0", "1"]


def test_the_file_is_the_diagrams_and_sweeps_ship_it(tmp_path):
    folder = tmp_path / "project"
    (folder / "data").mkdir(parents=True)
    write_csv(folder / "data" / "ref.csv")
    (folder / "d.yaml").write_text("""
name: replay
time: {t_end: 10 ms}
blocks:
  ref: {type: FromFile, period: 1 ms, params: {path: data/ref.csv, method: linear}}
  g:   {type: Gain, params: {k: 2.0}}
connections: [ref.y -> g.u]
log: [g.y]
""")
    diagram = blocks.load_diagram(folder / "d.yaml")
    assert diagram.files == {"data/ref.csv": folder / "data" / "ref.csv"}
    assert diagram.parameters()["ref"]["path"].endswith("data/ref.csv")
    from blocks.sweep import grid_points, read_sweep, run_sweep

    run_sweep(folder / "d.yaml", grid_points({"g.k": [1.0, 3.0]}), ["end=final(g.y[1])"], tmp_path / "sweep",
              progress=False, serial=True)  # serial runs read the sweep's bundle of files too
    rows = {float(r["g.k"]): float(r["end"]) for r in read_sweep(tmp_path / "sweep")[1]}
    assert rows == {1.0: VALUES[-1, 1], 3.0: 3 * VALUES[-1, 1]}


def test_in_a_diagram_a_relative_path_is_the_diagrams_folders(tmp_path, monkeypatch):
    write_csv(tmp_path / "ref.csv")
    (tmp_path / "d.yaml").write_text("blocks: {ref: {type: FromFile, period: 1 ms, params: {path: ref.csv}}}\n"
                                     "log: [ref.y]\n")
    monkeypatch.chdir("/")
    results = blocks.simulate(blocks.load_diagram(tmp_path / "d.yaml"), t_end="10 ms")
    np.testing.assert_array_equal(results["ref.y"][1], held(np.arange(11) * 1e-3))


@pytest.mark.parametrize("text, word", [
    ("t,a\n0,1\n1,x\n", "line 3, column 2: 'x' is not a number"),
    ("t,a\n0,1\n1,2,3\n", "line 3: 3 values"),
    ("t,a\n1,1\n0,2\n", "must not decrease"),
    ("t,a\n0,1\n1,inf\n", "values must be finite"),
    ("t\n0\n1\n", "at least one value"),
    ("t,a\n", "no rows"),
    ("", "is empty"),
])
def test_bad_csv_files_are_refused_in_one_line(tmp_path, text, word):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(ValueError, match=word) as err:
        FromFile(str(path))
    assert "\n" not in str(err.value) and "bad.csv" in str(err.value)


def test_bad_npz_files_are_refused_in_one_line(tmp_path):
    np.savez(tmp_path / "two.npz", time=TIMES, a=VALUES, b=VALUES)
    with pytest.raises(ValueError, match="name the array to read with 'signal'"):
        FromFile(str(tmp_path / "two.npz"))
    with pytest.raises(ValueError, match="no array 'c'"):
        FromFile(str(tmp_path / "two.npz"), signal="c")
    np.savez(tmp_path / "short.npz", time=TIMES[:3], values=VALUES)
    with pytest.raises(ValueError, match="shape"):
        FromFile(str(tmp_path / "short.npz"))
    np.savez(tmp_path / "objects.npz", time=TIMES, values=np.array([object()] * 6))
    with pytest.raises(ValueError, match="objects.npz"):
        FromFile(str(tmp_path / "objects.npz"))
    (tmp_path / "fake.npz").write_bytes(b"not a zip")
    with pytest.raises(ValueError, match="not a readable NPZ"):
        FromFile(str(tmp_path / "fake.npz"))


def test_an_npz_that_inflates_past_the_limit_is_refused_unread(tmp_path):
    path = tmp_path / "bomb.npz"
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED) as archive:
        with archive.open("time.npy", "w", force_zip64=True) as member:
            np.lib.format.write_array_header_1_0(member, {"descr": "<f8", "fortran_order": False,
                                                          "shape": (MAX_DATA_BYTES // 8 + 1,)})
            chunk = bytes(1 << 20)
            for _ in range(MAX_DATA_BYTES // len(chunk) + 1):
                member.write(chunk)
    assert path.stat().st_size < MAX_DATA_BYTES // 100
    with pytest.raises(ValueError, match="once decompressed"):
        FromFile(str(path))


@pytest.mark.parametrize("params, word", [
    (dict(path=""), "'path'"), (dict(path=3), "'path'"), (dict(path="x.txt"), "end in .csv or .npz"),
    (dict(path="missing.csv"), "not found"), (dict(path="x.csv", method="cubic"), "'method'"),
    (dict(path="x.csv", signal=""), "'signal'"),
])
def test_bad_parameters_are_named(params, word):
    with pytest.raises(ValueError, match=word):
        FromFile(**params)
