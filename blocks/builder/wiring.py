"""A diagram's wires checked and flattened: connections, its own ports, widths, inputs, logs.

Each level (``blocks.builder.scopes``) writes its wires between its blocks and its subsystems'
ports (``ctrl.e``); a subsystem's input stands for the inner inputs its ``inputs:``
lists, its output for the inner output its ``outputs:`` names. Here every wire becomes
the connections of the flat diagram, from an inner output to each inner input it
reaches, carrying the line and file where it is written; then widths are inferred over
the flat connections, every input must be driven (an unconnected subsystem input is
reported at the subsystem's entry), and the logged signals are resolved by path
(``ctrl.integ.y``).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field, replace
from typing import Any

from blocks.arrays import float_array
from blocks.block import checked_units
from blocks.builder.context import BuildContext, known, suggest
from blocks.builder.records import PortEntry, Site, WireEntry
from blocks.builder.diagram import BlockSpec, Composite, Connection, DeclaredReference, DiagramPort, LogEntry
from blocks.builder.annotations import annotate, check_connected_units
from blocks.builder.element_wiring import carried, check_assembled, received, resolve
from blocks.builder.elements import ElementError, Endpoint, parse_endpoint, parse_wire_end
from blocks.builder.scopes import NAME, Level
from blocks.builder.widths import propagate_widths
from blocks.limits import MAX_DECIMATE

_PATH = re.compile(r"^\s*[A-Za-z_][A-Za-z0-9_]*(?:\.[A-Za-z_][A-Za-z0-9_]*)+\s*$")

@dataclass
class Ports:
    """A level's own ports as checked: each input's inner inputs, each output's inner
    output (None: a port whose declaration is bad, reported)."""

    inputs: dict[str, list[Endpoint] | None] = field(default_factory=dict)
    outputs: dict[str, Endpoint | None] = field(default_factory=dict)
    fed: dict[Endpoint, str] = field(default_factory=dict)
    """Each local (name, port) an input of this level feeds -> that input's name."""


