"""The op-table core runs from plain C: a packed table and kernels, no Python at all.

``kernel_sources/run_table.c`` is a C host of ``blocks/csrc/core.c``, built here with the
test kernels and without Python's headers or library. It reads a table as
``OpTable.pack`` writes it, binds leak.c's kernels, runs it and writes what it logged: the
same rows, status and end as ``simulate`` gives, to the last bit. A damaged table is
refused with what is wrong, not run.
"""

from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np
import pytest

from blocks import build_schedule, loads_diagram, simulate
from blocks.engine.optable import L_WIDTH, op_table

from ..compiled_blocks import Leak, Scale, Stopper, register
from ..fmu.build import compiler

SOURCES = Path(__file__).parents[1] / "kernel_sources"
CSRC = Path(__file__).resolve().parents[3] / "blocks" / "csrc"


@pytest.fixture(scope="module")
def run_table(tmp_path_factory) -> Path:
    if compiler() is None:
        pytest.skip("no C compiler")
    folder = tmp_path_factory.mktemp("core")
    strict = ["-std=c99", "-pedantic", "-Wall", "-Wextra", "-Werror"]  # the core and its host: plain C99
    for source, flags in [(CSRC / "core.c", strict), (SOURCES / "run_table.c", strict), (SOURCES / "leak.c", [])]:
        cmd = [compiler(), "-c", "-O2", "-ffp-contract=off", *flags, f"-I{CSRC}", str(source), "-o",
               str(folder / f"{source.stem}.o")]
        done = subprocess.run(cmd, capture_output=True, text=True, check=False)
        assert done.returncode == 0, done.stderr
    program = folder / "run_table"
    done = subprocess.run([compiler(), *(str(folder / f"{n}.o") for n in ("core", "run_table", "leak")), "-o",
                           str(program), "-lm"], capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stderr
    return program


@pytest.fixture(autouse=True)
def registered(library, monkeypatch):
    register(library, monkeypatch)


def spec_line(block) -> str:
    if isinstance(block, Leak):
        return f"leak {block.a!r} {block.b!r} {block.limit!r} {block.width} {block.x0!r}"
    if isinstance(block, Scale):
        return f"scale {block.k!r} {int(block.params[1])}"
    assert isinstance(block, Stopper)
    return f"stopper {block.stop!r}"


def run_in_c(program: Path, diagram, tmp_path: Path):
    """The diagram's table run by the plain C host: (status line fields, rows per log entry)."""
    table = op_table(diagram, build_schedule(diagram, diagram.t_end))
    (tmp_path / "table").write_bytes(table.pack())
    (tmp_path / "spec").write_text("\n".join(spec_line(diagram.blocks[n].block) for n in table.names.blocks) + "\n")
    done = subprocess.run([str(program), str(tmp_path / "table"), str(tmp_path / "spec"), str(tmp_path / "out")],
                          capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stderr
    data = (tmp_path / "out").read_bytes()
    rows, at = {}, 0
    for signal, entry in zip(table.names.logs, table.logs):
        count = int(np.frombuffer(data, np.int64, 1, at)[0])
        width = int(entry[L_WIDTH])
        rows[signal] = np.frombuffer(data, np.float64, count * width, at + 8).reshape(count, width)
        at += 8 + 8 * count * width
    return [int(x) for x in done.stdout.split()], rows, table


FUSED = """
time: {t_end: 0.2 s}
blocks:
  s: {type: TestStopper, period: 2 ms, params: {stop: %(stop)s}}
  z: {type: TestLeak, period: 0.25 ms, params: {a: 0.9, b: 1.0, width: 2, limit: %(limit)s}}
  a: {type: TestLeak, period: 1 ms, params: {a: 0.99, b: 0.5, width: 2, x0: 1.0}}
  k: {type: TestScale, params: {k: -0.5}}
connections: [a.y -> z.u, a.y -> k.u, {from: k.y, to: a.u, delay: 1, initial: 0.25}]
log: [{signal: z.sum, decimate: 7}, a.y, a.sum, k.y, s.y]
"""


@pytest.mark.parametrize("limit, stop", [(1e9, 1000), (0.8, 1000), (1e9, 13)], ids=["complete", "failed", "ended"])
def test_a_packed_table_runs_in_plain_c_as_in_the_python_process(run_table, tmp_path, limit, stop):
    diagram = loads_diagram(FUSED % {"limit": limit, "stop": stop}, filename="fused.yaml")
    (status, end, reached, op, tick, code, end_op, end_asked), rows, table = run_in_c(run_table, diagram, tmp_path)
    results = simulate(diagram)
    assert list(rows) == sorted(results, key=list(table.names.logs).index)
    for signal in rows:
        assert np.array_equal(rows[signal], results[signal][1]), signal
    tick_s = 0.25e-3  # the base tick
    if limit < 1:
        assert status == 1 and code == 7 and results.status.startswith(f"failed at t={tick * tick_s:.9g} s")
        assert tick * tick_s == pytest.approx(results["z.sum"][0][-1] + 0.25e-3, abs=7 * tick_s)
    elif stop < 100:  # the 13th update, at 24 ms, asks; the stopper's next hit, 26 ms, ends the run
        assert status == 0 and (end_asked, end) == (96, 104) and results.ended_by["time"] == pytest.approx(0.026)
    else:
        assert status == 0 and end == table.n_ticks == 800 and end_op == -1 and results.complete


def test_a_damaged_table_is_refused_with_what_is_wrong(run_table, tmp_path):
    diagram = loads_diagram(FUSED % {"limit": 1e9, "stop": 1000}, filename="fused.yaml")
    packed = op_table(diagram, build_schedule(diagram, diagram.t_end)).pack()
    (tmp_path / "spec").write_text("")
    for damaged, message in [(packed[:-8], "arena values do not fill its end"),
                             (packed[:16] + (10**6).to_bytes(8, "little") + packed[24:], "wrong size"),
                             (b"x" * 8 + packed[8:], "not a packed op table")]:
        (tmp_path / "table").write_bytes(damaged)
        done = subprocess.run([str(run_table), str(tmp_path / "table"), str(tmp_path / "spec"), str(tmp_path / "out")],
                              capture_output=True, text=True, check=False)
        assert done.returncode == 1 and message in done.stderr, done.stderr
