"""What names an SSP, without the reader: ``blocks.load_diagram`` asks this of every path,
and a YAML diagram should not import the SSP reader, the FMU block and the exporter."""

from __future__ import annotations

from pathlib import Path

SSD_NAME = "SystemStructure.ssd"
"""The SSD every SSP holds at its root (SSP 1.0, 4.1)."""


def is_ssp(path: str | Path) -> bool:
    """Whether ``path`` names an SSP: a ``.ssp`` file, an ``.ssd`` file, or a folder with a
    SystemStructure.ssd."""
    p = Path(path)
    return p.suffix.lower() in (".ssp", ".ssd") or (p.is_dir() and (p / SSD_NAME).is_file())
