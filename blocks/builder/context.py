"""What one ``DiagramBuilder.build()`` gathers while it checks: the issues, the files read
and the hash of what the diagram was made from.

Every check of the build reports here (``error``, or ``override_error`` for a value the
caller gave as an override), so that all problems come out together in one
``DiagramError``, each as ``file:line: message (hint: ...)``.
"""

from __future__ import annotations

import hashlib
from pathlib import Path
from typing import Any, Iterable

from blocks.issues import Issue


def suggest(word: Any, choices: Iterable[str]) -> str:
    """``did you mean 'x'?`` for the choice closest to ``word``, or ``""``."""
    import difflib  # here: only a diagram with a mistake asks

    close = difflib.get_close_matches(str(word), list(choices), n=1)
    return f"did you mean '{close[0]}'?" if close else ""


def known(choices: Iterable[str]) -> str:
    """The choices as a list for a hint (``none`` if there are none)."""
    return ", ".join(choices) or "none"


class BuildContext:
    """The issues, files and hash of one build; ``overrides`` and ``origins`` as given to it."""

    def __init__(self, overrides: dict[str, Any], origins: dict[str, str], files_map: dict[str, Path]):
        self.overrides = overrides
        self.origins = origins
        self.files_map = files_map
        """Where to read each file, by its reference from the top diagram's folder."""
        self.issues: list[Issue] = []
        self.files: dict[str, Path] = {}
        """The files read, by reference (``Diagram.files``)."""
        self.hash = hashlib.sha256()

    def error(self, file: str, line: int | None, message: str, hint: str = "") -> None:
        self.issues.append(Issue(file, line, message, hint))

    def add(self, issue: Issue) -> None:
        self.issues.append(issue)

    def override_error(self, key: str, message: str, hint: str = "") -> None:
        """A problem with override ``key``, reported as the caller gave it (``--set k=v``)."""
        origin = self.origins.get(key) or f"--set {key}={self.overrides[key]!r}"
        self.issues.append(Issue(origin, None, message, hint, override=key))

    def found(self, ref: str, default: Path) -> Path:
        """Where to read the file named ``ref`` (from the top diagram's folder): its entry in
        the files map, else ``default``; recorded in ``files`` when it is a file."""
        real = self.files_map.get(ref, default)
        if real.is_file():
            self.files[ref] = real
        return real

    def unique_issues(self) -> list[Issue]:
        """The issues in the order found, each once (a file included twice reports its own
        problems once)."""
        return list(dict.fromkeys(self.issues))
