"""The C sources include each other without a circle, as the Python modules import each
other without one (test_imports.py): a file of ``blocks/csrc`` or ``hierhand/csrc`` and
what it includes form layers, so that each can be read, and changed, knowing only those
below it.

A ``.c`` file and the ``.h`` of the same name are one unit (the header is the file's
interface): ``fmu_channel.c`` including ``fmu_channel.h`` is no circle, but
``fmu_block_step.c`` including ``fmu_channel.h`` while ``fmu_channel.c`` includes
``fmu_block_step.h`` is one. Only quoted includes count; a header that is not in the
tree (Python's, libc's, the FMI standard's in ``blocks/csrc/fmi``, which the build passes
as an include folder of its own) is no unit of ours.
"""

from __future__ import annotations

import re
from pathlib import Path

import networkx as nx

ROOT = Path(__file__).resolve().parents[2]
FOLDERS = [ROOT / "blocks" / "csrc", ROOT / "hierhand" / "csrc"]
"""The C trees, which are also the include folders the build passes (setup.py)."""

INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.MULTILINE)


def unit(path: Path) -> Path:
    """A file's unit: its path without the suffix (``x.c`` and ``x.h`` are one)."""
    return path.with_suffix("")


def included(path: Path, folders: list[Path]) -> list[Path]:
    """The files of the tree that ``path`` includes, found as a compiler finds a quoted
    include: beside the file first, then in the include folders."""
    found = []
    for name in INCLUDE.findall(path.read_text(encoding="utf-8", errors="replace")):
        for folder in [path.parent, *folders]:
            candidate = (folder / name).resolve()
            if candidate.is_file():
                found.append(candidate)
                break
    return found


def include_graph(folders: list[Path]) -> nx.DiGraph:
    """Unit -> unit for every quoted include between the C files under ``folders``."""
    graph = nx.DiGraph()
    for folder in folders:
        for path in sorted(folder.rglob("*")):
            if path.suffix not in (".c", ".h"):
                continue
            source = unit(path.resolve())
            graph.add_node(source)
            graph.add_edges_from((source, unit(target)) for target in included(path, folders)
                                 if unit(target) != source)
    return graph


def circles(graph: nx.DiGraph) -> list[str]:
    """Each circle of units as 'a -> b -> a', from its first unit in path order, paths
    relative to the repository."""
    name = lambda node: node.relative_to(ROOT).as_posix() if node.is_relative_to(ROOT) else str(node)  # noqa: E731
    found = []
    for cycle in nx.simple_cycles(graph):
        start = cycle.index(min(cycle))
        cycle = cycle[start:] + cycle[:start]
        found.append(" -> ".join(name(n) for n in [*cycle, cycle[0]]))
    return sorted(found)


def test_the_include_reader_finds_includes_beside_the_file_upwards_and_in_the_include_folders():
    graph = include_graph(FOLDERS)
    blocks, hand = FOLDERS
    assert graph.has_edge(blocks / "fmu_block_step", blocks / "fmu_channel")  # beside the file
    assert graph.has_edge(hand / "python" / "py_kernel_types", hand / "kernel_types")  # "../kernel_types.h"
    assert graph.has_edge(hand / "kernel_types", blocks / "blocks_kernel")  # an include folder
    assert not graph.has_edge(blocks / "fmu_channel", blocks / "fmu_channel")  # x.c with x.h: one unit


def test_a_circle_between_two_units_is_found(tmp_path):
    (tmp_path / "a.h").write_text("int a(void);\n")
    (tmp_path / "b.h").write_text("int b(void);\n")
    (tmp_path / "a.c").write_text('#include "a.h"\n#include "b.h"\nint a(void) { return b(); }\n')
    (tmp_path / "b.c").write_text('#include "b.h"\n#include "a.h"\nint b(void) { return a(); }\n')
    assert circles(include_graph([tmp_path])) == [f"{tmp_path / 'a'} -> {tmp_path / 'b'} -> {tmp_path / 'a'}"]
    (tmp_path / "b.c").write_text('#include "b.h"\nint b(void) { return 0; }\n')
    assert circles(include_graph([tmp_path])) == []


def test_the_c_sources_include_each_other_without_a_circle():
    found = circles(include_graph(FOLDERS))
    assert not found, "C include circles (a .c and its .h are one unit):\n" + "\n".join(found)
