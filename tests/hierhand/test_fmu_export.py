"""The hand plant exported as a native FMU (FMI 2 and 3).

The FMU's binary is the plant's C core with an FMI wrapper: it must pass ``fmpy validate``,
step exactly as ``HandPlant`` does, run in a C host without Python, rebuild from its own
sources, rewind through get/set FMU state, and report bad parameters, rejected steps and a
numerical blow-up through the host's logger without crashing the host.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
import textwrap
import zipfile
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.validation import validate_fmu

from hierhand.fmu_export import FmuExportError, default_output_path, export_plant_fmu
from hierhand.model import Hand, HandPlant
from tests.blocks.fmu_export.slave import Slave as SteppedSlave

STEP = 1e-3  # communication step: 10 plant steps of 0.1 ms
N_STEPS = 50  # 50 ms
Q = [f"q[{i}]" for i in range(1, 10)]
OBJ = [f"obj[{i}]" for i in range(1, 4)]
REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def fmus(tmp_path_factory):
    """The default hand exported for FMI 2 and FMI 3."""
    folder = tmp_path_factory.mktemp("fmus")
    return {fmi: export_plant_fmu(folder / f"plant{fmi}.fmu", fmi=fmi) for fmi in (2, 3)}


def native(hand: dict | None = None, f_ext=(0.0, 0.0, 0.0), n_steps: int = N_STEPS) -> dict[str, np.ndarray]:
    """q and obj of the native block at 0, 1, ..., n_steps ms: advance 10 steps per ms, zero torques."""
    plant = HandPlant(**(hand or {}))
    plant.bind(Fraction(1, 10000))
    state = plant.initial_state()
    inputs = {"tau": np.zeros(9), "f_ext": np.array(f_ext, dtype=float)}
    first = plant.output(0.0, state, inputs)
    rows = {"q": [first["q"].copy()], "obj": [first["obj"].copy()]}
    for k in range(n_steps):
        state, out = plant.advance(k * STEP, state, inputs, 10)
        for port, values in rows.items():
            values.append(out[port][-1].copy())
    return {port: np.array(r) for port, r in rows.items()}


def simulate_in(folder: Path, fmu: Path, **options):
    """``fmpy.simulate_fmu`` on the FMU unpacked into ``folder`` (a pytest tmp_path).

    Given the .fmu file, fmpy unpacks it into a fresh folder in the system temp and removes
    that only when the simulation returns: a failing FMU or test left a 1 MB copy of the
    binaries in /tmp. Given a folder, fmpy unpacks nothing.
    """
    return simulate_fmu(extract(str(fmu), folder / "simulated"), **options)


def columns(result, names) -> np.ndarray:
    return np.column_stack([result[name] for name in names])


def heavy_hand() -> dict:
    """The default hand with a heavier object, whose inertia follows its mass (the FMU's
    ``object.mass`` set alone does the same)."""
    return {"object": {"mass": 0.6}}


def heavy_hand_fixed_inertia() -> dict:
    hand = Hand.default().params.to_dict()
    hand["object"]["mass"] = 0.6
    return hand


class Slave(SteppedSlave):
    """An instance of a plant FMU, stepped by STEP unless told otherwise."""

    def step(self, t: float, h: float = STEP):
        return super().step(t, h)


@pytest.mark.parametrize("fmi", [2, 3])
def test_fmu_is_valid_and_declares_the_plant(fmus, fmi):
    path = fmus[fmi]
    assert validate_fmu(str(path)) == []
    md = read_model_description(str(path))
    assert md.fmiVersion.startswith(str(fmi))
    identifier = md.coSimulation.modelIdentifier
    assert identifier.startswith("HandPlant_")
    by_causality: dict[str, list[str]] = {}
    for v in md.modelVariables:
        by_causality.setdefault(v.causality, []).append(v.name)
    assert by_causality["input"] == [f"tau[{i}]" for i in range(1, 10)] + [f"f_ext[{i}]" for i in range(1, 4)]
    expected = [f"{port}[{i}]" for port, width in HandPlant().outputs.items() for i in range(1, width + 1)]
    assert by_causality["output"] == expected
    params = set(by_causality["parameter"])
    assert len(params) == len(Hand.default().vector) == 100
    for name in ("gravity[2]", "object.mass", "object.inertia", "contact.mu_s", "contact.k_n",
                 "fingers[1].links[1].mass", "fingers[3].q0[3]", "fingers[2].tip_radius"):
        assert name in params
    mass = next(v for v in md.modelVariables if v.name == "object.mass")
    assert float(mass.start) == 0.3 and mass.variability == "fixed"
    declared = {v.name: v for v in md.modelVariables}
    assert (mass.min, mass.max) == ("0.0", None)  # the hand file's check: > 0
    assert declared["contact.mu_s"].min == "0.0" and declared["gravity[2]"].min is None  # >= 0; any number
    units = {v.name: v.unit for v in md.modelVariables}
    assert (units["tau[1]"], units["q[1]"], units["qd[1]"], units["fn[1]"], units["object.mass"]) == (
        "N m", "rad", "rad/s", "N", "kg")
    assert "element fore.1" in next(v for v in md.modelVariables if v.name == "q[4]").description
    newton = next(u for u in md.unitDefinitions if u.name == "N").baseUnit
    assert (newton.kg, newton.m, newton.s) == (1, 1, -2)
    outputs = [v for v in md.modelVariables if v.causality == "output"]
    assert all(v.initial == "calculated" for v in outputs)
    assert {v.variability for v in outputs} == {"continuous"}  # samples of the integrated plant
    assert all(u.dependencies == [] for u in md.outputs)  # no direct feedthrough
    # initial outputs depend on parameters only: an importer need not compute inputs first
    assert {u.variable.name for u in md.initialUnknowns} == {v.name for v in outputs}
    assert all({d.causality for d in u.dependencies} == {"parameter"} for u in md.initialUnknowns)
    assert md.coSimulation.canGetAndSetFMUstate and md.coSimulation.canSerializeFMUstate
    with zipfile.ZipFile(path) as archive:
        names = set(archive.namelist())
    folder = "linux64" if fmi == 2 else "x86_64-linux"
    assert f"binaries/{folder}/{identifier}.so" in names
    assert {"sources/plant.c", "sources/hand.h", "sources/core.c", "sources/kernel_types.c", "sources/layouts.h",
            "sources/joint_low_pass.c", f"sources/export_fmi{fmi}.c", "resources/diagram.bin"} <= names
    assert ("sources/buildDescription.xml" in names) == (fmi == 3)
    listed = md.buildConfigurations[0].sourceFileSets[0].sourceFiles
    assert all(f"sources/{name}" in names for name in listed) and "plant.c" in listed


@pytest.mark.parametrize("fmi", [2, 3])
def test_fmu_steps_exactly_as_the_native_block(fmus, fmi, tmp_path):
    ref = native()
    result = simulate_in(tmp_path, fmus[fmi], stop_time=N_STEPS * STEP, output_interval=STEP, output=Q + OBJ)
    assert np.allclose(result["time"], np.arange(N_STEPS + 1) * STEP, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(columns(result, Q), ref["q"])
    np.testing.assert_array_equal(columns(result, OBJ), ref["obj"])
    assert np.abs(ref["q"][-1] - ref["q"][0]).max() > 1e-3  # the hand did move (it sags)


def test_parameters_and_inputs_are_applied(fmus, tmp_path):
    ref = native(heavy_hand(), f_ext=(0.5, 0.0, 0.0), n_steps=20)
    result = simulate_in(tmp_path, fmus[3], stop_time=20 * STEP, output_interval=STEP, output=Q + OBJ,
                          start_values={"object.mass": 0.6, "f_ext[1]": 0.5})
    np.testing.assert_array_equal(columns(result, OBJ), ref["obj"])
    np.testing.assert_array_equal(columns(result, Q), ref["q"])


def test_a_failing_simulation_leaves_nothing_in_the_system_temp(fmus, tmp_path, monkeypatch):
    system_temp = tmp_path / "system-temp"
    system_temp.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(system_temp))
    with pytest.raises(Exception, match="ExitInitializationMode"):
        simulate_in(tmp_path, fmus[2], stop_time=STEP, start_values={"object.mass": -1.0})
    assert list(system_temp.iterdir()) == []


@pytest.mark.parametrize("fmi", [2, 3])
def test_invalid_parameters_are_logged_and_fail_initialization(fmus, fmi, tmp_path):
    slave = Slave(fmus[fmi], tmp_path)
    try:
        slave.set(contact__mu_d=2.0, object__mass=-1.0)
        slave.fmu.enterInitializationMode()
        with pytest.raises(Exception, match="ExitInitializationMode"):
            slave.fmu.exitInitializationMode()
        assert slave.errors() == ["invalid parameter: object.mass must be > 0, got -1"]
    finally:
        slave.close()


@pytest.mark.parametrize("fmi", [2, 3])
def test_events_are_logged_only_when_logging_is_on(fmus, fmi, tmp_path):
    quiet, chatty = Slave(fmus[fmi], tmp_path / "quiet"), Slave(fmus[fmi], tmp_path / "chatty", logging_on=True)
    try:
        for slave in (quiet, chatty):
            slave.initialize()
        assert quiet.messages == []
        assert [(status, category) for status, category, _ in chatty.messages] == [(0, "logEvents")] * 2
        assert chatty.messages[1][2].startswith("initialized: 1 block")
        with pytest.raises(Exception, match="SetDebugLogging"):
            chatty.fmu.setDebugLogging(True, ["logEverything"])
        assert "unknown log category 'logEverything'" in chatty.errors()[0]
        chatty.fmu.setDebugLogging(False, [])
        chatty.messages.clear()
        chatty.step(0.0)
        assert chatty.messages == []
    finally:
        quiet.close()
        chatty.close()


@pytest.mark.parametrize("fmi", [2, 3])
def test_parameters_are_fixed_once_initialized(fmus, fmi, tmp_path):
    slave = Slave(fmus[fmi], tmp_path)
    try:
        slave.initialize()
        with pytest.raises(Exception, match="Set"):
            slave.set(object__mass=0.5)
        assert "object.mass can only be set before initialization ends" in slave.errors()[0]
        assert slave.get(["object.mass"])[0] == 0.3
    finally:
        slave.close()


@pytest.mark.parametrize("fmi", [2, 3])
def test_a_numerical_blow_up_is_an_error_status_not_a_crash(fmus, fmi, tmp_path):
    slave = Slave(fmus[fmi], tmp_path)
    try:
        slave.initialize()
        slave.step(0.0)
        slave.set(**{"f_ext[2]": 1e308})  # finite, but f / m overflows: the object's velocity becomes inf
        with pytest.raises(Exception, match="DoStep"):
            slave.step(STEP)
        # the same time HandPlant gives: the step that failed starts at t = 1 ms (the bad state is 0.1 ms later)
        assert slave.errors() == [
            "non-finite value in the step at t=0.001 s: object velocity obj_vel[2] (vy) is not finite"]
        with pytest.raises(Exception, match="DoStep"):  # a failed instance stays failed
            slave.step(20 * STEP)
    finally:
        slave.close()


@pytest.mark.parametrize("fmi", [2, 3])
def test_long_communication_steps_land_where_short_ones_do(fmus, fmi, tmp_path):
    """A step of 25 ms is 250 plant steps, more than one advance call of the FMU takes:
    it gives the native plant's samples as 25 steps of 1 ms do."""
    slave = Slave(fmus[fmi], tmp_path)
    try:
        slave.set(**{"f_ext[1]": 0.5})
        slave.initialize()
        rows = []
        for k in range(2):
            slave.step(k * 0.025, 0.025)
            rows.append(slave.get(Q + OBJ))
    finally:
        slave.close()
    ref = native(f_ext=(0.5, 0.0, 0.0), n_steps=50)
    got = np.array(rows)
    np.testing.assert_array_equal(got[:, :9], ref["q"][[25, 50]])
    np.testing.assert_array_equal(got[:, 9:], ref["obj"][[25, 50]])


