"""``blocks``: the registered block types with their ports and parameters."""

from __future__ import annotations

import argparse

from .program import EXIT_OK, UsageError


def add(sub, program) -> argparse.ArgumentParser:
    """The ``blocks`` command."""
    types = sub.add_parser("blocks", help="list block types with their ports and parameters",
                           description="Describe the registered block types (the library's and those "
                                       "packages register through the blocks.types entry points): their "
                                       "parameters with defaults, ports with widths, units and element "
                                       "names, and feedthrough.")
    types.add_argument("types", nargs="*", metavar="TYPE", help="only these types")
    types.set_defaults(handler=cmd_blocks)
    return types


def cmd_blocks(args: argparse.Namespace) -> int:
    """Describe the named types (default: all), or refuse unknown names with the known ones."""
    from blocks.registry import block_types
    from blocks.typeinfo import describe_type

    types = block_types()
    wanted = args.types or sorted(types)
    unknown = [t for t in wanted if t not in types]
    if unknown:
        raise UsageError(f"unknown block type(s): {', '.join(unknown)}; known: {', '.join(sorted(types))}")
    print("\n\n".join(describe_type(types[name]) for name in wanted))
    return EXIT_OK
