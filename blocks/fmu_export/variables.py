"""An exported diagram's FMU variables: its inputs, outputs and tunable parameters.

- Inputs: the diagram's own inputs (``inputs:``), one scalar per element (``q[1]``, ...;
  a port of width 1 keeps its name), each written to the buffers of the inner inputs it
  feeds; start value the inner input's default (or 0).
- Outputs: the diagram's own outputs (``outputs:``); a diagram without any has its logged
  signals as outputs, named by the signal (``plant.q[1]``), so a closed loop can be
  watched. Each output depends on the inputs that reach it through blocks with
  feedthrough (``ModelStructure``), so an importer that sets the inputs of a
  communication point before reading the outputs sees them feed through.
- Parameters: the tunables of the blocks' records, under their dotted names
  (``reflex.ki``, ``plant.object.mass``; in a diagram of one block without the block's
  name, ``object.mass``, but ``step.time`` for ``time``, FMI 3's independent variable),
  their start values what the diagram gives.

Units and element names come from the diagram (``Diagram.port_units``, ``element_labels``:
a block's own, or those the diagram gives its port with ``units:`` / ``elements:``; a
diagram input's from the ports it feeds) and the tunables; element names go into each
variable's description.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from blocks.builder.diagram import Diagram
from ..issues import DiagramError
from blocks.engine.optable import B_FIRST_INPUT, B_FIRST_PORT, I_OFFSET, P_OFFSET
from .plan import Plan

VR_TIME = 0
VR_FIRST = 1


@dataclass(frozen=True)
class Variable:
    name: str
    vr: int
    causality: str
    description: str
    unit: str | None = None
    start: float | None = None
    offsets: tuple[int, ...] = ()
    """Input: the arena offsets it is written to; output: its one offset."""
    block: int = -1
    slot: int = -1
    finite: bool = False
    minimum: float | None = None
    maximum: float | None = None
    """Parameter: its block and record slot, whether the FMU checks that it is finite,
    and the range its block holds it to (``Tunable``)."""
    discrete: bool = False
    """Output: it changes only at its block's hits (a sampled block's, such as a
    controller's torques), held in between (variability ``discrete``)."""
    depends: tuple[int, ...] = ()
    initial_depends: tuple[int, ...] = ()
    """Output: the input variables (their positions among the inputs) it depends on, at a
    communication point and at initialization."""


@dataclass(frozen=True)
class FollowRule:
    block: int
    slot: int
    when: tuple[int, ...]
    unless: tuple[int, ...]


@dataclass(frozen=True)
class LinkRule:
    block: int
    slot: int
    source: int
    source_slot: int
    length: int


@dataclass
class Variables:
    inputs: list[Variable] = field(default_factory=list)
    outputs: list[Variable] = field(default_factory=list)
    parameters: list[Variable] = field(default_factory=list)
    follows: list[FollowRule] = field(default_factory=list)
    links: list[LinkRule] = field(default_factory=list)

    @property
    def vr_input(self) -> int:
        return VR_FIRST

    @property
    def vr_output(self) -> int:
        return VR_FIRST + len(self.inputs)

    @property
    def vr_param(self) -> int:
        return self.vr_output + len(self.outputs)


def output_signals(diagram: Diagram) -> list[tuple[str, str]]:
    """(FMU name, inner signal) of each output: the diagram's outputs, else its logged signals."""
    if diagram.outputs:
        return [(name, port.signals[0]) for name, port in diagram.outputs.items()]
    return [(e.signal, e.signal) for e in diagram.log]


def fmu_variables(plan: Plan) -> Variables:
    d, t = plan.diagram, plan.table
    names = t.names
    index = {n: i for i, n in enumerate(names.blocks)}
    v = Variables()
    input_of: dict[tuple[str, str], int] = {}
    """Inner input port -> its diagram input (position among the diagram's inputs)."""
    for k, (name, port) in enumerate(d.inputs.items()):
        offsets_per_signal = []
        for signal in port.signals:
            block, inner = signal.rsplit(".", 1)
            b = index[block]
            row = int(t.blocks[b, B_FIRST_INPUT]) + names.inputs[b].index(inner)
            offsets_per_signal.append(int(t.inputs[row, I_OFFSET]))
            input_of[block, inner] = k
        for i in range(port.width):
            offsets = tuple(o + i for o in offsets_per_signal)
            v.inputs.append(Variable(_element(name, i, port.width), v.vr_input + len(v.inputs), "input",
                                     _describe(f"input {name}", port.labels, i, port.signals),
                                     _unit(port.units, i), float(t.initial[offsets[0]]), offsets))
    input_vars = _first_variables(d, v.inputs)
    outputs = output_signals(d)
    for name, signal in outputs:
        block, port = signal.rsplit(".", 1)
        b = index[block]
        width = d.blocks[block].block.outputs[port]
        base = int(t.ports[int(t.blocks[b, B_FIRST_PORT]) + names.ports[b].index(port), P_OFFSET])
        depends = _reaching(d, block, port, input_of, initial=False)
        initial = _reaching(d, block, port, input_of, initial=True)
        labels, units = d.element_labels(block, port), d.port_units(block, port)
        for i in range(width):
            v.outputs.append(Variable(
                _element(name, i, width), 0, "output", _describe(f"output {signal}", labels, i, ()),
                _unit(units, i), offsets=(base + i,), discrete=_sampled(d, block, input_of, set()),
                depends=tuple(j for k in sorted(depends) for j in input_vars[k]),
                initial_depends=tuple(j for k in sorted(initial) for j in input_vars[k])))
    v.outputs = [Variable(**{**o.__dict__, "vr": v.vr_output + i}) for i, o in enumerate(v.outputs)]
    _parameters(plan, v, index)
    return v


