"""A diagram's top-level blocks and subsystems as diagrams of their own, to leave as FMUs.

An SSP component is an FMU, so a block that is not an FMU block becomes one through the
FMU exporter (``blocks.fmu_export``): ``component_diagram`` makes the diagram it exports.
For a subsystem it is the subsystem's level as its file wrote it (its blocks, nested
subsystems and wires, its inputs and outputs the FMU's); for a block, that block alone,
every input and output port the FMU's. The blocks are the very objects of the loaded
diagram, so a block reference (``hand: plant``) carries what its target gave it when the
diagram was loaded, overrides included, though that target is another component; what
follows the target's tunable values at run time does not cross components (the FMUs
share no parameters). Names inside are the subsystem's own (``reflex``), so the FMU's
parameters are ``reflex.ki`` and an SSP's ``--set ctrl.reflex.ki`` names the diagram's
``ctrl.reflex.ki``.
"""

from __future__ import annotations

from fractions import Fraction

from blocks.builder.diagram_builder import DiagramBuilder
from blocks.builder.diagram import Composite, Connection, Diagram
from blocks.builder.records import Site


def component_diagram(diagram: Diagram, name: str, period: Fraction | None = None) -> Diagram:
    """The diagram of top-level block or subsystem ``name`` of ``diagram``, its ports the
    diagram's inputs and outputs; DiagramError as the builder finds it. ``period``: a
    block's period there (for a block that inherits its rate in ``diagram``)."""
    if name in diagram.subsystems:
        return _level(diagram, diagram.subsystems[name]).build()
    spec = diagram.blocks[name]
    b = DiagramBuilder(name, f"block '{name}' ({spec.type_name}) of the diagram '{diagram.name}'",
                       base_dir=diagram.base_dir, where=Site(diagram.file, spec.line))
    for target in dict.fromkeys(spec.references.values()):
        if target in diagram.blocks:
            b.reference(target, diagram.blocks[target].block)
    _add_block(b, diagram, name, name, period)
    for port in spec.block.inputs:
        b.input(port, f"{name}.{port}")
    for port in spec.block.outputs:
        b.output(port, f"{name}.{port}")
    return b.build()


def _level(diagram: Diagram, level: Composite) -> DiagramBuilder:
    """A builder of subsystem ``level`` with every name relative to it."""
    b = DiagramBuilder(level.diagram_name, f"subsystem '{level.path}' ({level.origin}) of the diagram "
                       f"'{diagram.name}'", base_dir=diagram.base_dir,
                       where=Site(level.including_file or diagram.file, level.line))
    for reference, target in level.bindings.items():
        if target in diagram.blocks:
            b.reference(reference, diagram.blocks[target].block)
    for path in level.blocks:
        _add_block(b, diagram, path, level.name_of(path))
    for path in level.subsystems:
        sub = diagram.subsystems[path]
        b.add_subsystem(level.name_of(path), _level(diagram, sub), where=Site(sub.including_file or "", sub.line))
    for wire in level.wires:
        b.connect(_end(level, wire.src_block, wire.src_port, wire.src_select),
                  _end(level, wire.dst_block, wire.dst_port, wire.dst_select),
                  delay=wire.delay, initial=None if wire.initial is None else list(wire.initial), where=_site(diagram, wire))
    for port in level.inputs.values():
        b.input(port.name, *(_local(level, s) for s in port.signals), where=Site(port.file or diagram.file, port.line))
    for port in level.outputs.values():
        b.output(port.name, _local(level, port.signals[0]), where=Site(port.file or diagram.file, port.line))
    return b


def _add_block(b: DiagramBuilder, diagram: Diagram, path: str, local: str, period: Fraction | None = None) -> None:
    spec = diagram.blocks[path]
    b.add(local, spec.block, period=period or spec.period, offset=spec.offset or None, units=spec.units or None,
          elements={port: list(labels) for port, labels in spec.labels.items()} or None,
          where=Site(spec.file or diagram.file, spec.line))


def _local(level: Composite, signal: str) -> str:
    block, port = signal.rsplit(".", 1)
    return f"{level.name_of(block)}.{port}"


def _end(level: Composite, block: str, port: str, select: str | None) -> str:
    text = f"{level.name_of(block)}.{port}"
    return text if select is None else f"{text}[{select}]"


def _site(diagram: Diagram, wire: Connection) -> Site:
    return Site(wire.file or diagram.file, wire.line)
