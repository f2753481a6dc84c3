"""``assemble``: a ``DiagramRecord``'s record made into a checked, flat ``Diagram``.

The passes, in order: the diagram's own fields (name, description, end time); its tree
of subsystems as levels, with overrides and block references routed (``blocks.builder.scopes``);
the blocks, checked and constructed (``blocks.builder.construct``); the wires, flattened and
checked, with widths, inputs and logged signals (``blocks.builder.wiring``). Every pass reports
into one ``BuildContext``, and the Diagram is made only when none found a problem.
"""

from __future__ import annotations

import json
from fractions import Fraction
from typing import Any

from blocks.builder.context import BuildContext
from blocks.builder.records import DiagramRecord, Site
from blocks.builder.construct import Constructor
from blocks.builder.diagram import Diagram, jsonable
from blocks.issues import DiagramError
from blocks.builder.scopes import expand
from blocks.timebase import DurationError, positive_duration
from blocks.builder.wiring import Wiring


def assemble(root: DiagramRecord, overrides: dict[str, Any], origins: dict[str, str]) -> Diagram:
    """The Diagram ``root`` describes, with ``overrides``; DiagramError with every problem."""
    ctx = BuildContext(overrides, origins, dict(root.files_map))
    ctx.files.update(root.files_read)
    for text in root.texts or [root.fingerprint()]:
        ctx.hash.update(text.encode("utf-8"))
    ctx.hash.update(json.dumps(jsonable(overrides), sort_keys=True).encode())
    name = text_field(ctx, root, "name", root.name, "diagram")
    description = text_field(ctx, root, "description", root.description, "")
    t_end, t_end_line = end_time(ctx, root)
    top = expand(ctx, root)
    constructor = Constructor(ctx, top)
    blocks = constructor.make_all()
    wiring = Wiring(ctx, top, blocks, constructor.failed)
    for level in top.levels():
        wiring.ports_of(level)
        wiring.connect(level)
    if not ctx.issues:
        wiring.infer_widths()
    if not ctx.issues:
        wiring.check_inputs()
    log = wiring.log()
    for level in top.levels():
        if not level.builder.entries and not level.builder.problems:
            ctx.add(level.builder.site.issue("the diagram needs a non-empty 'blocks' mapping",
                                             "blocks: {name: {type: Gain, params: {k: 2}}, ...}", key="blocks"))
    if not ctx.issues:
        composites = [wiring.composite(level, text_field(ctx, level.builder, "name", level.builder.name, "diagram"))
                      for level in top.levels()]
    issues = ctx.unique_issues()
    if issues:
        raise DiagramError(issues)
    return Diagram(name=name, description=description, file=root.file, blocks=blocks,
                   connections=wiring.connections, log=log, t_end=t_end, source_hash=ctx.hash.hexdigest(),
                   t_end_line=t_end_line, base_dir=root.base_dir, files=dict(ctx.files), root=composites[0],
                   subsystems={c.path: c for c in composites[1:]})


def text_field(ctx: BuildContext, builder: DiagramRecord, key: str, value: Any, default: str) -> str:
    if not isinstance(value, str):
        ctx.add(builder.site.issue(f"'{key}' must be text, got {type(value).__name__}", key=key))
        return default
    return value


def end_time(ctx: BuildContext, builder: DiagramRecord) -> tuple[Fraction | None, int | None]:
    """The diagram's end time (None: not given) and the line it is written on."""
    if builder.t_end is None:
        return None, None
    site: Site = builder.t_end_site or builder.site
    line = site.key("t_end")
    try:
        return positive_duration(builder.t_end, "time.t_end"), line
    except DurationError as exc:
        ctx.error(site.file, line, str(exc))
        return None, line
