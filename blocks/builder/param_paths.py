"""``--set`` paths into block parameters: ``plant.contact.mu_s``, ``plant.fingers.1.links.0.length``.

After the block name, a path's first part names the parameter and each further part
goes one level down: a key of a mapping, or a 0-based index of a list. A key missing
from a mapping is created (as an empty mapping on the way down), so a path can add to a
partial mapping; an index must address an existing element, because a list has no
natural filler for the elements before it. A parameter the diagram does not give starts
from ``Block.param_default``.
"""

from __future__ import annotations

from typing import Any, Callable


class PathError(ValueError):
    """A path that does not fit the parameter's value; ``hint`` says what would."""

    def __init__(self, message: str, hint: str = ""):
        super().__init__(message)
        self.hint = hint


def set_path(params: dict, block: str, parts: list[str], value: Any, start: Callable[[str], Any]) -> None:
    """``params[parts[0]][parts[1]]... = value`` (``block`` names the block in messages);
    ``start(parameter)`` is the value to go down into when ``params`` lacks the parameter."""
    if len(parts) > 1 and parts[0] not in params:
        initial = start(parts[0])
        params[parts[0]] = {} if initial is None else initial
    container: Any = params
    for depth, part in enumerate(parts[:-1]):
        container = _child(container, part, f"{block}.{'.'.join(parts[:depth])}" if depth else block)
        if not isinstance(container, (dict, list)):
            where = f"{block}.{'.'.join(parts[:depth + 1])}"
            raise PathError(f"'{where}' is {_kind(container)}, not a mapping or a list",
                            f"set '{where}' itself, e.g. --set {where}=...")
    last = parts[-1]
    where = f"{block}.{'.'.join(parts[:-1])}" if len(parts) > 1 else block
    if isinstance(container, list):
        container[_index(container, last, where)] = value
    else:
        container[last] = value


def _child(container: dict | list, part: str, where: str) -> Any:
    if isinstance(container, list):
        return container[_index(container, part, where)]
    if part not in container:
        container[part] = {}
    return container[part]


def _index(items: list, part: str, where: str) -> int:
    last = f"0 to {len(items) - 1}" if items else "none: the list is empty"
    if not (part.isascii() and part.isdigit()):
        raise PathError(f"'{where}' is a list; '{part}' is not an index of it",
                        f"address an element by its 0-based index ({last})")
    index = int(part)
    if index >= len(items):
        raise PathError(f"index {index} is out of range: '{where}' has {len(items)} element(s)",
                        f"valid indices: {last}")
    return index


def _kind(value: Any) -> str:
    return "None" if value is None else f"a {type(value).__name__} ({value!r})"
