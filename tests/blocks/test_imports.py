"""The project's import structure: ``blocks`` never imports ``hierhand``, the modules of
both import each other without a cycle, and the framework's layers (data -> builder ->
planner -> front end -> executor) stay layers.

Imports are read from the source with ``ast``, wherever they stand: at module level,
under ``if TYPE_CHECKING``, or inside a function (a deferred import is still a
dependency, only a later one).
"""

from __future__ import annotations

import ast
import functools
import os
import subprocess
import sys
from pathlib import Path

import networkx as nx
import pytest

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "blocks"


def module_name(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


PROJECT = {module_name(p): p for package in ("blocks", "hierhand") for p in sorted((ROOT / package).rglob("*.py"))}
"""Every module of the project, the framework's and the application's."""
MODULES = {name: path for name, path in PROJECT.items() if name.split(".")[0] == "blocks"}
"""The framework's modules."""
TOP_LEVEL_LIMIT = 12
"""The most modules at the top of ``blocks/``: the rest lives in subpackages, one stage or
concern each, so that the tree shows where a change belongs."""


def imported(module: str) -> set[str]:
    """Every module ``module`` imports: ``from pkg import sub`` counts as ``pkg.sub`` when
    that is a module, relative imports resolved."""
    path = PROJECT[module]
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    found: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), filename=str(path))):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[:len(package.split(".")) - node.level + 1]
                source = ".".join(base + ([node.module] if node.module else []))
            else:
                source = node.module
            for alias in node.names:
                sub = f"{source}.{alias.name}"
                found.add(sub if sub in PROJECT else source)
    found.discard(module)  # a package importing its compiled extension (``from . import _native``)
    return found


@functools.lru_cache(maxsize=1)
def import_graph() -> nx.DiGraph:
    """The graph of who imports whom among the project's modules, read once: the layer
    checks each walk it, and the sources do not change while the tests run."""
    graph = nx.DiGraph()
    graph.add_nodes_from(PROJECT)
    for module in PROJECT:
        graph.add_edges_from((module, target) for target in imported(module) if target in PROJECT)
    return graph


def test_the_import_reader_sees_imports_inside_functions_and_relative_ones():
    assert "blocks.library" in imported("blocks.registry")  # inside block_types()
    assert "blocks.block" in imported("blocks.builder.construct")  # from .block import ...
    assert "blocks.fmu.interrupt" in imported("blocks.fmu.block")  # from . import interrupt
    assert "blocks.timebase" in imported("blocks.fmu.block")  # from ..timebase import ...


@pytest.mark.parametrize("module", sorted(MODULES))
def test_no_blocks_module_imports_hierhand(module):
    bad = sorted(m for m in imported(module) if m == "hierhand" or m.startswith("hierhand."))
    assert not bad, f"{MODULES[module].relative_to(ROOT)} imports {', '.join(bad)}"


def test_importing_every_blocks_module_loads_nothing_of_hierhand():
    code = (f"import {', '.join(sorted(MODULES))}\n"
            "import sys\n"
            "loaded = sorted(m for m in sys.modules if m == 'hierhand' or m.startswith('hierhand.'))\n"
            "assert not loaded, loaded\n")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")])))
    proc = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=env, capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 0, proc.stderr


def test_the_project_modules_import_each_other_without_a_cycle():
    graph = import_graph()
    cycles = list(nx.simple_cycles(graph))
    assert not cycles, "import cycles: " + "; ".join(" -> ".join(c + [c[0]]) for c in cycles)


LAYERS = ["blocks.issues", "blocks.builder.diagram", "blocks.builder.records", "blocks.engine.schedule",
          "blocks.builder.assemble", "blocks.builder.diagram_builder", "blocks.diagram_file.params_file",
          "blocks.diagram_file.reader", "blocks.diagram_file.load", "blocks.engine.simulate"]
"""The core modules from the lowest layer up: data, what a diagram records, planner, the
checks that make a Diagram, the builder (checks + planner), its YAML front end (the params
files it reads for the builder, the diagram file), load (front end + builder), executor."""


@pytest.mark.parametrize("lower, higher", [(a, b) for i, a in enumerate(LAYERS) for b in LAYERS[i + 1:]])
def test_a_lower_layer_never_reaches_a_higher_one(lower, higher):
    graph = import_graph()
    assert not nx.has_path(graph, lower, higher), " -> ".join(nx.shortest_path(graph, lower, higher))


def test_the_top_of_blocks_holds_few_modules():
    top = sorted(p.name for p in PACKAGE.glob("*.py"))
    assert len(top) <= TOP_LEVEL_LIMIT, f"{len(top)} modules at the top of blocks/: {', '.join(top)}"


def in_package(package: str) -> list[str]:
    """The modules of ``package`` (``blocks.builder``), the package itself included."""
    return sorted(m for m in MODULES if m == package or m.startswith(package + "."))


@pytest.mark.parametrize("module", in_package("blocks.builder"))
def test_the_builder_imports_no_front_end(module):
    """The builder knows no file format: its front ends (``blocks.diagram_file``, YAML) are
    a layer above it, which hands it source positions in its own form (``Site``,
    ``Positions``) and reads the params files its diagrams name (``ParamsReader``)."""
    bad = sorted(m for m in imported(module) if m in in_package("blocks.diagram_file") or m.split(".")[0] == "yaml")
    assert not bad, f"{MODULES[module].relative_to(ROOT)} imports {', '.join(bad)}"


def test_importing_the_command_line_and_sweeps_loads_no_application_code():
    """Nor Dask's distributed or matplotlib, which only the commands that need them import."""
    code = ("import sys, blocks.cli, blocks.sweep, blocks.sweep.plan, blocks.sweep.plot; "
            "print(sorted(m for m in sys.modules if m.split('.')[0] in ('hierhand', 'distributed', 'matplotlib')))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True)
    assert out.stdout.strip() == "[]"