@pytest.mark.parametrize("fmi", [2, 3])
def test_a_step_off_the_internal_step_holds_the_last_internal_steps_outputs(fmus, fmi, tmp_path):
    """The export declares its internal step (fixedInternalStepSize, informative), and takes
    any communication step: 0.15 ms steps land on the plant's 0.1 ms samples at or before
    each communication point (OMSimulator steps every FMU at the smallest step of all)."""
    short = simulate_in(tmp_path, fmus[fmi], stop_time=2 * STEP, output_interval=5e-4, output=["q[1]"])
    assert len(short) == 5  # 0.5 ms is 5 internal steps
    slave = Slave(fmus[fmi], tmp_path)
    try:
        slave.set(**{"f_ext[1]": 0.5})
        slave.initialize()
        rows = []
        for k in range(4):
            slave.step(k * 1.5e-4, 1.5e-4)
            rows.append(slave.get(Q))
    finally:
        slave.close()
    plant = HandPlant()
    plant.bind(Fraction(1, 10000))
    state, inputs = plant.initial_state(), {"tau": np.zeros(9), "f_ext": np.array([0.5, 0.0, 0.0])}
    samples = []
    for k in range(6):
        state, out = plant.advance(k * 1e-4, state, inputs, 1)
        samples.append(out["q"][-1].copy())
    np.testing.assert_array_equal(np.array(rows), np.array(samples)[[0, 2, 3, 5]])  # 0.1, 0.3, 0.4, 0.6 ms


