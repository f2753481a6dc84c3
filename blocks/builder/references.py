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
    cycles: list[list[Reference]] = []
    found: set[tuple[Reference, ...]] = set()
    for root in references:
        if root in done:
            continue
        # depth-first, with an explicit stack so that a long chain of references does
        # not reach Python's recursion limit; ``on_path`` gives a block's place in it
        path = [root]
        on_path = {root: 0}
        pending = [iter(references[root].values())]
        while pending:
            for target in pending[-1]:
                if target not in references or target in done:
                    continue
                if target in on_path:
                    members = path[on_path[target]:]
                    cycle = [_closing(references, b, members[(i + 1) % len(members)]) for i, b in enumerate(members)]
                    if tuple(cycle) not in found:  # two parameters naming the same block close it twice
                        found.add(tuple(cycle))
                        cycles.append(cycle)
                    continue
                on_path[target] = len(path)
                path.append(target)
                pending.append(iter(references[target].values()))
                break
            else:
                pending.pop()
                name = path.pop()
                del on_path[name]
                done.add(name)
                order.append(name)
    return order, cycles


def _closing(references: Mapping[str, Mapping[str, str]], block: str, target: str) -> Reference:
    """The (first) reference of ``block`` to ``target``."""
    param = next(p for p, t in references[block].items() if t == target)
    return Reference(block, param, target)
