"""Export the hand plant (``HandPlant``) as a co-simulation FMU, FMI 2.0 or 3.0.

``export_plant_fmu(out, fmi, hand)`` builds the FMU with pythonfmu (FMI 2) or pythonfmu3
(FMI 3) from the slave template ``hierhand/hand_plant_slave.py.in``:

- inputs ``tau[1]``..``tau[9]``, ``f_ext[1]``..``f_ext[3]`` (start 0); one output per
  element of every plant output port, named the same way (``q[1]``, ``obj[3]``, ...),
  ``initial="calculated"`` (computed from the parameters when initialization ends) and
  declared independent of the inputs (the plant has no direct feedthrough);
- every number of the hand file as a parameter (variability ``fixed``), named after its
  place in the hand file with 1-based indices: ``gravity[2]``, ``object.mass``,
  ``contact.mu_s``, ``fingers[1].links[3].com[1]`` (thumb, distal link, COM along the link),
  ``fingers[2].q0[1]``; the start values are those of ``hand`` (default: the shipped hand);
- a fixed internal step of 0.1 ms; ``do_step`` accepts any communication step that is a whole
  multiple of it and runs the plant's ``advance`` over it.

The FMU carries the model code it runs: the modules of ``hierhand/model`` that ``plant.py``
imports (found by following its imports) and ``blocks/block.py``, as one flat package whose
imports of ``blocks.block`` are made relative and whose PyYAML import is optional. The FMU's
model identifier (its slave class, script module and binary) is ``HandPlant_<hash>``, the
hash covering the hand, the FMI version, the hierhand version, the exporter and all bundled
code, so FMUs from different exports load side by side in one process. The bundled code is
imported as the package ``hierhand_fmu_model_<hash of the code>``: FMUs carrying the same
code share it (numba compiles it once; the hand lives in each plant object), FMUs carrying
different code never collide.

What an importing tool needs: a Python with numpy and numba (not hierhand); pythonfmu's
binary embeds that interpreter, so a C/C++ host must have ``libpython3.X.so`` loadable
(e.g. ``LD_LIBRARY_PATH`` or ``LD_PRELOAD``) and find numpy and numba on its ``sys.path``
(``PYTHONPATH``/``PYTHONHOME``); a Python host such as fmpy runs the FMU in its own
interpreter. Numba compiles the kernels on first use; the compiled code is cached beside a
copy of the model sources under ``$HIERHAND_FMU_CACHE`` (default ``~/.cache/hierhand-fmu``),
see the template's docstring.
"""

from __future__ import annotations

import ast
import hashlib
import json
import os
import pprint
import shutil
import sys
import tempfile
from fractions import Fraction
from pathlib import Path
from typing import Any

SLAVE_TEMPLATE = Path(__file__).resolve().with_name("hand_plant_slave.py.in")
FMU_DIR = Path("fmu")
"""Where exports go by default: ``fmu/`` under the current folder, like ``runs/`` for results."""

INTERNAL_STEP = Fraction(1, 10000)
DEFAULT_COMMUNICATION_STEP = 1e-3
FMI_VERSIONS = (2, 3)

ENTRY_MODULE = "plant"  # hierhand/model/plant.py: HandPlant
RUNTIME_PACKAGES = frozenset({"numpy", "numba"})  # what the FMU's Python must provide
OPTIONAL_PACKAGES = frozenset({"yaml"})  # imported if present (the default hand ships as JSON)
SECTION_ORDER = ("gravity", "object", "contact", "fingers")

