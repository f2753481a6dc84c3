"""Commands that start fast: hierhand's commands against Python's own start and numpy's import.

Each command runs as a fresh process, in turns with its baselines in the same loop of
runs: ``python -c pass`` for ``hierhand --version`` and ``--help`` (targets, issue 43: at
most 2x, and no numpy imported, which tests/hierhand/test_start_imports.py checks),
``python -c "import numpy"`` for ``hierhand run toy -o DIR -q`` (at most 2x). Prints the
medians of --repeat runs of each, in CPU time of the child (user + system, which a core
shared with other work does not inflate) and in wall time, and the ratios. Bytecode
caches are written and used, as an installed program's are (PYTHONDONTWRITEBYTECODE is
left out of the children's environment).

    python benchmarks/start.py [--repeat 11]
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

TARGET = 2.0


def hierhand() -> list[str]:
    """The hierhand console script beside this Python, else ``python -m hierhand``."""
    script = Path(sys.executable).with_name("hierhand")
    return [str(script)] if script.is_file() else [sys.executable, "-m", "hierhand"]


def timed(command: list[str], cwd: str, env: dict) -> tuple[float, float]:
    """(CPU seconds of the child, wall seconds) of one run of ``command``."""
    t0 = time.perf_counter()
    child = subprocess.Popen(command, cwd=cwd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _, status, usage = os.wait4(child.pid, 0)
    wall = time.perf_counter() - t0
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"{' '.join(command)} failed")
    return usage.ru_utime + usage.ru_stime, wall


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=11, help="runs of each command (median; at least 7)")
    args = parser.parse_args()
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "out")
        commands = {
            "python -c pass": [sys.executable, "-c", "pass"],
            "python -c 'import numpy'": [sys.executable, "-c", "import numpy"],
            "hierhand --version": [*hierhand(), "--version"],
            "hierhand --help": [*hierhand(), "--help"],
            "hierhand run toy -o DIR -q": [*hierhand(), "run", "toy", "-o", out, "-q"],
        }
        for command in commands.values():  # warm: bytecode caches, the page cache
            timed(command, tmp, env)
        runs: dict[str, list[tuple[float, float]]] = {name: [] for name in commands}
        for _ in range(args.repeat):
            for name, command in commands.items():
                runs[name].append(timed(command, tmp, env))
                shutil.rmtree(out, ignore_errors=True)
    cpu = {name: statistics.median(c for c, _ in r) for name, r in runs.items()}
    wall = {name: statistics.median(w for _, w in r) for name, r in runs.items()}
    baseline = {"hierhand --version": "python -c pass", "hierhand --help": "python -c pass",
                "hierhand run toy -o DIR -q": "python -c 'import numpy'"}
    print(f"medians of {args.repeat} fresh processes, each command in turn with its baselines; CPU time (wall time)")
    for name in commands:
        line = f"  {name:28s} {cpu[name] * 1e3:7.1f} ms ({wall[name] * 1e3:7.1f} ms)"
        if name in baseline:
            base = baseline[name]
            ratio = cpu[name] / cpu[base]
            line += (f"   {ratio:4.2f}x {base} ({wall[name] / wall[base]:4.2f}x wall)   target <= {TARGET:g}x: "
                     f"{'met' if ratio <= TARGET else 'NOT met'}")
        print(line)


if __name__ == "__main__":
    main()
