"""``plot`` on a run of a diagram with library blocks: selections of elements and overlays,
markers, SVG and PDF files, and bad selections or outputs as one line with exit code 2."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

DIAGRAM = """
name: plotted
time: {t_end: 0.2 s}
blocks:
  ref:  {type: Step, period: 1 ms, params: {time: 0.05}}
  mux:  {type: Mux, params: {widths: [1, 1], labels: [ref, wave]}}
  wave: {type: Sine, period: 1 ms, params: {frequency: 10.0}}
connections: [ref.y -> mux.u0, wave.y -> mux.u1]
log: [mux.y, ref.y]
"""


def blocks_cli(*args, cwd):
    return subprocess.run([sys.executable, "-m", "blocks", *map(str, args)], capture_output=True, text=True, cwd=cwd,
                          timeout=120)


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory) -> Path:
    work = tmp_path_factory.mktemp("plotted")
    (work / "d.yaml").write_text(DIAGRAM)
    proc = blocks_cli("run", "d.yaml", "-o", "out", cwd=work)
    assert proc.returncode == 0, proc.stderr
    return work / "out"


def test_elements_by_label_and_overlays_make_one_png(run_dir, tmp_path):
    target = tmp_path / "p.png"
    proc = blocks_cli("plot", run_dir, "-s", "mux.y[wave]", "-s", "mux.y[ref],ref.y", "-o", target, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == f"wrote {target}" and target.read_bytes()[:4] == b"\x89PNG"
    proc = blocks_cli("plot", run_dir, "--no-markers", "-s", "mux.y[0:2]", "-o", target, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr


@pytest.mark.parametrize("selection, word", [
    ("mux.y[speed]", "signal 'mux.y' has no element 'speed'; its elements: ref, wave"),
    ("nope", "error: 'nope' is not a signal (block.port)"),
    ("mux.y[5]", "index 5 is out of range"), ("mux.y,nope.y", "signal 'nope.y' was not logged"),
])
def test_a_bad_selection_is_one_line_and_exit_2(run_dir, tmp_path, selection, word):
    proc = blocks_cli("plot", run_dir, "-s", selection, "-o", tmp_path / "p.png", cwd=tmp_path)
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and word in lines[0] and "Traceback" not in proc.stderr
    assert not (tmp_path / "p.png").exists()


def test_a_plot_that_cannot_be_written_is_one_line_and_exit_1(run_dir, tmp_path):
    (tmp_path / "file").write_text("not a folder")
    proc = blocks_cli("plot", run_dir, "-o", tmp_path / "file" / "p.png", cwd=tmp_path)
    assert proc.returncode == 1
    assert proc.stderr == f"blocks: the plots could not be written: File exists: {tmp_path / 'file'}\n"


@pytest.mark.parametrize("suffix", [".svg", ".pdf"])
def test_an_svg_or_pdf_output_is_a_vector_file(run_dir, tmp_path, suffix):
    target = tmp_path / f"p{suffix}"
    proc = blocks_cli("plot", run_dir, "-s", "mux.y", "-o", target, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    data = target.read_bytes()
    if suffix == ".pdf":
        assert data.startswith(b"%PDF-") and data.rstrip().endswith(b"%%EOF")
    else:
        import xml.etree.ElementTree as ET

        root = ET.fromstring(data)
        assert root.tag == "{http://www.w3.org/2000/svg}svg" and root.findall(".//{http://www.w3.org/2000/svg}path")


def test_another_kind_of_output_is_one_line_and_exit_2(run_dir, tmp_path):
    proc = blocks_cli("plot", run_dir, "-o", tmp_path / "p.jpg", cwd=tmp_path)
    assert proc.returncode == 2 and all(kind in proc.stderr for kind in (".png", ".svg", ".pdf"))  # what it takes
    assert len(proc.stderr.strip().splitlines()) == 1 and not (tmp_path / "p.jpg").exists()