PORT_DOCS = {
    "tau": "joint torques [N m]: thumb joints 1-3, fore 1-3, middle 1-3 (proximal to distal)",
    "f_ext": "external load on the object: fx, fy [N], torque [N m]",
    "q": "joint angles [rad]: thumb 1-3, fore 1-3, middle 1-3 (relative angles)",
    "qd": "joint rates [rad/s]: thumb 1-3, fore 1-3, middle 1-3",
    "tip": "per finger (thumb, fore, middle) the tip centre x, y [m] and the link-3 angle [rad]",
    "fn": "per finger the summed normal contact force [N]",
    "ft": "per finger the summed tangential contact force on the object [N] (counter-clockwise tangent)",
    "ratio": "per finger |ft| / fn (0 without contact)",
    "contact": "per finger 1 while its normal force is positive, else 0",
    "obj": "object pose: x, y [m], theta [rad]",
    "obj_vel": "object velocity: vx, vy [m/s], omega [rad/s]",
    "normal": "per finger the unit vector x, y from the tip centre to its contact point (0 without contact)",
}

LEAF_DOCS = {
    "gravity": "gravity [m/s^2]",
    "mass": "mass [kg]",
    "inertia": "moment of inertia about the centre of mass [kg m^2]",
    "size": "side length [m]",
    "pos": "initial position of the centre [m]",
    "angle": "initial angle [rad]",
    "surface_spacing": "spacing of the surface contact points [m]",
    "k_n": "normal contact stiffness [N/m]",
    "c_n": "normal contact damping [N s/m]",
    "k_t": "tangential contact stiffness [N/m]",
    "c_t": "tangential contact damping [N s/m]",
    "mu_s": "static friction coefficient",
    "mu_d": "dynamic friction coefficient",
    "base": "base joint position [m]",
    "base_angle": "base angle [rad]",
    "length": "link length [m]",
    "com": "centre of mass along, across the link [m]",
    "damping": "joint damping [N m s/rad]",
    "armature": "joint armature inertia [kg m^2]",
    "tip_radius": "fingertip radius [m]",
    "q0": "initial joint angle [rad]",
}


class FmuExportError(RuntimeError):
    """The FMU cannot be built (for instance the model code imports something it cannot carry)."""


def export_plant_fmu(out: Path | None = None, fmi: int = 2, hand: Path | None = None) -> Path:
    """Build the hand plant FMU and return its path.

    ``out``: a ``.fmu`` file, or a folder to put ``HandPlant_fmi<N>.fmu`` in (default
    ``fmu/HandPlant_fmi<N>.fmu`` under the current folder); ``fmi``: 2 or 3; ``hand``: a hand file
    whose values become the parameters' start values (default: the shipped hand). Raises
    ``HandFileError`` for an invalid hand file and ``FmuExportError`` when the FMU cannot be
    built.
    """
    if fmi not in FMI_VERSIONS:
        raise ValueError(f"fmi must be 2 or 3, got {fmi!r}")
    target = _output_path(out, fmi)
    if not SLAVE_TEMPLATE.is_file():
        raise FmuExportError(f"the FMU slave template {SLAVE_TEMPLATE} is missing; reinstall hierhand")

    from hierhand.model import HandPlant, load_hand
    from hierhand.model.handfile import default_hand_dict

    hand_dict = load_hand(hand if hand is not None else {}).params.to_dict()
    plant = HandPlant(**hand_dict)
    files = _bundle_files(default_hand_dict())
    digest = bundle_digest(files)
    template = SLAVE_TEMPLATE.read_text(encoding="utf-8")
    identifier = _identifier(fmi, hand_dict, digest, template)
    spec = _spec(identifier, fmi, hand_dict, plant, files, digest)
    script = _render(template, identifier, fmi, spec)

    with tempfile.TemporaryDirectory(prefix="hierhand_fmu_") as tmp:
        tmp = Path(tmp)
        source = tmp / "source"
        bundle = source / spec["model_dir"]
        bundle.mkdir(parents=True)
        for name, data in files.items():
            (bundle / name).write_bytes(data)
        script_file = source / f"{identifier}.py"
        script_file.write_text(script, encoding="utf-8")
        built = _build(script_file, bundle, tmp / "build", fmi, identifier)
        target.parent.mkdir(parents=True, exist_ok=True)
        partial = target.with_name(target.name + ".partial")
        shutil.copyfile(built, partial)
        os.replace(partial, target)
    return target


