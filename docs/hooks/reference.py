"""MkDocs hook: the pages' generated parts, made from the code at each build.

A page asks for a generated part with a marker comment on a line of its own:

- ``<!-- generated: block-reference -->``: every registered block type (the framework's
  library and the ``blocks.types`` entry points) with its parameters, ports, units,
  element names and feedthrough, read through ``blocks.typeinfo.type_info``, the record
  ``hierhand blocks`` prints;
- ``<!-- generated: cli-synopsis -->``: one usage line per command of ``hierhand``;
- ``<!-- cli: hierhand run -->`` (any command's words): that command's usage and options,
  read from the argument parsers ``hierhand.cli.PROGRAM`` builds.

The build fails (strict or not) when a command of the parser has no ``<!-- cli: ... -->``
marker on the page that holds the synopsis, so a new command or subcommand cannot go
undocumented, and when a marker names a command that does not exist.
"""

from __future__ import annotations

import argparse
import re

from mkdocs.exceptions import PluginError

MARKER = re.compile(r"^<!-- (?P<kind>generated|cli): (?P<what>[^>]+?) -->$", re.MULTILINE)


def on_page_markdown(markdown: str, page, config, files) -> str:
    """The page with each marker replaced by what it asks for."""
    commands = leaf_commands()
    found = {m["what"] for m in MARKER.finditer(markdown) if m["kind"] == "cli"}
    if "<!-- generated: cli-synopsis -->" in markdown:
        missing = sorted(set(commands) - found)
        if missing:
            raise PluginError(f"{page.file.src_uri}: no '<!-- cli: ... -->' section for: {', '.join(missing)}")

    def replace(match: re.Match) -> str:
        kind, what = match["kind"], match["what"]
        if kind == "cli":
            if what not in commands:
                raise PluginError(f"{page.file.src_uri}: '{what}' is not a command of {PROGRAM_NAME}")
            return command_section(commands[what])
        if what in GENERATORS:
            return GENERATORS[what]()
        raise PluginError(f"{page.file.src_uri}: unknown generated part '{what}'")

    return MARKER.sub(replace, markdown)


# -- the command line ------------------------------------------------------------------

PROGRAM_NAME = "hierhand"


def leaf_commands() -> dict[str, argparse.ArgumentParser]:
    """Every command that runs something, by its words (``hierhand fmu export``), in the
    order of the help; a group (``fmu``) is not one, its subcommands are."""
    from blocks.cli import build_parser
    from hierhand.cli import PROGRAM

    found: dict[str, argparse.ArgumentParser] = {}

    def walk(parser: argparse.ArgumentParser) -> None:
        subs = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
        if not subs:
            found[parser.prog] = parser
            return
        for choice in dict.fromkeys(subs[0].choices.values()):  # aliases share a parser
            walk(choice)

    walk(build_parser(PROGRAM))
    return found


def usage(parser: argparse.ArgumentParser) -> str:
    """The command's usage on one line, however long."""
    formatter = argparse.HelpFormatter(parser.prog, width=10_000)
    formatter.add_usage(parser.usage, parser._actions, parser._mutually_exclusive_groups, prefix="")
    return " ".join(formatter.format_help().split()).replace(" [-h]", "")


def synopsis() -> str:
    lines = [usage(p) for p in leaf_commands().values()]
    return "```text\n" + "\n".join(lines) + "\n```\n"


def command_section(parser: argparse.ArgumentParser) -> str:
    """Usage, description and a table of the arguments of one command."""
    rows = []
    for action in parser._actions:
        if isinstance(action, argparse._HelpAction) or action.help == argparse.SUPPRESS:
            continue
        if action.option_strings:
            name = ", ".join(action.option_strings)
            if action.nargs != 0:
                name += f" {action.metavar or action.dest.upper()}"
        else:
            name = str(action.metavar or action.dest)
        default = action.default
        shown = "" if default in (None, False, [], argparse.SUPPRESS) or action.nargs == 0 else f"`{default}`"
        rows.append(f"| `{name}` | {cell(action.help or '')} | {shown} |")
    table = "| argument | what | default |\n|---|---|---|\n" + "\n".join(rows) if rows else ""
    description = parser.description or ""
    return f"```text\n{usage(parser)}\n```\n\n{description}\n\n{table}\n"


def cell(text: str) -> str:
    """Text for a Markdown table cell: pipes escaped, ``%%`` as argparse prints it."""
    return " ".join(text.replace("%%", "%").replace("|", "\\|").split())


# -- the block types ----------------------------------------------------------------

def block_reference() -> str:
    """A section per registered block type, the framework's first, each group by name."""
    from blocks.registry import block_types
    from blocks.typeinfo import type_info

    infos = [type_info(cls) for cls in block_types().values()]
    groups = {"The framework's library (blocks)": [i for i in infos if i.qualname.startswith("blocks.")],
              "Installed by other packages (blocks.types entry points)":
                  [i for i in infos if not i.qualname.startswith("blocks.")]}
    parts = []
    for title, members in groups.items():
        if not members:
            continue
        members.sort(key=lambda i: i.name)
        parts.append(f"## {title}\n\n" + ", ".join(f"[`{i.name}`](#{i.name.lower()})" for i in members) + "\n")
        parts += [type_section(i) for i in members]
    return "\n".join(parts)


def type_section(info) -> str:
    from blocks.typeinfo import REQUIRED, unit_text

    lines = [f"### {info.name}", "", f"`{info.qualname}`", ""]
    if info.summary:
        lines += [info.summary, ""]
    if info.parameters:
        lines += ["| parameter | type | default | what |", "|---|---|---|---|"]
        for p in info.parameters:
            default = "required" if p.default is REQUIRED else f"`{p.default!r}`"
            kind = "a block's name" if p.block_reference else p.type
            lines.append(f"| `{p.name}` | {cell(kind)} | {cell(default)} | {cell(p.text)} |")
        lines.append("")
    if info.any_parameter:
        lines += ["Takes any further parameter (its own `**kwargs`).", ""]
    if info.inputs is None:
        lines += [f"Ports: {info.ports_note}.", ""]
    else:
        ports = [("input" + (" (optional)" if p.optional else ""), p) for p in info.inputs]
        ports += [("output", p) for p in info.outputs]
        if ports:
            lines += ["| port | direction | width | unit | elements |", "|---|---|---|---|---|"]
            for direction, p in ports:
                width = "inferred" if p.width is None else str(p.width)
                units = ", ".join(u or "?" for u in p.units) if isinstance(p.units, list) else \
                    (unit_text(p.units) if p.units else "")
                labels = ", ".join(p.labels) if p.labels else ""
                lines.append(f"| `{p.name}` | {direction} | {width} | {cell(units)} | {cell(labels)} |")
            lines.append("")
        lines.append(f"**Feedthrough:** {cell(info.feedthrough)}" +
                     (f"; at t = 0: {cell(info.initial_feedthrough)}" if info.initial_feedthrough else "") + ".")
        lines.append("")
    if info.time_varying:
        lines += ["A time-varying source: it needs a period of its own.", ""]
    return "\n".join(lines)


GENERATORS = {"block-reference": block_reference, "cli-synopsis": synopsis}
