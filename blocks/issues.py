"""Problems with a diagram's input: ``Issue`` (where, what, how to fix) and ``DiagramError``.

The loader, the planner and the executor's argument checks all report bad input this
way, so every layer says ``file:line: message (hint: ...)`` and a caller catches one
exception type.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Iterable


@dataclass(frozen=True)
class Issue:
    """One problem in a diagram, with where it is and how to fix it."""

    file: str
    line: int | None
    message: str
    hint: str = ""
    override: str | None = None
    """The override (``block.param``) the issue is about; ``file`` then says how the user
    gave it (``--set plant.k=2``, ``--grid plant.k=1,2``)."""

    def __str__(self) -> str:
        where = f"{self.file}:{self.line}" if self.line else self.file
        return f"{where}: {self.message}" + (f" (hint: {self.hint})" if self.hint else "")


class DiagramError(Exception):
    """Invalid diagram input; ``issues`` lists every problem found."""

    def __init__(self, issues: Iterable[Issue]):
        self.issues = list(issues)
        super().__init__("\n".join(str(i) for i in self.issues))
