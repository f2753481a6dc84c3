"""The diagrams shipped with hierhand: their folder, one of them by name, and copies of them.

A clone has them in ``diagrams/``; an installed wheel carries a copy in the package
(``hierhand/diagrams``, made by setup.py), with the diagram file's JSON Schema that their
first lines name. ``hierhand run regrasp`` finds one by name where no file of that name
exists, and ``hierhand examples DIR`` copies them all, so the commands of the
documentation work from any folder after any install.
"""

from __future__ import annotations

import re
import shutil
from pathlib import Path

from blocks.diagram_file.schema import SCHEMA_FILE


def shipped_diagrams() -> Path:
    """The folder of the shipped diagrams: the copy an installed wheel carries in the
    package (``hierhand/diagrams``, made by setup.py), else the repository's ``diagrams/``
    (a clone, or an editable install of it)."""
    package = Path(__file__).resolve().parent
    packaged = package / "diagrams"
    return packaged if (packaged / "regrasp.yaml").is_file() else package.parent / "diagrams"


SHIPPED = shipped_diagrams()
_NAME = re.compile(r"^[A-Za-z0-9_-]+(\.yaml)?$")


def shipped_diagram(name: str) -> Path | None:
    """The shipped diagram ``name`` (``regrasp`` or ``regrasp.yaml``), or None: a name
    with a folder in it, or one that is not shipped."""
    if not _NAME.match(name):
        return None
    path = SHIPPED / (name if name.endswith(".yaml") else f"{name}.yaml")
    return path if path.is_file() else None


def example_files() -> list[Path]:
    """The shipped diagrams and the schema they name, in name order."""
    return sorted([*SHIPPED.glob("*.yaml"), SHIPPED / SCHEMA_FILE])


def copy_examples(folder: Path) -> list[Path]:
    """Copy the shipped diagrams (and their schema) into ``folder``, made if need be;
    FileExistsError naming the files already there, before anything is copied."""
    files = example_files()
    taken = [folder / f.name for f in files if (folder / f.name).exists()]
    if taken:
        raise FileExistsError(", ".join(str(p) for p in taken))
    folder.mkdir(parents=True, exist_ok=True)
    return [Path(shutil.copy2(f, folder / f.name)) for f in files]
