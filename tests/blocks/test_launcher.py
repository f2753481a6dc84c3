"""A command's executable (blocks/csrc/launcher.c): SIGINT and SIGTERM while Python starts
are the command's one line and exit code, and otherwise it is ``python -m`` of the command.

The installed ``hierhand`` (beside this interpreter) is the one tested where it is the
native launcher; copies built here with other interpreters to fall back to show how it
finds one and what it says when there is none. A signal that comes while the interpreter
starts is made deterministic by ``tests.blocked_start``: already pending, and blocked,
when the launcher starts, which is what such a signal is when the program's code first runs.
"""

from __future__ import annotations

import errno
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from blocks.engine import native_sources
from tests.blocked_start import blocked

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the launcher is built on Linux")

REPO = Path(__file__).resolve().parents[2]
TOY = REPO / "diagrams" / "toy.yaml"
INSTALLED = Path(sys.executable).parent / "hierhand"
HINT = "python3 -m hierhand runs the same command"
ENV = dict(os.environ, PYTHONPATH=str(REPO))
"""Both ways of running the command import this tree's packages."""


@pytest.fixture(scope="module")
def launcher() -> Path:
    if not INSTALLED.is_file() or INSTALLED.read_bytes()[:4] != b"\x7fELF":
        pytest.skip(f"{INSTALLED} is not the native launcher: this tree is not installed here (pip install -e .)")
    return INSTALLED


def run(argv: list, cwd: Path = REPO, env: dict | None = None) -> subprocess.CompletedProcess:
    return subprocess.run(argv, cwd=cwd, env=ENV if env is None else env, capture_output=True, text=True, timeout=120)


def build(folder: Path, python: str) -> Path:
    """A launcher of ``hierhand`` in ``folder`` that falls back to ``python``."""
    compiler = shutil.which(os.environ.get("CC", "")) or shutil.which("cc") or shutil.which("gcc")
    if compiler is None:
        pytest.skip("no C compiler to build a launcher")
    folder.mkdir(parents=True, exist_ok=True)
    macros = native_sources.launcher_macros("hierhand", "hierhand.start:main", python, HINT)
    target = folder / "hierhand"
    subprocess.run([compiler, *native_sources.CFLAGS, "-std=c99", "-Wextra", *(f"-D{k}={v}" for k, v in macros),
                    str(REPO / native_sources.CSRC / native_sources.LAUNCHER), "-o", str(target)],
                   check=True, capture_output=True)
    return target


@pytest.mark.parametrize("send, code", [("SIGINT", 130), ("SIGTERM", 143)])
def test_a_signal_while_python_starts_is_one_line_and_its_exit_code(launcher, send, code):
    proc = run(blocked([str(launcher), "validate", str(TOY)], pending=send))
    assert (proc.returncode, proc.stderr, proc.stdout) == (code, "hierhand: interrupted\n", "")


@pytest.mark.parametrize("argv", [["validate", "diagrams/toy.yaml"], ["--help"], ["--version"],
                                  ["validate", "no such.yaml"], ["run"]],
                         ids=["validate", "help", "version", "missing file", "usage error"])
def test_unsignalled_it_is_python_m_hierhand(launcher, argv):
    native, module = run([launcher, *argv]), run([sys.executable, "-m", "hierhand", *argv])
    assert (native.returncode, native.stdout, native.stderr) == (module.returncode, module.stdout, module.stderr)
    if argv == ["--help"]:
        assert native.stdout.startswith("usage: hierhand ")


def test_the_program_gets_its_arguments_as_given(launcher, tmp_path):
    """Spaces, non-ASCII and undecodable bytes, empty arguments and Python's own options."""
    hook = tmp_path / "hook"
    hook.mkdir()
    (hook / "sitecustomize.py").write_text(
        "import atexit, json, os, sys\n"
        f"atexit.register(lambda: open({str(tmp_path / 'argv.json')!r}, 'w').write("
        "json.dumps([os.fsencode(a).hex() for a in sys.argv])))\n")
    given = [b"validate", b"a b.yaml", "ü".encode(), b"\xff", b"", b"-P", b"-c", b"--"]
    run([bytes(launcher), *given], cwd=tmp_path, env=dict(ENV, PYTHONPATH=f"{hook}{os.pathsep}{REPO}"))
    seen = [bytes.fromhex(a) for a in json.loads((tmp_path / "argv.json").read_text())]
    assert seen == [bytes(launcher), *given]