# -- naming ---------------------------------------------------------------------------------


def default_output_path(fmi: int) -> Path:
    return FMU_DIR / f"HandPlant_fmi{fmi}.fmu"


def _output_path(out: Path | None, fmi: int) -> Path:
    if out is None:
        return default_output_path(fmi)
    out = Path(out)
    if out.suffix.lower() == ".fmu":
        return out
    return out / default_output_path(fmi).name


def _hierhand_version() -> str:
    from importlib import metadata

    try:
        return metadata.version("hierhand")
    except metadata.PackageNotFoundError:
        return "unknown"


def _identifier(fmi: int, hand_dict: dict[str, Any], digest: str, template: str) -> str:
    """``HandPlant_<hash>``: differs whenever the FMU's parameters, code or FMI version do."""
    if fmi == 2:
        from pythonfmu import __version__ as builder_version
    else:
        from pythonfmu3 import __version__ as builder_version

    key = {
        "fmi": fmi,
        "hand": hand_dict,
        "hierhand": _hierhand_version(),
        "model": digest,
        "slave": hashlib.sha256(template.encode()).hexdigest(),
        "exporter": hashlib.sha256(Path(__file__).read_bytes()).hexdigest(),
        "builder": builder_version,
    }
    text = json.dumps(key, sort_keys=True, separators=(",", ":"))
    return "HandPlant_" + hashlib.sha256(text.encode()).hexdigest()[:12]


# -- parameters -----------------------------------------------------------------------------


def hand_parameters(hand_dict: dict[str, Any]) -> list[dict[str, Any]]:
    """Every number of a (complete) hand dict as an FMU parameter: name, path, start, description.

    Names follow the hand file with 1-based indices (FMI's structured naming); ``path`` is
    the location in the hand dict (0-based), ``description`` names the hand-file field.
    """
    params: list[dict[str, Any]] = []
    sections = [k for k in SECTION_ORDER if k in hand_dict] + [k for k in hand_dict if k not in SECTION_ORDER]
    for section in sections:
        _flatten(hand_dict[section], [section], section, section, params, hand_dict)
    return params


def _flatten(value: Any, path: list, name: str, hand_path: str, params: list, hand_dict: dict) -> None:
    if isinstance(value, dict):
        for key, item in value.items():
            _flatten(item, path + [key], f"{name}.{key}", f"{hand_path}.{key}", params, hand_dict)
    elif isinstance(value, list):
        for i, item in enumerate(value):
            _flatten(item, path + [i], f"{name}[{i + 1}]", f"{hand_path}[{i}]", params, hand_dict)
    elif isinstance(value, str):
        return  # finger names: not parameters
    elif isinstance(value, (int, float)) and not isinstance(value, bool):
        leaf = next(k for k in reversed(path) if isinstance(k, str))
        doc = LEAF_DOCS.get(leaf, leaf)
        if path[0] == "fingers" and len(path) > 1:
            doc = f"{hand_dict['fingers'][path[1]].get('name', '')} {doc}".strip()
        params.append({"name": name, "path": path, "start": float(value),
                       "description": f"hand file {hand_path}: {doc}"})
    else:
        raise FmuExportError(f"hand file field {hand_path} is neither a number nor a string: {value!r}")


# -- the bundled model code -----------------------------------------------------------------

_BUNDLE_INIT = '''\
"""The HandPlant model code carried by a hierhand FMU (generated by hierhand.fmu_export).

Copies of hierhand/model modules and blocks/block.py, with ``from blocks.block import``
made relative and PyYAML optional (``_no_yaml``): the default hand is default_hand.json.
"""

import json as _json
from pathlib import Path as _Path

from . import handfile as _handfile

if not hasattr(_handfile, "default_hand_dict"):
    raise ImportError("bundled handfile.py has no default_hand_dict() to replace")

_DEFAULT_HAND = _json.loads(_Path(__file__).with_name("default_hand.json").read_text(encoding="utf-8"))


def _default_hand_dict():
    """The default hand file as a plain dict (a fresh copy), without PyYAML."""
    return _json.loads(_json.dumps(_DEFAULT_HAND))


_handfile.default_hand_dict = _default_hand_dict

from .plant import HandPlant

__all__ = ["HandPlant"]
'''

