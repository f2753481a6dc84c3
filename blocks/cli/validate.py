"""``validate``: check a diagram and print its blocks (as a tree of its subsystems), rates,
ports, references and execution order."""

from __future__ import annotations

import argparse

from .options import diagram_args, end_time, load
from .program import EXIT_OK


def add(sub, program) -> argparse.ArgumentParser:
    """The ``validate`` command."""
    validate = sub.add_parser("validate", help="check a diagram and print its schedule",
                              description="Check DIAGRAM and print blocks, periods, base tick, "
                                          "hyperperiod and execution order. Nothing is run: an FMU's "
                                          "binary is not loaded.")
    diagram_args(validate)
    validate.add_argument("--plan", action="store_true",
                          help="also print the run's op table: blocks, programs of ops, copies and logs, with names")
    validate.set_defaults(handler=cmd_validate)
    return validate


def cmd_validate(args: argparse.Namespace) -> int:
    from blocks import build_schedule
    from blocks.timebase import format_duration

    diagram = load(args)
    t_end = end_time(args, diagram) if (args.t_end or diagram.t_end) else None
    s = build_schedule(diagram, t_end)
    print(f"diagram {diagram.name!r} ({diagram.file}): valid")
    if diagram.description:
        print(f"  {diagram.description}")
    print(f"base tick: {format_duration(s.base_tick)}; hyperperiod: {s.hyperperiod} ticks "
          f"({format_duration(s.hyperperiod * s.base_tick)})"
          + (f"; t_end: {format_duration(t_end)} = {s.n_ticks} ticks" if t_end else ""))
    print("blocks:")
    print_block_tree(diagram, s)
    print_terms(diagram, s)
    print_ports(diagram)
    print_element_wiring(diagram)
    print_references_and_notes(diagram)
    print("execution order:")
    print(f"  t = 0: {s.initial.describe()}")
    for held in s.initial_held:
        print(f"    {held.block}.{held.port} holds its initial value at t = 0: {held.block} is computed "
              f"before its source, which depends on it ({held.loop})")
    seen: dict[int, list[int]] = {}
    for r, j in zip(s.event_ticks, s.event_programs):
        seen.setdefault(j, []).append(int(r))
    for j, ticks in seen.items():
        at = ", ".join(format_duration(r * s.base_tick) for r in ticks[:6]) + (", ..." if len(ticks) > 6 else "")
        print(f"  at {at} (mod {format_duration(s.hyperperiod * s.base_tick)}): {s.programs[j].describe()}")
    if not s.event_ticks.size and s.advanced:
        print(f"  no other events: {', '.join(sorted(s.advanced))} advanced from t = 0 to t_end")
    if args.plan:
        from blocks.engine.optable import op_table
        from blocks.engine.optable_text import describe_table

        t_end = t_end if t_end is not None else end_time(args, diagram)
        print(describe_table(op_table(diagram, build_schedule(diagram, t_end))))
    return EXIT_OK


def print_block_tree(diagram, s) -> None:
    """Each block with its type, rate and ports; a subsystem's blocks indented under a
    line of its own (its file, ports and what it was given) where its entry stands."""
    def indent(path: str) -> str:
        return "  " * (1 + sum(1 for sub in diagram.subsystems if path.startswith(sub + ".")))

    wn = max(len(indent(n)) + len(n) for n in diagram.blocks)
    wt = max(len(b.type_name) for b in diagram.blocks.values())
    shown: set[str] = set()
    for name, spec in diagram.blocks.items():
        for path, sub in diagram.subsystems.items():
            if name.startswith(path + ".") and path not in shown:
                shown.add(path)
                print(f"{indent(path)}{path}: subsystem {sub.origin} (diagram {sub.diagram_name!r})"
                      + "".join(f"; {part}" for part in subsystem_parts(sub)))
        blk = spec.block
        ins = ", ".join(port_of(spec, p, w) for p, w in blk.inputs.items()) or "-"
        outs = ", ".join(port_of(spec, p, w) for p, w in blk.outputs.items()) or "-"
        notes = []
        if name in s.advanced:
            notes.append("advanced between events")
        if blk.has_feedthrough():
            notes.append("feedthrough")
        if any(blk.initial_reads(p) != blk.reads(p) for p in blk.outputs):
            initial = sorted(set().union(*(blk.initial_reads(p) for p in blk.outputs)))
            notes.append(f"feedthrough at t = 0 from {', '.join(initial)}" if initial
                         else "no feedthrough at t = 0")
        label = indent(name) + name
        print(f"{label:<{wn}}  {spec.type_name:<{wt}}  {s.rate_text(name):<22} in: {ins}  out: {outs}"
              + (f"  ({', '.join(notes)})" if notes else ""))


TERMS = {
    "inherited": "fires whenever a block feeding it fires",
    "lazy": "a stateless block of inherited rate, computed only when a block that fires reads it, "
            "so it adds no events of its own",
    "advanced between events": "stepped over the ticks where nothing else fires in one call",
}
"""The words of the block list that need saying once, and what they mean."""