class Wiring:
    """The flat connections, log and levels of a diagram whose blocks are made (``specs``)."""

    def __init__(self, ctx: BuildContext, top: Level, specs: dict[str, BlockSpec], failed: set[str]):
        self.ctx = ctx
        self.top = top
        self.specs = specs
        self.failed = failed
        self.ports: dict[int, Ports] = {}
        self.connections: list[Connection] = []
        self.written: dict[int, Connection] = {}
        """id of a flat connection -> the wire it comes from, as its file writes it."""
        self.wires: dict[str, list[Connection]] = {}
        self.driven: dict[str, set[Endpoint]] = {}
        """Level path -> the (block path, port) its connections drive."""
        self.logged: dict[str, list[LogEntry]] = {}
        """Level path -> the signals it asks to log."""

    def file_of(self, site: Site) -> str | None:
        return site.file if site.file != self.top.file else None

    # -- ports of a level --------------------------------------------------------------

    def ports_of(self, level: Level) -> Ports:
        """The level's inputs and outputs, checked once."""
        found = self.ports.get(id(level))
        if found is not None:
            return found
        ports = self.ports[id(level)] = Ports()
        for decl in level.builder.inputs:
            name = self.port_name(level, decl, ports.inputs, "input")
            if name is None:
                continue
            targets: list[Endpoint] | None = []
            signals = decl.signals
            if not signals or not all(isinstance(s, str) for s in signals):
                self.ctx.add(decl.site.issue(f"diagram input '{name}' must name the inputs it feeds, "
                                             f"got {list(signals)!r}", "inputs: {e: [integ.u, prop.u]}"))
                targets = None
            for text in signals if targets is not None else ():
                ep = parse_endpoint(text)
                if ep is None:
                    self.ctx.add(decl.site.issue(f"diagram input '{name}': {text.strip()!r} is not 'block.port'",
                                                 "inputs: {e: [integ.u, prop.u]}"))
                    targets = None
                    continue
                other = ports.fed.get(ep)
                if other is not None:
                    self.ctx.add(decl.site.issue(f"input {level.flat(ep[0])}.{ep[1]} is fed by the diagram's "
                                                 f"inputs '{other}' and '{name}'", "an input takes one signal"))
                    targets = None
                    continue
                ports.fed[ep] = name
                reached = self.reach_input(level, ep, f"diagram input '{name}'", decl.site)
                if reached is None:
                    targets = None
                elif targets is not None:
                    targets.extend(reached)
            ports.inputs[name] = targets
        for decl in level.builder.outputs:
            name = self.port_name(level, decl, ports.outputs, "output")
            if name is None:
                continue
            if name in ports.inputs:  # 'sub.x' would name two ports
                self.ctx.add(decl.site.issue(f"the diagram's output '{name}' has the name of one of its inputs",
                                             "give each input and output of a diagram its own name"))
                continue
            (text,) = decl.signals
            ep = parse_endpoint(text)
            if ep is None:
                self.ctx.add(decl.site.issue(f"diagram output '{name}': {text!r} is not 'block.port'",
                                             "outputs: {u: u.y}"))
                ports.outputs[name] = None
                continue
            ports.outputs[name] = self.reach_output(level, ep, f"diagram output '{name}'", decl.site)
        return ports

    def port_name(self, level: Level, decl: PortEntry, seen: dict, kind: str) -> str | None:
        name = decl.name
        if not isinstance(name, str) or not NAME.match(name):
            self.ctx.add(decl.site.issue(f"invalid {kind} name {name!r}",
                                         "use letters, digits and '_' (not starting with a digit)"))
            return None
        if name in seen:
            self.ctx.add(decl.site.issue(f"the diagram's {kind} '{name}' is declared twice"))
            return None
        return name

    # -- where an endpoint leads ---------------------------------------------------------

    def reach_input(self, level: Level, ep: Endpoint, what: str, site: Site) -> list[Endpoint] | None:
        """The flat inputs ``ep`` (an input of a block or subsystem of ``level``) stands
        for; None if it is bad (reported) or spoiled."""
        found = self.lookup(level, ep, "inputs", what, site)
        return None if found is None else (found if isinstance(found, list) else [found])

    def reach_output(self, level: Level, ep: Endpoint, what: str, site: Site) -> Endpoint | None:
        found = self.lookup(level, ep, "outputs", what, site)
        return found if not isinstance(found, list) else None

    def lookup(self, level: Level, ep: Endpoint, kind: str, what: str, site: Site):
        name, port = ep
        flat = level.flat(name)
        if name in level.failed or flat in self.failed:
            return None
        if name in level.subsystems:
            sub = level.subsystems[name]
            ports = self.ports_of(sub)
            own, other = (ports.inputs, ports.outputs) if kind == "inputs" else (ports.outputs, ports.inputs)
            one = kind[:-1]
            if port not in own:
                hint = suggest(port, own) or f"{kind} of '{flat}': {known(own)}"
                if port in other:
                    hint = f"'{flat}.{port}' is an {'input' if kind == 'outputs' else 'output'}; " \
                           "connections go from an output to an input"
                self.ctx.add(site.issue(f"{what}: {sub.describe()} has no {one} '{port}'", hint))
                return None
            return own[port]
        spec = self.specs.get(flat)
        if spec is None:
            names = level.names()
            self.ctx.add(site.issue(f"{what}: no block named '{flat}'",
                                    suggest(flat, names) or f"blocks are: {known(names)}"))
            return None
        ports = getattr(spec.block, kind)
        if port not in ports:
            other = spec.block.inputs if kind == "outputs" else spec.block.outputs
            one = "output" if kind == "outputs" else "input"
            hint = suggest(port, ports) or f"{one}s of '{flat}' ({spec.type_name}): {known(ports)}"
            if port in other:
                hint = f"'{flat}.{port}' is an {'input' if kind == 'outputs' else 'output'}; " \
                       f"connections go from an output to an input"
            hint = spec.block.port_hint(port) or hint
            self.ctx.add(site.issue(f"{what}: block '{flat}' ({spec.type_name}) has no {one} '{port}'", hint))
            return None
        return (flat, port)

    # -- connections -------------------------------------------------------------------

    def connect(self, level: Level) -> None:
        """The level's wires as flat connections (and as written, ``wires``)."""
        wires = self.wires.setdefault(level.path, [])
        driven: dict[Endpoint, tuple[Connection, int | None]] = {}
        """Each input a wire drives whole; those that drive some elements go to ``partly``,
        checked element by element once the widths are known (``blocks.builder.element_wiring``)."""
        partly: dict[Endpoint, tuple[Connection, int | None]] = {}
        self.driven[level.path] = set()
        for w in level.builder.wires:
            written = self.wire(level, w)
            if written is None:
                continue
            wire, sources, targets = written
            key = (wire.dst_block, wire.dst_port)
            first_wire = driven.get(key) or (partly.get(key) if wire.dst_select is None else None)
            if first_wire is not None:
                first, line = first_wire
                self.ctx.add(w.site.issue(f"input {wire.dst} is driven twice: by {wire.src_text} and by "
                                          f"{first.src_text} (line {line})", "an input takes exactly one connection "
                                          "(or one per element: a.y -> g.u[0]); add a Sum block to combine signals"))
                continue
            (driven if wire.dst_select is None else partly).setdefault(key, (wire, w.site.line))
            wires.append(wire)
            if sources is None or targets is None:
                continue
            for dst in targets:
                same = sources == (wire.src_block, wire.src_port) and dst == (wire.dst_block, wire.dst_port)
                c = wire if same else replace(wire, src_block=sources[0], src_port=sources[1], dst_block=dst[0],
                                              dst_port=dst[1])
                self.connections.append(c)
                self.written[id(c)] = wire
        ports = self.ports_of(level)
        for (name, port), input_name in ports.fed.items():
            key = (level.flat(name), port)
            if key in driven or key in partly:
                first, line = driven.get(key) or partly[key]
                decl = next(d for d in level.builder.inputs if d.name == input_name)
                self.ctx.add(decl.site.issue(f"input {key[0]}.{port} is driven twice: by the diagram's input "
                                             f"'{input_name}' and by {first.src} (line {line})",
                                             "an input takes exactly one signal"))
        self.driven[level.path] = set(driven) | set(partly)

    def wire(self, level: Level, w: WireEntry):
        """(the wire as written, its flat source, its flat targets) or None (reported).
        The flat ends are None when an end is spoiled elsewhere."""
        site = w.site
        delay, initial = w.delay, None
        if delay is None:
            delay = 0
        if delay not in (0, 1) or isinstance(delay, bool):
            self.ctx.add(site.issue(f"connection delay must be 0 or 1, got {delay!r}",
                                    "delay: 1 is one sample of the destination's rate", key="delay"))
            return None
        if w.has_initial:
            try:
                initial = tuple(float(v) for v in float_array(w.initial, "initial", ndim=1))
            except ValueError:
                self.ctx.add(site.issue("connection 'initial' must be a number or list of numbers", key="initial"))
                return None
            if not delay:
                self.ctx.add(site.issue("'initial' only applies to a connection with delay: 1", key="initial"))
                return None
        src, dst = parse_wire_end(w.src), parse_wire_end(w.dst)
        text = f"{str(w.src).strip()} -> {str(w.dst).strip()}"
        if src is None or dst is None:
            bad = w.src if src is None else w.dst
            self.ctx.add(site.issue(f"connection '{text}': {str(bad).strip()!r} is not 'block.port'",
                                    self.path_hint(level, bad)
                                    or "e.g. - plant.y -> err.u1, or by element - plant.q[fore.1] -> pd.u"))
            return None
        what = f"connection '{text}'"
        sources = self.reach_output(level, src[:2], what, site)
        bad_src = sources is None and not self.spoiled(level, src[0])
        targets = self.reach_input(level, dst[:2], what, site)
        bad_dst = targets is None and not self.spoiled(level, dst[0])
        if bad_src or bad_dst:
            return None
        wire = Connection(level.flat(src[0]), src[1], level.flat(dst[0]), dst[1], int(delay), initial, site.line,
                          self.file_of(site), src_select=src[2], dst_select=dst[2])
        return wire, sources, targets

    def spoiled(self, level: Level, name: str) -> bool:
        return name in level.failed or level.flat(name) in self.failed

    def path_hint(self, level: Level, text: Any) -> str:
        """For ``ctrl.integ.u``: a subsystem is reached through its ports."""
        if not isinstance(text, str) or not _PATH.match(text):
            return ""
        first = text.strip().split(".")[0]
        if first not in level.subsystems:
            return ""
        sub = level.subsystems[first]
        ports = self.ports_of(sub)
        return (f"a connection reaches into subsystem '{sub.path}' through its ports: inputs "
                f"{known(ports.inputs)}; outputs {known(ports.outputs)}")

    # -- widths and inputs -------------------------------------------------------------

    def infer_widths(self) -> None:
        """Give polymorphic ports (width None) the width of what they connect to."""
        blocks = self.specs
        inferred = propagate_widths(lambda block, kind, port: getattr(blocks[block].block, kind)[port],
                                    self.connections)
        for name, spec in blocks.items():
            ports = {**spec.block.inputs, **spec.block.outputs}
            if any(w is None for w in ports.values()):
                if name not in inferred:
                    self.ctx.error(spec.file or self.top.file, spec.line,
                                   f"cannot infer the port widths of block '{name}' ({spec.type_name}): nothing "
                                   "with a known width is connected to it",
                                   "connect it to a block with fixed widths or give it a width parameter")
                    continue
                try:
                    spec.block.set_width(inferred[name])
                except ValueError as e:
                    self.ctx.error(spec.file or self.top.file, spec.line,
                                   f"block '{name}' ({spec.type_name}) cannot take the width {inferred[name]} of "
                                   f"what it connects to: {e}", "fix its parameters or give it a width parameter")
                    self.failed.add(name)
        annotate(self.top.levels(), blocks, self.failed, self.report)
        unresolved = self.resolve_elements()
        for c in self.connections:
            if id(c) in unresolved:
                continue
            ws, wd = carried(c, blocks), received(c, blocks)
            wire = self.written[id(c)]
            dst = c.dst_text if wire.dst == c.dst else f"{wire.dst_text} ({c.dst})"
            what = "has width" if c.src_elements is None else "selects"
            into = "has width" if c.dst_elements is None else "selects"
            if ws is not None and wd is not None and ws != wd:
                self.ctx.error(c.file or self.top.file, c.line,
                               f"connection '{wire.src_text} -> {wire.dst_text}': width mismatch: {wire.src_text} "
                               f"{what} {ws}, {dst} {into} {wd}", "insert a Gain with a matrix k to map "
                               "between widths, select elements (c.y[0:2] -> g.u), or fix the block parameters")
            elif c.initial is not None and ws is not None and len(c.initial) not in (1, ws):
                self.ctx.error(c.file or self.top.file, c.line,
                               f"connection '{wire.src_text} -> {wire.dst_text}': 'initial' has "
                               f"{len(c.initial)} values, the signal has width {ws}")

    def resolve_elements(self) -> set[int]:
        """The elements each connection's selections name, now that the widths are known;
        a selection that names none is reported at its connection (the ids of those returned)."""
        resolved, unresolved = [], set()
        for c in self.connections:
            wire = self.written.pop(id(c))
            if c.by_element and all(w is not None for w in (self.specs[c.src_block].block.outputs[c.src_port],
                                                             self.specs[c.dst_block].block.inputs[c.dst_port])):
                try:
                    c = resolve(c, wire, self.specs, self.labels)
                except ElementError as exc:
                    self.ctx.error(c.file or self.top.file, c.line, f"connection '{wire.src_text} -> "
                                   f"{wire.dst_text}': {exc}", "elements by label, by index from 0, or a slice "
                                   "start:stop, e.g. plant.q[fore.1], c.y[0:3]")
                    unresolved.add(id(c))
            resolved.append(c)
            self.written[id(c)] = wire
        self.connections[:] = resolved
        return unresolved

    def labels(self, block: str, port: str):
        """The element names of ``block.port`` (an output or input), or None."""
        return self.specs[block].element_labels(port)

    def report(self, file: str | None, line: int | None, message: str, hint: str = "") -> None:
        self.ctx.error(file or self.top.file, line, message, hint)

    def check_inputs(self) -> None:
        """Every input is driven, has a default, or is one of the top diagram's own inputs;
        a subsystem's input that nothing drives is reported at its entry; the elements of
        an input that connections assemble are each driven once."""
        check_assembled(self.connections, self.written, self.specs, self.report)
        check_connected_units(self.connections, self.written, self.specs, self.report)
        driven = {(c.dst_block, c.dst_port) for c in self.connections}
        fed_by_port = set()
        for level in self.top.levels():
            ports = self.ports_of(level)
            for targets in ports.inputs.values():
                fed_by_port.update(targets or ())
            for local, sub in level.subsystems.items():
                sub_ports = self.ports_of(sub)
                for port, targets in sub_ports.inputs.items():
                    mine = (local, port)
                    if (level.flat(local), port) in self.driven[level.path] or mine in ports.fed or not targets:
                        continue
                    if any(t[1] not in self.specs[t[0]].block.input_defaults for t in targets):
                        self.ctx.add(sub.entry.site.issue(
                            f"input {sub.path}.{port} of {sub.describe()} is not connected",
                            f"add a connection '- <block>.<port> -> {local}.{port}'"))
        for name, spec in self.specs.items():
            for port in spec.block.inputs:
                if (name, port) in driven or port in spec.block.input_defaults or (name, port) in fed_by_port:
                    continue
                local = name.rpartition(".")[2]
                self.ctx.error(spec.file or self.top.file, spec.line,
                               f"input {name}.{port} of block '{name}' ({spec.type_name}) is not connected",
                               f"add a connection '- <block>.<port> -> {local}.{port}'")

    # -- logged signals ----------------------------------------------------------------

    def log(self) -> list[LogEntry]:
        """The logged signals of every level, the top's first; a signal an including level
        logs already is not logged again."""
        entries: list[LogEntry] = []
        logged: set[str] = set()
        for level in self.top.levels():
            here: set[str] = set()
            asked = self.logged.setdefault(level.path, [])
            for request in level.builder.logs:
                for entry in self.log_request(level, request):
                    if entry.signal in here:
                        self.ctx.add(request.site.issue(f"signal '{entry.signal}' is logged twice"))
                        continue
                    here.add(entry.signal)
                    asked.append(entry)
                    if entry.signal not in logged:
                        logged.add(entry.signal)
                        entries.append(entry)
        return entries

    def log_request(self, level: Level, request) -> list[LogEntry]:
        site = request.site
        file = self.file_of(site)
        if request.every:
            inside = {sub.flat(n) for sub in level.levels() for n in sub.blocks}
            return [LogEntry(name, port, 1, site.line, file) for name, spec in self.specs.items() if name in inside
                    for port in spec.block.outputs]
        decimate = request.decimate
        if not isinstance(decimate, int) or isinstance(decimate, bool) or not 1 <= decimate <= MAX_DECIMATE:
            self.ctx.add(site.issue(f"log decimate must be a whole number from 1 to {MAX_DECIMATE}, got "
                                    f"{decimate!r}", key="decimate"))
            return []
        text = request.signal
        if not isinstance(text, str) or not _PATH.match(text):
            self.ctx.add(site.issue(f"log entry {text!r} is not 'block.port'", "e.g. - plant.y"))
            return []
        *names, port = text.strip().split(".")
        here = level
        for i, name in enumerate(names):
            flat = here.flat(name)
            last = i == len(names) - 1
            if name in here.failed or flat in self.failed:
                return []
            if name in here.subsystems:
                if last:
                    sub = here.subsystems[name]
                    source = self.ports_of(sub).outputs.get(port)
                    hint = (f"log the signal its output '{port}' comes from: {source[0]}.{source[1]}"
                            if source else f"log a signal of a block inside it: {flat}.<block>.<port>")
                    self.ctx.add(site.issue(f"log entry '{flat}.{port}': '{flat}' is a subsystem", hint))
                    return []
                here = here.subsystems[name]
                continue
            if name not in here.blocks:
                names_here = here.names()
                self.ctx.add(site.issue(f"log entry '{flat}.{port}': no block named '{flat}'",
                                        suggest(flat, names_here) or f"blocks are: {known(names_here)}"))
                return []
            if not last:
                self.ctx.add(site.issue(f"log entry '{text.strip()}': '{flat}' is a block, not a subsystem"))
                return []
        spec = self.specs[flat]
        outputs = spec.block.outputs
        if port not in outputs:
            self.ctx.add(site.issue(f"log entry '{flat}.{port}': block '{flat}' ({spec.type_name}) has no output "
                                    f"'{port}'", spec.block.port_hint(port) or suggest(port, outputs)
                                    or f"outputs: {known(outputs)}"))
            return []
        return [LogEntry(flat, port, decimate, site.line, file)]

    # -- the levels as written ---------------------------------------------------------

    def composite(self, level: Level, name: str) -> Composite:
        """The level as its file wrote it, for ``Diagram.root`` / ``Diagram.subsystems``."""
        ports = self.ports_of(level)
        inputs = {n: self.diagram_port(n, [(b, p) for b, p in targets], "inputs", decl.site)
                  for (n, targets), decl in zip(ports.inputs.items(), level.builder.inputs)}
        outputs = {n: self.diagram_port(n, [source], "outputs", decl.site)
                   for (n, source), decl in zip(ports.outputs.items(), level.builder.outputs)}
        entry = level.entry
        references = {n: DeclaredReference(n, _type_text(r.stand_in), r.site.line)
                      for n, r in level.references.items()}
        return Composite(level.path, name, level.file if level.builder.texts else None,
                         entry.site.line if entry else None, level.parent.file if level.parent else None,
                         entry.source if entry else None, tuple(level.flat(n) for n in level.blocks),
                         tuple(s.path for s in level.subsystems.values()), tuple(self.wires.get(level.path, ())),
                         tuple(self.logged.get(level.path, ())), inputs, outputs, references,
                         {n: b.target for n, b in level.bindings.items() if b is not None},
                         dict(entry.bind or {}) if entry else {}, dict(level.params))

    def diagram_port(self, name: str, signals: list[Endpoint], kind: str, site: Site) -> DiagramPort:
        blocks = [(self.specs[b].block, p) for b, p in signals]
        widths = {getattr(blk, kind)[p] for blk, p in blocks}
        if len(widths) > 1:
            self.ctx.add(site.issue(f"diagram input '{name}' feeds inputs of different widths: " + ", ".join(
                f"{b}.{p} [{getattr(self.specs[b].block, kind)[p]}]" for b, p in signals),
                "the inputs one diagram input feeds take the same signal"))
        units = labels = None
        for (b, p), (blk, _) in zip(signals, blocks):
            if units is None:
                try:
                    units = checked_units(self.specs[b].port_units(p), getattr(blk, kind)[p], p)
                except ValueError:
                    units = None
            if labels is None:
                found = self.specs[b].element_labels(p)
                labels = tuple(str(x) for x in found) if found is not None else None
        return DiagramPort(name, tuple(f"{b}.{p}" for b, p in signals), min(widths), units, labels, site.line,
                           self.file_of(site))


def _type_text(stand_in: Any) -> str | None:
    if stand_in is None or isinstance(stand_in, str):
        return stand_in
    return getattr(stand_in, "registered_name", lambda: str(stand_in))()