def test_several_instances_and_exports_run_side_by_side_in_one_process(fmus, tmp_path):
    hand_file = tmp_path / "heavy.yaml"
    hand_file.write_text("object: {mass: 0.6, inertia: 1.25e-4}\n")
    heavy = export_plant_fmu(tmp_path, fmi=2, hand=hand_file)
    assert heavy == tmp_path / "HandPlant_fmi2.fmu"
    ids = {read_model_description(str(p)).coSimulation.modelIdentifier for p in (fmus[2], heavy)}
    assert len(ids) == 2
    slaves = {"light": Slave(fmus[2], tmp_path / "light", "light"),
              "light again": Slave(fmus[2], tmp_path / "light2", "light again"),
              "heavy": Slave(heavy, tmp_path / "heavy", "heavy"),
              "light fmi3": Slave(fmus[3], tmp_path / "light3", "light fmi3")}
    push = {"light": 0.5, "light again": 0.25, "heavy": 0.5, "light fmi3": 0.5}
    hand = {"light": None, "light again": None, "heavy": heavy_hand_fixed_inertia(), "light fmi3": None}
    rows = {key: [] for key in slaves}
    try:
        for key, slave in slaves.items():
            slave.set(**{"f_ext[1]": push[key]})
            slave.initialize()
        for k in range(20):
            for key, slave in slaves.items():  # interleaved: all instances alive
                slave.step(k * STEP)
                rows[key].append(slave.get(Q + OBJ))
        masses = {key: slave.get(["object.mass"])[0] for key, slave in slaves.items()}
    finally:
        for slave in slaves.values():
            slave.close()
    assert masses == {"light": 0.3, "light again": 0.3, "heavy": 0.6, "light fmi3": 0.3}
    for key in slaves:
        ref = native(hand[key], f_ext=(push[key], 0.0, 0.0), n_steps=20)
        got = np.array(rows[key])
        np.testing.assert_array_equal(got[:, :9], ref["q"][1:])
        np.testing.assert_array_equal(got[:, 9:], ref["obj"][1:])