def print_terms(diagram, s) -> None:
    """One line explaining each of ``TERMS`` the block list used."""
    texts = [s.rate_text(name) for name in diagram.blocks]
    used = {"inherited": any("inherited" in t for t in texts), "lazy": bool(s.lazy),
            "advanced between events": bool(s.advanced)}
    for term, meaning in TERMS.items():
        if used[term]:
            print(f"  ({term}: {meaning})")


def port_of(spec, port: str, width: int) -> str:
    """A block's port as ``validate`` lists it: ``y[3]``, with the unit(s) where the block or
    the diagram gives them (``q[9] (rad)``, ``pose[3] (m, m, rad)``) and the names the diagram
    gives its elements (``y[3] {x, y, theta}``)."""
    from blocks.block import checked_units

    try:
        units = checked_units(spec.port_units(port), width, port)
    except ValueError:
        units = None
    text = f"{port}[{width}]"
    if units:
        text += f" ({units})" if isinstance(units, str) else f" ({', '.join(u or '?' for u in units)})"
    if port in spec.labels:
        text += " {" + ", ".join(spec.labels[port]) + "}"
    return text


def subsystem_parts(sub) -> list[str]:
    """A subsystem's ports, bindings and the overrides it was given, as ``validate`` shows them."""
    def inner(port) -> str:
        return ", ".join(sub.name_of(signal) for signal in port.signals)

    parts = [f"in: {'; '.join(f'{port_text(p)} -> {inner(p)}' for p in sub.inputs.values())}" if sub.inputs else "",
             f"out: {'; '.join(f'{port_text(p)} <- {inner(p)}' for p in sub.outputs.values())}"
             if sub.outputs else "",
             f"bind: {', '.join(f'{r} -> {b}' for r, b in sub.bindings.items())}" if sub.bindings else "",
             f"params: {', '.join(f'{k}={v!r}' for k, v in sub.params.items())}" if sub.params else ""]
    return [p for p in parts if p]


def port_text(port) -> str:
    """A port as ``validate`` names it: ``e[1]``, with its unit where known (``q[9] (rad)``)."""
    return f"{port.name}[{port.width}]" + (f" ({port.units})" if isinstance(port.units, str) else "")


def print_ports(diagram) -> None:
    """The diagram's own inputs and outputs and the references it leaves to an includer."""
    for kind, ports, arrow in (("inputs", diagram.inputs, "->"), ("outputs", diagram.outputs, "<-")):
        if ports:
            print(f"{kind} (of the diagram as a subsystem):")
            for port in ports.values():
                print(f"  {port_text(port)} {arrow} {', '.join(port.signals)}")
    refs = diagram.root.references if diagram.root else {}
    if refs:
        print("references the including diagram binds:")
        for ref in refs.values():
            print(f"  {ref.name}" + (f" (stand-in here: {ref.type_name})" if ref.type_name else ""))


def print_element_wiring(diagram) -> None:
    """The connections that name elements, each with the 0-based elements it stands for
    (``m.y[pos.1] -> g.u  (m.y[2] -> g.u)``)."""
    wires = [c for c in diagram.connections if c.by_element]
    if not wires:
        return
    print("wiring by element:")
    for c in wires:
        src = c.src if c.src_elements is None else f"{c.src}[{index_text(c.src_elements)}]"
        dst = c.dst if c.dst_elements is None else f"{c.dst}[{index_text(c.dst_elements)}]"
        print(f"  {c}" + ("" if (src, dst) == (c.src_text, c.dst_text) else f"  ({src} -> {dst})"))


def index_text(indices) -> str:
    """0-based indices as a selection writes them: ``2``, ``0:3``, ``3,0,1``."""
    if len(indices) > 1 and list(indices) == list(range(indices[0], indices[0] + len(indices))):
        return f"{indices[0]}:{indices[0] + len(indices)}"
    return ",".join(str(j) for j in indices)


def print_references_and_notes(diagram) -> None:
    """``validate``'s block references (``reflex.hand -> plant``) and, per block, where its
    configuration comes from: its params_file, its own ``describe()``, who refers to it."""
    references = diagram.references()
    if references:
        print("references:")
        for ref in references:
            print(f"  {ref}")
    notes = []
    for name, spec in diagram.blocks.items():
        users = [f"{r.block}.{r.param}" for r in references if r.target == name]
        parts = [f"params_file {spec.params_file}" if spec.params_file else "", spec.block.describe(),
                 f"referenced by {', '.join(users)}" if users else ""]
        if any(parts):
            notes.append(f"  {name}: {'; '.join(p for p in parts if p)}")
    if notes:
        print("notes:")
        print("\n".join(notes))
    conversions = diagram.conversions()
    if conversions:
        print("conversions (connections between ports of different types):")
        for conversion in conversions:
            print(f"  {conversion}")
