"""Links in an output folder that lead out of it: nothing is written (or removed) through
them. The corpus cannot make links, so these cases are tests of their own."""

from __future__ import annotations

import os
from pathlib import Path

from .cases_round2 import TOY
from .corpus import Case, run, verify


def _linked(tmp_path: Path, link: str) -> Path:
    folder = tmp_path / "case"
    (folder / "elsewhere").mkdir(parents=True)
    (folder / "elsewhere" / "signals.png").write_bytes(b"not the run's")
    target = folder / link
    target.parent.mkdir(parents=True, exist_ok=True)
    os.symlink(folder / "elsewhere", target)
    return folder


def _untouched(folder: Path) -> None:
    assert [p.name for p in (folder / "elsewhere").iterdir()] == ["signals.png"]
    assert (folder / "elsewhere" / "signals.png").read_bytes() == b"not the run's"


def test_plots_linking_out_is_refused_before_the_run(tmp_path):
    folder = _linked(tmp_path, "out/plots")
    case = Case("plots-link", ("run", "d.yaml", "-o", "out", "--plot"), 2,
                r"^hierhand: error: output folder out holds plots, a symbolic link out of it", files={"d.yaml": TOY})
    verify(case, folder, run(case, folder))
    _untouched(folder)


def test_a_run_without_plots_leaves_what_a_plots_link_leads_to(tmp_path):
    folder = _linked(tmp_path, "out/plots")
    case = Case("plots-link-no-plot", ("run", "d.yaml", "-o", "out", "-q"), 0, r"^$", files={"d.yaml": TOY})
    verify(case, folder, run(case, folder))
    _untouched(folder)


def test_sweep_runs_linking_out_is_refused(tmp_path):
    folder = _linked(tmp_path, "sw/runs")
    case = Case("runs-link", ("sweep", "d.yaml", "-o", "sw", "--grid", "g.k=1,2", "--metric", "m=final(g.y)",
                              "--keep-results"), 2, r"sw/runs is a symbolic link out of the sweep folder",
                files={"d.yaml": TOY})
    verify(case, folder, run(case, folder))
    _untouched(folder)


def test_sweep_csv_linking_out_is_refused(tmp_path):
    folder = _linked(tmp_path, "sw/x")
    os.symlink(folder / "elsewhere" / "sweep.csv", folder / "sw" / "sweep.csv")
    case = Case("csv-link", ("sweep", "d.yaml", "-o", "sw", "--grid", "g.k=1,2", "--metric", "m=final(g.y)"), 2,
                r"sw/sweep\.csv is a symbolic link out of the sweep folder", files={"d.yaml": TOY})
    verify(case, folder, run(case, folder))
    _untouched(folder)