@pytest.mark.parametrize("fmi", [2, 3])
def test_get_and_set_state_rewinds_a_run_exactly(fmus, fmi, tmp_path):
    slave = Slave(fmus[fmi], tmp_path)
    names = Q + OBJ + ["fn[1]", "fn[2]", "ratio[1]"]

    def run(k0: int, n: int) -> np.ndarray:
        out = []
        for k in range(k0, k0 + n):
            slave.step(k * STEP)
            out.append(slave.get(names))
        return np.array(out)

    try:
        slave.set(**{"f_ext[1]": 0.3})
        slave.initialize()
        run(0, 20)
        saved = slave.fmu.getFMUState()
        first = run(20, 30)
        slave.set(**{"f_ext[1]": -0.7})  # perturb, then rewind: inputs are part of the state
        run(50, 5)
        slave.fmu.setFMUState(saved)
        np.testing.assert_array_equal(run(20, 30), first)
        restored = slave.serialized_copy(saved)
        slave.fmu.setFMUState(restored)
        np.testing.assert_array_equal(run(20, 30), first)
        assert np.abs(first[-1] - first[0]).max() > 1e-4  # the rewound stretch did move
        slave.free_states(saved, restored)
    finally:
        slave.close()


def _nm(args: list[str], library: Path) -> str:
    tool = shutil.which(args[0])
    if tool is None:
        pytest.skip(f"{args[0]} is not installed")
    return subprocess.run([tool, *args[1:], str(library)], capture_output=True, text=True, check=True).stdout