def test_modules_in_the_working_folder_do_not_shadow_its_own(launcher, tmp_path):
    """Not even one named as the command's package, which ``python -m hierhand`` itself
    would import (``python -P -m`` does not)."""
    for name in ("numpy", "yaml", "blocks", "hierhand", "signal"):
        (tmp_path / f"{name}.py").write_text("raise RuntimeError('the working folder was imported')\n")
    shutil.copy(TOY, tmp_path / "toy.yaml")
    native = run([launcher, "validate", "toy.yaml"], cwd=tmp_path)
    module = run([sys.executable, "-P", "-m", "hierhand", "validate", "toy.yaml"], cwd=tmp_path)
    assert (native.returncode, native.stdout, native.stderr) == (0, module.stdout, "")


def test_a_link_to_it_runs_the_interpreter_beside_its_real_file(launcher, tmp_path):
    (tmp_path / "hierhand").symlink_to(launcher)
    proc = run([tmp_path / "hierhand", "validate", str(TOY)], cwd=tmp_path)
    assert proc.returncode == 0 and proc.stdout.startswith("diagram 'toy-multirate'"), proc.stderr


def fake_python(path: Path, record: Path) -> Path:
    """An interpreter that only records its arguments, and the signals blocked, in ``record``."""
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(f"#!{sys.executable}\nimport json, sys\n"
                    "blocked = [l.split()[1] for l in open('/proc/self/status') if l.startswith('SigBlk:')][0]\n"
                    f"json.dump({{'argv': sys.argv, 'blocked': blocked}}, open({str(record)!r}, 'w'))\n")
    path.chmod(0o755)
    return path


def test_it_runs_the_interpreter_beside_it_else_the_one_that_built_it(tmp_path):
    record = tmp_path / "record.json"
    built_with = fake_python(tmp_path / "build" / "python3", record)
    launcher = build(tmp_path / "bin", str(built_with))
    versioned = f"python{sys.version_info.major}.{sys.version_info.minor}"
    names = [versioned, "python3", "python"]
    for name in names:
        fake_python(launcher.parent / name, record)
    ran = []
    for name in [*names, None]:
        subprocess.run([launcher, "validate", "x y"], check=True, timeout=60)
        seen = json.loads(record.read_text())
        assert seen["argv"][1:3] == ["-P", "-c"] and seen["argv"][4:] == [str(launcher), "validate", "x y"]
        assert int(seen["blocked"], 16) & 0x4002 == 0x4002  # SIGINT and SIGTERM, as Python starts
        ran.append(Path(seen["argv"][0]).name if Path(seen["argv"][0]).parent == launcher.parent else "built with")
        if name is not None:
            (launcher.parent / name).unlink()
    assert ran == [versioned, "python3", "python", "built with"]


def test_without_an_interpreter_it_says_what_it_tried_and_exits_127(tmp_path):
    launcher = build(tmp_path / "bin", "/no/such/python3")
    proc = subprocess.run([launcher, "validate", str(TOY)], capture_output=True, text=True, timeout=60)
    missing = os.strerror(errno.ENOENT)
    tried = [f"{launcher.parent}/python{sys.version_info.major}.{sys.version_info.minor}",
             f"{launcher.parent}/python3", f"{launcher.parent}/python", "/no/such/python3"]
    assert (proc.returncode, proc.stdout) == (127, "")
    assert proc.stderr == f"hierhand: cannot start Python; tried {', '.join(f'{p} ({missing})' for p in tried)}; {HINT}\n"


def test_an_interpreter_it_cannot_run_is_named_and_exit_126(tmp_path):
    launcher = build(tmp_path / "bin", "/no/such/python3")
    (launcher.parent / "python3").write_text("not a program\n")  # not executable
    proc = subprocess.run([launcher], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 126
    assert f"{launcher.parent}/python3 ({os.strerror(errno.EACCES)})" in proc.stderr
    assert proc.stderr.count("\n") == 1 and proc.stderr.endswith(f"; {HINT}\n")
