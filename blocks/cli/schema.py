"""``schema``: the diagram file's JSON Schema, generated from the registered block types,
for editors (``# yaml-language-server: $schema=diagram.schema.json``) and validators."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .program import EXIT_OK, UsageError


def add(sub, program) -> argparse.ArgumentParser:
    """The ``schema`` command."""
    schema = sub.add_parser("schema", help="write the JSON Schema of the diagram file",
                            description="Write the JSON Schema (draft 2020-12) of the diagram file, generated "
                                        "from the registered block types (their parameters, types, defaults and "
                                        "ports), for editors and validators. A diagram names it in its first line: "
                                        "'# yaml-language-server: $schema=diagram.schema.json'.")
    schema.add_argument("-o", "--output", type=Path, metavar="FILE.json",
                        help="the file to write (default: standard output)")
    schema.set_defaults(handler=cmd_schema)
    return schema


def schema_text() -> str:
    """The schema as the text ``schema`` writes: indented JSON, one final newline."""
    import json

    from blocks.diagram_file.schema import diagram_schema

    return json.dumps(diagram_schema(), indent=1, ensure_ascii=False) + "\n"


def cmd_schema(args: argparse.Namespace) -> int:
    text = schema_text()
    if args.output is None:
        sys.stdout.write(text)
        return EXIT_OK
    if args.output.is_dir():
        raise UsageError(f"-o {args.output}: is a folder; name the file to write (e.g. -o "
                         f"{args.output / 'diagram.schema.json'})")
    try:
        args.output.write_text(text, encoding="utf-8")
    except OSError as exc:
        raise UsageError(f"-o {args.output}: cannot write it: {exc.strerror or exc}") from None
    print(f"wrote {args.output}")
    return EXIT_OK