_YAML_IMPORT = (
    "try:  # bundled into an FMU: PyYAML is optional (the default hand is default_hand.json)\n"
    "    import yaml\n"
    "except ImportError:\n"
    "    from ._no_yaml import yaml\n"
)

_NO_YAML = '''\
"""A stand-in for PyYAML where it is missing (generated by hierhand.fmu_export).

The bundled model code reads no YAML (its default hand is default_hand.json), but its
modules may touch ``yaml`` attributes when imported; any attribute is another stand-in,
and calling one raises.
"""


class _Missing:
    def __init__(self, name):
        self._name = name

    def __getattr__(self, attribute):
        if attribute.startswith("__"):
            raise AttributeError(attribute)
        return _Missing(f"{self._name}.{attribute}")

    def __call__(self, *args, **kwargs):
        raise ModuleNotFoundError(f"{self._name}() needs PyYAML, which this Python does not have")

    def __repr__(self):
        return f"<{self._name}: PyYAML is not installed>"


yaml = _Missing("yaml")
'''


def model_package_name(digest: str) -> str:
    """The bundled model code's package name: named by its hash, not by the export.

    FMUs that carry the same code share the package in a process (the hand parameters live
    in each plant object, none in the modules); FMUs with different code never share a name.
    Numba's on-disk cache records the module names of what it compiled, so the cache of a
    given code must always be loaded under the same name.
    """
    return "hierhand_fmu_model_" + digest[:16]


def bundle_digest(files: dict[str, bytes]) -> str:
    """The hash the slave checks its bundled files against (same recipe as the template)."""
    h = hashlib.sha256()
    for name in sorted(files):
        h.update(name.encode())
        h.update(b"\0")
        h.update(files[name])
        h.update(b"\0")
    return h.hexdigest()


def _bundle_files(default_hand: dict[str, Any]) -> dict[str, bytes]:
    """File name -> content of the model package the FMU carries."""
    import blocks.block
    import hierhand.model

    roots = {"model": Path(hierhand.model.__file__).parent, "blocks": Path(blocks.block.__file__).parent}
    files: dict[str, bytes] = {}
    origin: dict[str, Path] = {}
    queue = [("model", ENTRY_MODULE)]
    done: set[tuple[str, str]] = set()
    while queue:
        key = queue.pop(0)
        if key in done:
            continue
        done.add(key)
        package, module = key
        path = roots[package] / f"{module}.py"
        if not path.is_file():
            raise FmuExportError(f"the plant needs module {module!r} but {path} does not exist (a package?)")
        name = f"{module}.py"
        if name in files:
            raise FmuExportError(f"cannot bundle both {origin[name]} and {path}: both become {name}")
        text, deps = _rewrite_imports(path.read_text(encoding="utf-8"), path, package)
        files[name] = text.encode("utf-8")
        origin[name] = path
        queue.extend(deps)
    for reserved in ("__init__.py", "_no_yaml.py", "default_hand.json"):
        if reserved in files:
            raise FmuExportError(f"the model code has a module named like the bundle's {reserved}")
    files["__init__.py"] = _BUNDLE_INIT.encode("utf-8")
    files["_no_yaml.py"] = _NO_YAML.encode("utf-8")
    files["default_hand.json"] = (json.dumps(default_hand, indent=1, sort_keys=True) + "\n").encode("utf-8")
    return files


