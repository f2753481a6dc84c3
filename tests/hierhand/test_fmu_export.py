"""The hand plant exported as an FMU (FMI 2 and 3): valid, equal to the native block, self-contained.

Every FMU here compiles its bundled kernels with numba on first use (about 7 s). They all
carry the same model code, so they share one compilation: ``HIERHAND_FMU_CACHE`` points at a
folder of this module, where the FMUs keep the model sources and numba's cache, and the
subprocess that runs the FMUs without hierhand loads the kernels from it too.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import sysconfig
import textwrap
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

fmpy = pytest.importorskip("fmpy")
pytest.importorskip("pythonfmu")
pytest.importorskip("pythonfmu3")

from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi2 import FMU2Slave
from fmpy.validation import validate_fmu

from hierhand.fmu_export import default_output_path, export_plant_fmu
from hierhand.model import Hand, HandPlant

STEP = 1e-3  # communication step: 10 plant steps of 0.1 ms
N_STEPS = 50  # 50 ms
Q = [f"q[{i}]" for i in range(1, 10)]
OBJ = [f"obj[{i}]" for i in range(1, 4)]
TOL = 1e-9
REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module", autouse=True)
def fmu_cache(tmp_path_factory):
    path = tmp_path_factory.mktemp("fmu_cache")
    patch = pytest.MonkeyPatch()
    patch.setenv("HIERHAND_FMU_CACHE", str(path))
    yield path
    patch.undo()


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


def columns(result, names) -> np.ndarray:
    return np.column_stack([result[name] for name in names])


def heavy_hand() -> dict:
    hand = Hand.default().params.to_dict()
    hand["object"]["mass"] = 0.6
    return hand


@pytest.mark.parametrize("fmi", [2, 3])
def test_fmu_is_valid_and_declares_the_plant(fmus, fmi):
    path = fmus[fmi]
    assert validate_fmu(str(path)) == []
    md = read_model_description(str(path))
    assert md.fmiVersion.startswith(str(fmi))
    assert md.coSimulation.modelIdentifier.startswith("HandPlant_")
    by_causality: dict[str, list[str]] = {}
    for v in md.modelVariables:
        by_causality.setdefault(v.causality, []).append(v.name)
    assert by_causality["input"] == [f"tau[{i}]" for i in range(1, 10)] + [f"f_ext[{i}]" for i in range(1, 4)]
    expected = [f"{port}[{i}]" for port, width in HandPlant().outputs.items() for i in range(1, width + 1)]
    assert by_causality["output"] == expected
    params = set(by_causality["parameter"])
    for name in ("gravity[2]", "object.mass", "object.inertia", "contact.mu_s", "contact.k_n",
                 "fingers[1].links[1].mass", "fingers[3].q0[3]", "fingers[2].tip_radius"):
        assert name in params
    mass = next(v for v in md.modelVariables if v.name == "object.mass")
    assert float(mass.start) == 0.3 and mass.variability == "fixed"
    outputs = [v for v in md.modelVariables if v.causality == "output"]
    assert all(v.initial == "calculated" for v in outputs)
    assert all(u.dependencies == [] for u in md.outputs)  # no direct feedthrough


@pytest.mark.parametrize("fmi", [2, 3])
def test_fmu_matches_the_native_block(fmus, fmi):
    ref = native()
    result = simulate_fmu(str(fmus[fmi]), stop_time=N_STEPS * STEP, output_interval=STEP, output=Q + OBJ)
    assert np.allclose(result["time"], np.arange(N_STEPS + 1) * STEP, rtol=0, atol=1e-12)
    assert np.abs(columns(result, Q) - ref["q"]).max() <= TOL
    assert np.abs(columns(result, OBJ) - ref["obj"]).max() <= TOL
    assert np.abs(ref["q"][-1] - ref["q"][0]).max() > 1e-3  # the hand did move (it sags)


def test_parameters_and_inputs_are_applied(fmus):
    ref = native(heavy_hand(), f_ext=(0.5, 0.0, 0.0), n_steps=20)
    result = simulate_fmu(str(fmus[3]), stop_time=20 * STEP, output_interval=STEP, output=Q + OBJ,
                          start_values={"object.mass": 0.6, "f_ext[1]": 0.5})
    assert np.abs(columns(result, OBJ) - ref["obj"]).max() <= TOL
    assert np.abs(columns(result, Q) - ref["q"]).max() <= TOL


def test_invalid_parameters_fail_initialization(fmus):
    with pytest.raises(Exception, match="InitializationMode"):
        simulate_fmu(str(fmus[3]), stop_time=STEP, output_interval=STEP, start_values={"contact.mu_d": 2.0})


def test_communication_step_must_be_a_multiple_of_the_internal_step(fmus):
    short = simulate_fmu(str(fmus[2]), stop_time=2 * STEP, output_interval=5e-4, output=["q[1]"])
    assert len(short) == 5  # 0.5 ms is 5 internal steps
    # FMI 2: pythonfmu reports a rejected step as discard and fmpy stops the run there
    stopped = simulate_fmu(str(fmus[2]), stop_time=2 * STEP, output_interval=1.5e-4, output=["q[1]"])
    assert stopped["time"][-1] == 0.0
    with pytest.raises(Exception, match="DoStep"):  # FMI 3: an error
        simulate_fmu(str(fmus[3]), stop_time=2 * STEP, output_interval=1.5e-4, output=["q[1]"])


def test_two_exports_run_side_by_side_in_one_process(fmus, tmp_path):
    hand_file = tmp_path / "heavy.yaml"
    hand_file.write_text("object: {mass: 0.6, inertia: 1.25e-4}\n")
    heavy = export_plant_fmu(tmp_path, fmi=2, hand=hand_file)
    assert heavy == tmp_path / "HandPlant_fmi2.fmu"
    paths = {"light": fmus[2], "heavy": heavy}
    descriptions = {k: read_model_description(str(p)) for k, p in paths.items()}
    ids = {k: md.coSimulation.modelIdentifier for k, md in descriptions.items()}
    assert ids["light"] != ids["heavy"]

    slaves, refs = {}, {}
    for key, md in descriptions.items():
        vr = {v.name: v.valueReference for v in md.modelVariables}
        fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(str(paths[key]), tmp_path / key),
                        modelIdentifier=ids[key], instanceName=key)
        fmu.instantiate()
        fmu.setupExperiment(startTime=0.0)
        fmu.setReal([vr["f_ext[1]"]], [0.5])
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        slaves[key] = (fmu, [vr[n] for n in Q + OBJ], vr)
    hand = {"light": Hand.default().params.to_dict(), "heavy": heavy_hand()}
    refs = {key: native(hand[key], f_ext=(0.5, 0.0, 0.0), n_steps=20) for key in slaves}
    rows = {key: [] for key in slaves}
    try:
        for k in range(20):
            for key, (fmu, vrs, _) in slaves.items():  # interleaved: both instances alive
                fmu.doStep(currentCommunicationPoint=k * STEP, communicationStepSize=STEP)
                rows[key].append(fmu.getReal(vrs))
        masses = {key: fmu.getReal([vr["object.mass"]])[0] for key, (fmu, _, vr) in slaves.items()}
    finally:
        for fmu, _, _ in slaves.values():
            fmu.terminate()
            fmu.freeInstance()
    assert masses == {"light": 0.3, "heavy": 0.6}
    for key in slaves:
        got = np.array(rows[key])
        assert np.abs(got[:, :9] - refs[key]["q"][1:]).max() <= TOL
        assert np.abs(got[:, 9:] - refs[key]["obj"][1:]).max() <= TOL
    light, heavy_obj = np.array(rows["light"])[-1, 9], np.array(rows["heavy"])[-1, 9]
    assert light > 1.5 * heavy_obj > 0  # the same push moves the lighter object further


_ISOLATED = textwrap.dedent(
    """
    import importlib.util, json, sys
    repo, fmus, site = sys.argv[1], sys.argv[2:4], sys.argv[4:]
    sys.path.extend(p for p in site if p not in sys.path)  # python -S: no .pth files, no editable hierhand
    found = {m: importlib.util.find_spec(m) is not None for m in ("hierhand", "blocks")}

    class Refuse:  # and no PyYAML either: the FMU must need numpy and numba only
        def find_spec(self, name, path=None, target=None):
            if name.split(".")[0] in ("yaml", "hierhand", "blocks"):
                raise ModuleNotFoundError(f"{name} is not available here")

    sys.meta_path.insert(0, Refuse())
    from fmpy import simulate_fmu
    out = {"found": found, "runs": []}
    for fmu in fmus:
        r = simulate_fmu(fmu, stop_time=0.05, output_interval=1e-3)
        out["runs"].append({n: r[n].tolist() for n in r.dtype.names if n[:2] in ("q[", "ob")})
    out["from_repo"] = sorted(m for m, mod in list(sys.modules.items())
                              if str(getattr(mod, "__file__", "") or "").startswith(repo))
    print(json.dumps(out))
    """
)


def test_fmu_runs_in_a_python_without_hierhand(fmus, fmu_cache, tmp_path):
    paths = sysconfig.get_paths()
    # the installed packages' folders (a virtual environment may also see the system's),
    # but none of the .pth files that put the editable hierhand on the path
    site = sorted({paths["purelib"], paths["platlib"]}
                  | {p for p in sys.path if Path(p).name in ("site-packages", "dist-packages")})
    env = dict(os.environ, HIERHAND_FMU_CACHE=str(fmu_cache))
    env.pop("PYTHONPATH", None)
    proc = subprocess.run(
        [sys.executable, "-I", "-S", "-c", _ISOLATED, str(REPO), str(fmus[2]), str(fmus[3]), *site],
        cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300, check=False,
    )
    assert proc.returncode == 0, proc.stderr[-3000:]
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    assert out["found"] == {"hierhand": False, "blocks": False}
    assert out["from_repo"] == []
    ref = native()
    for run in out["runs"]:
        assert np.abs(np.column_stack([run[n] for n in Q]) - ref["q"]).max() <= TOL
        assert np.abs(np.column_stack([run[n] for n in OBJ]) - ref["obj"]).max() <= TOL


@pytest.mark.parametrize("fmi", [2, 3])
def test_round_trip_through_the_fmu_import_block(fmus, fmi):
    from blocks import loads_diagram, simulate

    diagram = loads_diagram(textwrap.dedent(f"""
        name: round_trip
        time: {{t_end: 50 ms}}
        blocks:
          fmu: {{type: FMU, period: 1 ms, params: {{path: "{fmus[fmi]}", start_values: {{object.mass: 0.6}}}}}}
          native: {{type: HandPlant, period: 0.1 ms, params: {{object: {{mass: 0.6, inertia: 1.25e-4}}}}}}
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
    for port in ("q", "obj"):
        t, fmu_values = results[f"fmu.{port}"]
        t_native, native_values = results[f"native.{port}"]
        assert len(t) == N_STEPS + 1 and np.allclose(t, t_native[: len(t)])
        assert np.abs(fmu_values - native_values[: len(t)]).max() <= TOL