@pytest.mark.parametrize("fmi", [2, 3])
def test_the_binary_needs_no_python(fmus, fmi, tmp_path):
    md = read_model_description(str(fmus[fmi]))
    folder = Path(extract(str(fmus[fmi]), tmp_path))
    library = next(folder.glob(f"binaries/*/{md.coSimulation.modelIdentifier}.so"))
    needed = [line.split("[")[1].rstrip("]") for line in _nm(["readelf", "-d"], library).splitlines()
              if "(NEEDED)" in line]
    assert needed and not any("python" in lib for lib in needed), needed
    assert set(needed) <= {"libm.so.6", "libc.so.6"}, needed
    undefined = _nm(["nm", "-D", "--undefined-only"], library).split()
    assert not [s for s in undefined if s.startswith(("Py", "_Py"))]
    exported = [line.split()[-1] for line in _nm(["nm", "-D", "--defined-only"], library).splitlines()]
    assert exported and all(s.startswith(f"fmi{fmi}") for s in exported if s[0].isalpha()), exported


def test_a_c_host_without_python_runs_the_fmu(fmus, c_host, tmp_path):
    md = read_model_description(str(fmus[2]))
    folder = Path(extract(str(fmus[2]), tmp_path))
    library = next(folder.glob(f"binaries/*/{md.coSimulation.modelIdentifier}.so"))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    wanted = ",".join(str(vr[n]) for n in Q + OBJ)
    env = {"PATH": "/usr/bin:/bin"}  # no PYTHONHOME, PYTHONPATH, LD_PRELOAD: nothing of Python
    done = subprocess.run([str(c_host), str(library), md.guid, (folder / "resources").as_uri(), repr(STEP),
                           str(N_STEPS), wanted, f"{vr['object.mass']}=0.6", f"{vr['f_ext[1]']}=0.5"],
                          capture_output=True, text=True, env=env, timeout=60)
    assert done.returncode == 0, done.stderr
    rows = np.array([[float(x) for x in line.split()] for line in done.stdout.splitlines()])
    ref = native(heavy_hand(), f_ext=(0.5, 0.0, 0.0))
    np.testing.assert_array_equal(rows[:, 0], np.arange(N_STEPS + 1) * STEP)
    np.testing.assert_array_equal(rows[:, 1:10], ref["q"])
    np.testing.assert_array_equal(rows[:, 10:], ref["obj"])


