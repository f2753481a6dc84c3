"""The options every diagram command shares (DIAGRAM, --set, --t-end, --trust) and reading them.

``run``, ``validate`` and ``graph`` take the same diagram arguments; ``load`` turns them
into a ``Diagram`` and ``end_time`` into the run's end time, with the command line's own
messages for values that are not right.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from collections.abc import Sequence

from .program import UsageError

TYPE_CHECKING = False  # typing's constant without importing typing (blocks.cli.program says why)
if TYPE_CHECKING:
    from typing import Any


def diagram_args(p: argparse.ArgumentParser) -> None:
    """Add DIAGRAM, --set, --t-end (alias --stop-time), --step and --trust to a command's parser."""
    p.add_argument("diagram", type=Path, metavar="DIAGRAM",
                   help="YAML diagram file, or an SSP (.ssp archive, or a folder with SystemStructure.ssd); "
                        "a name that is no file: a diagram the program ships, if it has one of that name")
    p.add_argument("--set", action="append", default=[], dest="overrides", metavar="BLOCK.PARAM=VALUE",
                   help="override a parameter (value read as YAML; repeatable), e.g. --set prop.k=2")
    p.add_argument("--t-end", "--stop-time", dest="t_end", metavar="T",
                   help="end time, e.g. 2, '0.5 s' or '300 ms' (default: the diagram's time.t_end)")
    p.add_argument("--step", metavar="T",
                   help="SSP only: the communication step of the components whose SSD gives none, e.g. '1 ms'")
    trust_arg(p)


def trust_arg(p: argparse.ArgumentParser) -> None:
    """Add --trust, which lets a diagram name Python classes as block types."""
    p.add_argument("--trust", action="store_true",
                   help="allow 'python:module:Class' block types, which import code named in the diagram")


def parse_overrides(items: Sequence[str]) -> dict[str, Any]:
    """``["plant.k=2", "ctrl.gains=[1, 2]"]`` -> {"plant.k": 2, "ctrl.gains": [1, 2]}."""
    from blocks.diagram_file.yaml_source import load_yaml_value  # here: --help and --version need no YAML

    overrides: dict[str, Any] = {}
    for item in items:
        key, eq, text = item.partition("=")
        key = key.strip()
        if not eq or "." not in key or not all(key.split(".")):
            raise UsageError(f"--set {item!r}: expected BLOCK.PARAM=VALUE, e.g. --set prop.k=2")
        try:
            overrides[key] = load_yaml_value(text, f"--set {key}") if text.strip() else None
        except ValueError as exc:
            raise UsageError(str(exc)) from None
        if overrides[key] is None:
            raise UsageError(f"--set {item!r}: no value after '='")
    return overrides


def load(args: argparse.Namespace):
    """The diagram the arguments name, with their overrides."""
    from blocks import load_diagram

    return load_diagram(args.diagram, overrides=parse_overrides(args.overrides), trust=args.trust,
                        step=getattr(args, "step", None))


def end_time(args: argparse.Namespace, diagram):
    """The end time: --t-end if given (checked), else the diagram's; DiagramError if neither
    (``blocks.engine.simulate.run_end_time``), UsageError for a bad --t-end."""
    from blocks.engine.simulate import run_end_time
    from blocks.timebase import DurationError

    try:
        return run_end_time(diagram, args.t_end, "--t-end")
    except DurationError as exc:
        raise UsageError(str(exc)) from None


def picture_output(path: Path, suffixes: Sequence[str] = (".png",)) -> Path:
    """``path`` as the picture file an ``-o`` option names: UsageError for a name that does
    not end in one of ``suffixes`` (the picture would be written under another name, or as
    another kind of file) or for a folder."""
    kinds = suffixes[0] if len(suffixes) == 1 else f"{', '.join(suffixes[:-1])} or {suffixes[-1]}"
    if path.is_dir():
        raise UsageError(f"-o {path}: is a folder; name the {kinds} file to write "
                         f"(e.g. -o {path / ('signals' + suffixes[0])})")
    if path.suffix.lower() not in suffixes:
        raise UsageError(f"-o {path}: write a {kinds} file (e.g. -o {path.with_suffix(suffixes[0])})")
    return path