def test_default_output_path():
    assert default_output_path(2) == Path("fmu") / "HandPlant_fmi2.fmu"
    assert default_output_path(3) == Path("fmu") / "HandPlant_fmi3.fmu"
    with pytest.raises(ValueError, match="fmi"):
        export_plant_fmu(fmi=1)


def test_an_installed_package_exports_without_the_repository(tmp_path, fmus):
    """Only the package folders, as an install has them, and another working folder: the
    export needs nothing else, lands in ./fmu/, and carries the same model as from here."""
    import shutil

    site, work = tmp_path / "site", tmp_path / "work"
    for package in ("blocks", "hierhand"):
        shutil.copytree(REPO / package, site / package, ignore=shutil.ignore_patterns("__pycache__"))
    work.mkdir()
    script = ("import hierhand, sys; from hierhand.fmu_export import export_plant_fmu; "
              "print(hierhand.__file__); print(export_plant_fmu(fmi=2))")
    env = {**os.environ, "PYTHONPATH": str(site)}
    done = subprocess.run([sys.executable, "-c", script], cwd=work, env=env, capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stderr
    imported, written = done.stdout.split()
    assert Path(imported).resolve().is_relative_to(site.resolve())
    assert (work / written).resolve() == (work / "fmu" / "HandPlant_fmi2.fmu").resolve()
    installed = read_model_description(str(work / written))
    here = read_model_description(str(fmus[2]))
    assert installed.coSimulation.modelIdentifier == here.coSimulation.modelIdentifier


@pytest.fixture(scope="module")
def native_regrasp():
    import blocks

    return blocks.simulate(blocks.load_diagram(REPO / "diagrams" / "regrasp.yaml"))


@pytest.mark.parametrize("fmi", [2, 3])
def test_regrasp_with_the_exported_plant_matches_the_native_run(fmus, native_regrasp, fmi):
    """diagrams/regrasp_fmu.yaml: the same task with the plant as an FMU, at 1 ms steps."""
    import blocks
    from hierhand.tasks.metrics import regrasp_summary

    diagram = blocks.load_diagram(REPO / "diagrams" / "regrasp_fmu.yaml",
                                  overrides={"plant.path": str(fmus[fmi])})
    via_fmu = blocks.simulate(diagram)
    assert via_fmu.complete
    t_native, q_native = native_regrasp["plant.q"]
    t_fmu, q_fmu = via_fmu["plant.q"]
    np.testing.assert_array_equal(t_fmu, t_native)
    np.testing.assert_allclose(q_fmu, q_native, rtol=0, atol=TOL)
    fmu_events, native_events = regrasp_summary(via_fmu), regrasp_summary(native_regrasp)
    assert fmu_events == native_events
    assert fmu_events["fore_separation_time_s"] is not None