def test_the_c_host_sees_bad_parameters_as_a_logged_error(fmus, c_host, tmp_path):
    md = read_model_description(str(fmus[2]))
    folder = Path(extract(str(fmus[2]), tmp_path))
    library = next(folder.glob(f"binaries/*/{md.coSimulation.modelIdentifier}.so"))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    done = subprocess.run([str(c_host), str(library), md.guid, (folder / "resources").as_uri(), repr(STEP), "3",
                           str(vr["q[1]"]), f"{vr['object.mass']}=-1"], capture_output=True, text=True, timeout=60)
    assert done.returncode == 1  # the host's own exit after fmi2Error, not a signal
    assert "[3] host logStatusError: invalid parameter: object.mass must be > 0, got -1" in done.stderr
    wrong = subprocess.run([str(c_host), str(library), "{not-this-fmu}", (folder / "resources").as_uri(),
                            repr(STEP), "1", "1"], capture_output=True, text=True, timeout=60)
    assert wrong.returncode == 1 and "instantiation token" in wrong.stderr


@pytest.mark.parametrize("fmi", [2, 3])
def test_an_fmu_rebuilt_from_its_sources_gives_the_same_results(fmus, fmi, tmp_path):
    """As an importer on another platform would: drop the binary, build from sources/ (fmpy
    compiles with CMake from the SourceFiles / buildDescription.xml), run."""
    from fmpy.build import build_platform_binary

    if shutil.which("cmake") is None:
        pytest.skip("cmake is not installed")
    unzipped = tmp_path / "unzipped"
    extract(str(fmus[fmi]), unzipped)
    shutil.rmtree(unzipped / "binaries")
    (tmp_path / "build").mkdir()
    build_platform_binary(unzipped, build_dir=tmp_path / "build")
    rebuilt = list((unzipped / "binaries").glob("*/*.so"))
    assert len(rebuilt) == 1
    result = simulate_fmu(str(unzipped), stop_time=N_STEPS * STEP, output_interval=STEP, output=Q + OBJ)
    ref = native()
    np.testing.assert_array_equal(columns(result, Q), ref["q"])
    np.testing.assert_array_equal(columns(result, OBJ), ref["obj"])


@pytest.mark.parametrize("fmi", [2, 3])
def test_round_trip_through_the_fmu_import_block(fmus, fmi):
    from blocks import loads_diagram, simulate

    diagram = loads_diagram(textwrap.dedent(f"""
        name: round_trip
        time: {{t_end: 50 ms}}
        blocks:
          fmu: {{type: FMU, period: 1 ms, params: {{path: "{fmus[fmi]}", start_values: {{object.mass: 0.6}}}}}}
          native: {{type: HandPlant, period: 0.1 ms, params: {{object: {{mass: 0.6}}}}}}
          tau: {{type: Constant, params: {{value: [0, 0, 0, 0, 0, 0, 0, 0, 0]}}}}
          push: {{type: Constant, params: {{value: [0.5, 0, 0]}}}}
        connections:
          - tau.y -> fmu.tau
          - tau.y -> native.tau
          - push.y -> fmu.f_ext
          - push.y -> native.f_ext
        log:
          - {{signal: fmu.q}}
          - {{signal: fmu.obj}}
          - {{signal: native.q, decimate: 10}}
          - {{signal: native.obj, decimate: 10}}
        """))
    results = simulate(diagram)
    again = simulate(diagram)  # the pooled FMU instance is reset and runs again
    for port in ("q", "obj"):
        t, fmu_values = results[f"fmu.{port}"]
        t_native, native_values = results[f"native.{port}"]
        assert len(t) == N_STEPS + 1 and np.allclose(t, t_native[: len(t)])
        np.testing.assert_array_equal(fmu_values, native_values[: len(t)])
        np.testing.assert_array_equal(again[f"fmu.{port}"][1], fmu_values)