def _rewrite_imports(text: str, path: Path, package: str) -> tuple[str, list[tuple[str, str]]]:
    """``text`` with its imports made self-contained, and the modules it needs."""
    tree = ast.parse(text, filename=str(path))
    deps: list[tuple[str, str]] = []
    edits: list[tuple[ast.stmt, str]] = []

    def fail(node: ast.AST, why: str) -> FmuExportError:
        return FmuExportError(f"{path}:{node.lineno}: {why}")

    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                top = alias.name.split(".")[0]
                if top in ("blocks", "hierhand"):
                    raise fail(node, f"'import {alias.name}' cannot be bundled; use 'from ... import ...'")
                if top in OPTIONAL_PACKAGES:
                    if len(node.names) != 1 or alias.asname is not None or alias.name != "yaml":
                        raise fail(node, "write the PyYAML import as a plain 'import yaml' statement")
                    edits.append((node, _YAML_IMPORT))
                else:
                    _check_runtime_import(top, node, fail)
        elif isinstance(node, ast.ImportFrom):
            if node.level == 0:
                parts = (node.module or "").split(".")
                if parts[0] == "blocks" and len(parts) == 2:
                    dep = ("blocks", parts[1])
                elif parts[:2] == ["hierhand", "model"] and len(parts) == 3:
                    dep = ("model", parts[2])
                elif parts[0] in ("blocks", "hierhand"):
                    raise fail(node, f"'from {node.module} import' cannot be bundled (only modules of "
                                     "hierhand.model and blocks can)")
                elif parts[0] in OPTIONAL_PACKAGES:
                    raise fail(node, f"'from {node.module} import' cannot be made optional; use 'import yaml'")
                else:
                    _check_runtime_import(parts[0], node, fail)
                    continue
                deps.append(dep)
                new = ast.unparse(ast.ImportFrom(module=dep[1], names=node.names, level=1))
                edits.append((node, new + f"  # bundled: was 'from {node.module} import'\n"))
            elif node.level == 1:
                if node.module is None:
                    deps.extend((package, alias.name) for alias in node.names)
                elif "." in node.module:
                    raise fail(node, f"relative import of a subpackage ('.{node.module}') cannot be bundled")
                else:
                    deps.append((package, node.module))
            else:
                raise fail(node, "relative imports above the package cannot be bundled")

    lines = text.splitlines(keepends=True)
    for node, new in sorted(edits, key=lambda e: e[0].lineno, reverse=True):
        first, last = lines[node.lineno - 1], lines[node.end_lineno - 1]
        indent = first[: node.col_offset]
        tail = last[node.end_col_offset :].strip()
        if indent.strip() or (tail and not tail.startswith("#")):
            raise fail(node, "an import to rewrite must be a statement on lines of its own")
        body = "".join(indent + line if line.strip() else line for line in new.splitlines(keepends=True))
        pad = "\n" * max(0, node.end_lineno - node.lineno + 1 - new.count("\n"))  # keep line numbers
        lines[node.lineno - 1 : node.end_lineno] = [body + pad]
    result = "".join(lines)
    compile(result, str(path), "exec")
    return result, deps


def _check_runtime_import(top: str, node: ast.AST, fail) -> None:
    if top in RUNTIME_PACKAGES or top in sys.stdlib_module_names or top == "__future__":
        return
    raise fail(node, f"the model code imports {top!r}, but the FMU's Python is only required to "
                     f"have {', '.join(sorted(RUNTIME_PACKAGES))}")


# -- the slave script -----------------------------------------------------------------------


def _spec(identifier: str, fmi: int, hand_dict: dict, plant, files: dict[str, bytes], digest: str) -> dict:
    ports = list(plant.inputs.items()) + list(plant.outputs.items())
    return {
        "identifier": identifier,
        "fmi_version": fmi,
        "hierhand_version": _hierhand_version(),
        "description": (
            "hierhand HandPlant: three-fingered planar hand grasping a square object, penalty contact; "
            f"internal step {float(INTERNAL_STEP) * 1e3:g} ms, communication steps must be multiples of it"
        ),
        "package": model_package_name(digest),
        "model_dir": model_package_name(digest),
        "model_digest": digest,
        "model_files": sorted(files),
        "dt": [INTERNAL_STEP.numerator, INTERNAL_STEP.denominator],
        "default_step": DEFAULT_COMMUNICATION_STEP,
        "hand": hand_dict,
        "parameters": hand_parameters(hand_dict),
        "inputs": [[p, int(w)] for p, w in plant.inputs.items()],
        "outputs": [[p, int(w)] for p, w in plant.outputs.items()],
        "docs": {p: PORT_DOCS.get(p, f"HandPlant port {p!r}") for p, _ in ports},
    }