def _parameters(plan: Plan, v: Variables, index: dict[str, int]) -> None:
    d = plan.diagram
    alone = len(plan.blocks) == 1
    by_object = {id(d.blocks[n].block): i for n, i in index.items()}
    for b, eb in enumerate(plan.blocks):
        rec = eb.record
        mine = {}
        for tunable in rec.tunables:
            mine[tunable.name] = len(v.parameters)
            name = tunable.name if alone and tunable.name != "time" else f"{eb.name}.{tunable.name}"
            v.parameters.append(Variable(name, v.vr_param + len(v.parameters), "parameter",
                                         tunable.description or f"parameter {tunable.name} of block '{eb.name}'",
                                         tunable.unit, float(rec.values[tunable.slot]), block=b, slot=tunable.slot,
                                         finite=tunable.finite, minimum=tunable.minimum, maximum=tunable.maximum))
        for rule in rec.follows:
            when = tuple(mine[n] for n in rule.when_set if n in mine)
            if when:
                v.follows.append(FollowRule(b, rule.slot, when, tuple(mine[n] for n in rule.unless_set if n in mine)))
        for link in rec.links:
            source = by_object.get(id(link.source))
            if source is not None:
                v.links.append(LinkRule(b, link.slot, source, link.source_slot, link.length))
    if len({p.name for p in v.parameters}) != len(v.parameters):
        raise DiagramError([d.issue(None, "two tunable parameters of the exported diagram have the same name")])


def _sampled(d: Diagram, block: str, input_of: dict[tuple[str, str], int], seen: set[str]) -> bool:
    """Whether ``block``'s outputs change only at the hits of sampled blocks: it is no
    sampled continuous-time model (``Block.samples_continuous_time``) and has a period of
    its own, or inherits one from blocks that are sampled alone (not from the diagram's
    inputs, which may change at every communication step)."""
    spec = d.blocks[block]
    if spec.block.samples_continuous_time:
        return False
    if spec.period is not None or block in seen:
        return True
    seen.add(block)
    if any((block, port) in input_of for port in spec.block.inputs):
        return False
    return all(_sampled(d, c.src_block, input_of, seen) for c in d.connections if c.dst_block == block)


def _first_variables(d: Diagram, inputs: list[Variable]) -> list[list[int]]:
    """Per diagram input, the positions of its variables among the inputs."""
    out, at = [], 0
    for port in d.inputs.values():
        out.append(list(range(at, at + port.width)))
        at += port.width
    return out


def _reaching(d: Diagram, block: str, port: str, input_of: dict[tuple[str, str], int], initial: bool) -> set[int]:
    """The diagram inputs that reach output ``block.port`` through same-tick feedthrough
    (at tick 0 through the blocks' initial feedthrough)."""
    feeding = {(c.dst_block, c.dst_port): c for c in d.connections}
    found: set[int] = set()
    seen: set[tuple[str, str]] = set()
    stack = [(block, port)]
    while stack:
        b, p = stack.pop()
        if (b, p) in seen:
            continue
        seen.add((b, p))
        blk = d.blocks[b].block
        for inner in (blk.initial_reads(p) if initial else blk.reads(p)):
            if (b, inner) in input_of:
                found.add(input_of[b, inner])
            c = feeding.get((b, inner))
            if c is not None and not c.delay:
                stack.append((c.src_block, c.src_port))
    return found


def _element(name: str, i: int, width: int) -> str:
    return f"{name}[{i + 1}]" if width > 1 else name


def _unit(units, i: int) -> str | None:
    if units is None:
        return None
    unit = units if isinstance(units, str) else units[i]
    return unit or None


def _describe(what: str, labels, i: int, signals: tuple[str, ...]) -> str:
    text = what
    if labels:
        text += f", element {labels[i]}"
    if signals:
        text += f" (feeds {', '.join(signals)})"
    return text