def test_default_output_path():
    assert default_output_path(2) == Path("fmu") / "HandPlant_fmi2.fmu"
    assert default_output_path(3) == Path("fmu") / "HandPlant_fmi3.fmu"
    with pytest.raises(ValueError, match="fmi"):
        export_plant_fmu(fmi=1)


def test_equal_exports_are_equal_files(fmus, tmp_path):
    again = export_plant_fmu(tmp_path / "again.fmu", fmi=2)
    assert again.read_bytes() == fmus[2].read_bytes()


def test_an_installed_package_exports_without_the_repository_or_a_compiler(tmp_path, fmus):
    """Only the package folders, as an install has them (with the extension and the FMU
    libraries), another working folder and no compiler on PATH: the export lands in ./fmu/
    and is the same FMU as from here."""
    site, work = tmp_path / "site", tmp_path / "work"
    for package in ("blocks", "hierhand"):
        shutil.copytree(REPO / package, site / package, ignore=shutil.ignore_patterns("__pycache__"))
    work.mkdir()
    script = ("import hierhand, sys; from hierhand.fmu_export import export_plant_fmu; "
              "print(hierhand.__file__); print(export_plant_fmu(fmi=2))")
    env = {**os.environ, "PYTHONPATH": str(site), "PATH": str(tmp_path / "no-compilers-here")}
    done = subprocess.run([sys.executable, "-c", script], cwd=work, env=env, capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stderr
    imported, written = done.stdout.split()
    assert Path(imported).resolve().is_relative_to(site.resolve())
    assert (work / written).resolve() == (work / "fmu" / "HandPlant_fmi2.fmu").resolve()
    assert (work / written).read_bytes() == fmus[2].read_bytes()


def test_a_missing_fmu_library_is_a_clear_error(monkeypatch, tmp_path):
    import hierhand.fmu_export as export

    monkeypatch.setattr(export, "PACKAGE_DIR", tmp_path / "nothing")
    with pytest.raises(FmuExportError, match="reinstall"):
        export.export_plant_fmu(tmp_path / "x.fmu", fmi=3)
    assert not (tmp_path / "x.fmu").exists()


def test_cli_reports_an_invalid_hand_file_in_one_line(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("object: {mass: -1}\n")
    done = subprocess.run([sys.executable, "-m", "hierhand", "fmu", "export", "--hand", str(bad), "-o",
                           str(tmp_path)], capture_output=True, text=True, timeout=120)
    assert done.returncode == 2
    assert done.stderr.strip() == f"{bad}:1: object.mass must be > 0, got -1"
    assert not list(tmp_path.glob("*.fmu"))


@pytest.mark.parametrize("fmi", [2, 3])
def test_regrasp_with_the_exported_plant_matches_the_native_run(fmus, native_regrasp, fmi):
    """diagrams/regrasp_fmu.yaml: the same task with the plant as an FMU, at 1 ms steps."""
    import blocks
    from hierhand.tasks.summaries import regrasp_events

    diagram = blocks.load_diagram(REPO / "diagrams" / "regrasp_fmu.yaml",
                                  overrides={"plant.path": str(fmus[fmi])})
    via_fmu = blocks.simulate(diagram)
    assert via_fmu.complete
    for signal in ("plant.q", "plant.obj", "plant.fn"):
        t_native, native_values = native_regrasp[signal]
        t_fmu, fmu_values = via_fmu[signal]
        np.testing.assert_array_equal(t_fmu, t_native)
        scale = np.maximum(np.abs(native_values), 1e-300)
        assert (np.abs(fmu_values - native_values) / scale).max() <= 1e-12, signal
    fmu_events, native_events = regrasp_events(via_fmu), regrasp_events(native_regrasp)
    assert fmu_events == native_events
    assert fmu_events["fore_separation_time_s"] is not None
