"""Block references: the order to build a diagram's blocks in, and the cycles that forbid one.

A block parameter named in ``Block.block_params`` holds another block of the diagram
(``hand: plant``). The referenced block must exist before the block that refers to it is
made, so the loader builds blocks in an order where every reference points backwards:
file order, except that a referenced block is pulled in front of its first user. A
cycle of references (``a.hand -> b, b.x -> a``) has no such order and is an error.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping


@dataclass(frozen=True)
class Reference:
    """Parameter ``param`` of block ``block`` names block ``target``."""

    block: str
    param: str
    target: str

    def __str__(self) -> str:
        return f"{self.block}.{self.param} -> {self.target}"


def chain_text(cycle: list[Reference]) -> str:
    """``a.hand -> b, b.x -> a``: a cycle as the references that close it."""
    return ", ".join(str(r) for r in cycle)


def build_order(references: Mapping[str, Mapping[str, str]]) -> tuple[list[str], list[list[Reference]]]:
    """(every block in an order where referenced blocks come first, the cycles found).

    ``references`` maps each block, in file order, to its references (parameter ->
    target); targets that are not keys are ignored (the caller reports them). Blocks on a
    cycle are still listed; the caller must not build them. Each cycle is listed once,
    starting at its block met first in the search (which goes in file order).
    """
    order: list[str] = []
    done: set[str] = set()
    path: list[str] = []
    cycles: list[list[Reference]] = []

    def visit(name: str) -> None:
        path.append(name)
        for param, target in references[name].items():
            if target not in references or target in done:
                continue
            if target in path:
                members = path[path.index(target):]
                cycle = [_closing(references, b, members[(i + 1) % len(members)]) for i, b in enumerate(members)]
                if cycle not in cycles:  # two parameters naming the same block close it twice
                    cycles.append(cycle)
                continue
            visit(target)
        path.pop()
        done.add(name)
        order.append(name)

    for name in references:
        if name not in done:
            visit(name)
    return order, cycles


def _closing(references: Mapping[str, Mapping[str, str]], block: str, target: str) -> Reference:
    """The (first) reference of ``block`` to ``target``."""
    param = next(p for p, t in references[block].items() if t == target)
    return Reference(block, param, target)