_FMI_IMPORTS = {
    2: (
        "from pythonfmu.default_experiment import DefaultExperiment\n"
        "from pythonfmu.enums import Fmi2Causality as Causality\n"
        "from pythonfmu.enums import Fmi2Initial as Initial\n"
        "from pythonfmu.enums import Fmi2Status as Status\n"
        "from pythonfmu.enums import Fmi2Variability as Variability\n"
        "from pythonfmu.fmi2slave import Fmi2Slave\n"
        "from pythonfmu.variables import Real as FloatVar"
    ),
    3: (
        "from pythonfmu3.default_experiment import DefaultExperiment\n"
        "from pythonfmu3.enums import Fmi3Causality as Causality\n"
        "from pythonfmu3.enums import Fmi3Initial as Initial\n"
        "from pythonfmu3.enums import Fmi3Status as Status\n"
        "from pythonfmu3.enums import Fmi3Variability as Variability\n"
        "from pythonfmu3.fmi3slave import Fmi3Slave, Fmi3StepResult\n"
        "from pythonfmu3.variables import Float64 as FloatVar"
    ),
}


def _render(template: str, identifier: str, fmi: int, spec: dict) -> str:
    values = {
        "CLASS_NAME": identifier,
        "FMI_VERSION": str(fmi),
        "BASE": "Fmi2Slave" if fmi == 2 else "Fmi3Slave",
        "FMI_IMPORTS": _FMI_IMPORTS[fmi],
        "SPEC": pprint.pformat(spec, width=110, sort_dicts=False),
        "MODEL_DIR": spec["model_dir"],
        "PACKAGE": spec["package"],
        "DT_TEXT": f"{float(INTERNAL_STEP) * 1e3:g} ms",
    }
    text = template
    for key, value in values.items():
        text = text.replace("{{" + key + "}}", value)
    if "{{" in text:
        start = text.index("{{")
        raise FmuExportError(f"unfilled placeholder in {SLAVE_TEMPLATE}: {text[start:start + 40]!r}")
    compile(text, f"{identifier}.py", "exec")
    return text


# -- building -------------------------------------------------------------------------------


def _build(script: Path, bundle: Path, dest: Path, fmi: int, identifier: str) -> Path:
    """Run the pythonfmu builder, keeping this process's ``sys.path`` and modules as they were."""
    if fmi == 2:
        from pythonfmu.builder import FmuBuilder
    else:
        from pythonfmu3.builder import FmuBuilder
    if not FmuBuilder.has_binary():
        raise FmuExportError(f"pythonfmu{'3' if fmi == 3 else ''} has no FMU binary for this platform")
    saved_path = list(sys.path)
    try:
        dest.mkdir(parents=True, exist_ok=True)
        built = Path(FmuBuilder.build_FMU(
            script, dest=dest, project_files=[bundle],
            # the model runs inside the FMU (on the Python runtime its binary embeds), not in
            # an external tool it talks to; importers refuse tool-coupling FMUs
            needsExecutionTool=False,
            # pythonfmu3 0.3.4 writes this flag from the wrong variable unless it is given
            canHandleVariableCommunicationStepSize=True,
        ))
    finally:
        sys.path[:] = saved_path  # the FMI 2 builder leaves the script's folder on sys.path
        sys.modules.pop(identifier, None)  # ... and the script module imported
    if not built.is_file():
        raise FmuExportError(f"the FMU builder did not write {built}")
    return built
