"""The ``hierhand`` command as pip installs it from a wheel: with ``--prefix``, with
``--user`` and into a fresh virtual environment, its console script runs the installed
copy with the interpreter that installed it, and Ctrl-C stops it as it stops
``python -m hierhand``.

One wheel is built per session, from a copy of the source tree, so that nothing a previous
build left in ``build/`` ends up in it. The copy keeps the extensions and FMU binaries that
the editable install compiled in the tree (with their times), which the build reuses while
they are newer than their sources, as it does for ``pip wheel .``: the wheel then costs no
C compile. The installs take
no dependencies (``--no-deps``): they come from this test's own environment, put on the
installed command's module path after the installed copy.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from blocks import Results, load_diagram, simulate
from tests.blocks.cli.test_cli import LONG_DIAGRAM as LONG

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"),
                                reason="an install's bin/ layout and POSIX signals")

REPO = Path(__file__).resolve().parents[1]
HOOK = REPO / "tests" / "blocks" / "cli" / "signal_hook"
NOT_SOURCES = shutil.ignore_patterns(".git", "build", "dist", "runs", "*.egg-info", "__pycache__",
                                     ".pytest_cache", ".hypothesis", "*.fmu", ".whl", ".gl")
"""What a copy of the tree for the build leaves out: build folders and caches (.gitignore's),
but not the in-tree builds (``*.so``) that the build reuses while current."""


def quiet_pip(*args: str | Path, runner: list[str | Path] | None = None, env: dict[str, str] | None = None) -> None:
    """pip (``python -m pip`` unless ``runner`` says how to run it) with ``args``, offline and
    without questions, ``env`` added to this environment; the error in the assert if it fails."""
    env = dict(os.environ, PIP_NO_INDEX="1", PIP_DISABLE_PIP_VERSION_CHECK="1", PIP_NO_INPUT="1", **(env or {}))
    env.pop("PYTHONPATH", None)
    argv = [str(a) for a in [*(runner or [sys.executable, "-m", "pip"]), *args]]
    done = subprocess.run(argv, env=env, capture_output=True, text=True, timeout=900)
    assert done.returncode == 0, done.stdout + done.stderr


def usable(argv: list[str]) -> str | None:
    """None if ``argv`` runs and exits 0, else why not (for a skip's reason)."""
    try:
        done = subprocess.run(argv, capture_output=True, text=True, timeout=120)
    except OSError as exc:
        return str(exc)
    return None if done.returncode == 0 else (done.stderr.strip().splitlines() or [f"exit {done.returncode}"])[-1]


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    why = usable([sys.executable, "-m", "pip", "--version"])
    if why:
        pytest.skip(f"pip is not usable with {sys.executable} ({why}): the install tests need it")
    work = tmp_path_factory.mktemp("wheel")
    source = work / "source"
    shutil.copytree(REPO, source, ignore=NOT_SOURCES, symlinks=True)
    quiet_pip("wheel", "--no-deps", "--no-build-isolation", "-w", work / "dist", source)
    (built,) = (work / "dist").glob("hierhand-*.whl")
    return built


def dependencies() -> list[str]:
    """This environment's module path, the repository's own folders excepted: where the
    installed command finds numpy and the rest."""
    return [p for p in sys.path if p and Path(p).is_dir() and Path(p).resolve() != REPO
            and not Path(p).resolve().is_relative_to(REPO / "tests")]


def site_of(root: Path) -> Path:
    """The folder under ``root`` into which pip installed the packages."""
    (init,) = root.rglob("hierhand/__init__.py")
    return init.parent.parent


def command_env(home: Path, path: list[str | Path], **more: str) -> dict[str, str]:
    """This environment with a home of the test's own, ``path`` (if any) as PYTHONPATH and ``more``."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONUSERBASE")}
    env.update(HOME=str(home), **more)
    if path:
        env["PYTHONPATH"] = os.pathsep.join(map(str, path))
    return env


def run(argv: list[str | Path], env: dict[str, str], cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([str(a) for a in argv], env=env, cwd=cwd, capture_output=True, text=True, timeout=300)


def assert_runs_the_installed_copy(command: Path, python: str | Path, site: Path, env: dict[str, str],
                                   work: Path) -> None:
    """``command --version`` and ``command run`` of the toy diagram the wheel ships: both
    exit 0, run the copy in ``site`` with ``python``, the interpreter that installed it, and
    the run writes the results this tree computes; a ``yaml.py`` in the working folder is
    not imported instead of PyYAML."""
    version = run([command, "--version"], env, work)
    assert version.returncode == 0, version.stderr
    assert version.stdout.split() == ["hierhand", _wheel_version(site)]
    assert str(python) in "".join(command.read_text(encoding="utf-8").splitlines()[:2])  # its #! line(s)
    where = run([python, "-c", "import blocks, hierhand; print(blocks.__file__); print(hierhand.__file__)"],
                env, work)
    assert [Path(p).parent.parent for p in where.stdout.split()] == [site, site], where.stderr
    (work / "yaml.py").write_text("raise ImportError('the working folder was on the module path')\n")
    done = run([command, "run", site / "hierhand" / "diagrams" / "toy.yaml", "-o", "out"], env, work)
    assert done.returncode == 0, done.stderr
    saved = Results.load(work / "out")
    assert saved.complete
    reference = simulate(load_diagram(REPO / "diagrams" / "toy.yaml"))
    for got, want in zip(saved["plant.y"], reference["plant.y"]):
        assert np.array_equal(got, want)


def _wheel_version(site: Path) -> str:
    (info,) = site.glob("hierhand-*.dist-info")
    return info.name.removeprefix("hierhand-").removesuffix(".dist-info")


def test_a_prefix_install_runs(wheel, tmp_path):
    """``pip install --prefix DIR``: the interpreter, not the command, is told where the
    packages are (PYTHONPATH), as that option's users do."""
    quiet_pip("install", "--no-deps", "--ignore-installed", "--prefix", tmp_path / "prefix", wheel)
    site = site_of(tmp_path / "prefix")
    env = command_env(tmp_path, [site, *dependencies()])
    assert_runs_the_installed_copy(tmp_path / "prefix" / "bin" / "hierhand", sys.executable, site, env, tmp_path)


def test_a_user_install_runs(wheel, tmp_path):
    """``pip install --user`` (into a user base of the test's own). A virtual environment
    has no user site, so there the interpreter it was made from installs it."""
    python = sys.executable if sys.prefix == sys.base_prefix else getattr(sys, "_base_executable", sys.executable)
    why = usable([python, "-m", "pip", "--version"])
    if why:
        pytest.skip(f"pip is not usable with {python} ({why}), which a --user install needs")
    base = tmp_path / "userbase"
    user = {"HOME": str(tmp_path), "PYTHONUSERBASE": str(base)}
    quiet_pip("install", "--no-deps", "--ignore-installed", "--user", wheel, runner=[python, "-m", "pip"],
              env=dict(user, PIP_BREAK_SYSTEM_PACKAGES="1"))  # only the test's user base is written
    site = site_of(base)
    env = command_env(tmp_path, [site, *dependencies()], PYTHONUSERBASE=str(base))
    assert_runs_the_installed_copy(base / "bin" / "hierhand", python, site, env, tmp_path)


@pytest.fixture(scope="module")
def venv(wheel, tmp_path_factory) -> Path:
    """A fresh virtual environment with the wheel installed, which sees this environment's
    packages through a .pth file (after its own)."""
    root = tmp_path_factory.mktemp("venv") / "env"
    why = usable([sys.executable, "-m", "venv", "--without-pip", str(root)])
    if why:
        pytest.skip(f"venv is not usable with {sys.executable} ({why})")
    import pip  # usable: the wheel's fixture checked

    # this environment's pip, run by the new environment's interpreter, installs into that one
    quiet_pip("install", "--no-deps", "--ignore-installed", wheel,
              runner=[root / "bin" / "python", Path(pip.__file__).parent])
    site = site_of(root)
    (site / "test-dependencies.pth").write_text("".join(f"{p}\n" for p in dependencies()), encoding="utf-8")
    return root


def test_a_virtual_environment_install_runs(venv, tmp_path):
    env = command_env(tmp_path, [])
    assert_runs_the_installed_copy(venv / "bin" / "hierhand", venv / "bin" / "python", site_of(venv), env, tmp_path)


def interrupted(venv: Path, tmp_path: Path, at: str, call: int = 1) -> subprocess.CompletedProcess:
    """The installed command running the long diagram, sent SIGINT by itself at ``at``
    (``signal_hook``; the ``call``-th call there), so no timing decides where it lands."""
    (tmp_path / "long.yaml").write_text(LONG, encoding="utf-8")
    env = command_env(tmp_path, [HOOK], SIGNAL_AT=at, SIGNAL_SEND="SIGINT", SIGNAL_CALL=str(call))
    proc = run([venv / "bin" / "hierhand", "run", "long.yaml", "-o", "out"], env, tmp_path)
    assert "Traceback" not in proc.stderr, proc.stderr
    return proc


def test_ctrl_c_while_the_command_imports_is_one_line_and_130(venv, tmp_path):
    proc = interrupted(venv, tmp_path, "import:numpy")
    assert (proc.returncode, proc.stderr) == (130, "hierhand: interrupted\n")
    assert not (tmp_path / "out").exists()


def test_ctrl_c_while_the_command_runs_a_diagram_saves_it_and_exits_130(venv, tmp_path):
    proc = interrupted(venv, tmp_path, "blocks.cli.run:ProgressBar.__call__", call=2)
    assert proc.returncode == 130, proc.stderr
    assert all(line.startswith("hierhand: ") for line in proc.stderr.splitlines()), proc.stderr
    saved = Results.load(tmp_path / "out")
    assert saved.interrupted and saved.status.endswith("by SIGINT")
    t, y = saved["ramp.y"]
    assert len(t) > 0
    np.testing.assert_allclose(y[:, 0], t)  # a ramp of slope 1, up to where it stopped
