"""``DiagramBuilder``: the one way a ``Diagram`` is made, from Python or from a YAML file.

Its calls record what a diagram says: blocks (by registered type, class or ``Block``
instance), subsystems (another builder used as one block), connections, the diagram's
own inputs and outputs, the block references it leaves to an including diagram, and
the signals to log; each with where it was said (``Site``): the file and line of the
Python call, or the line (and the ``Positions`` of its parts) that a front end of this
class, such as the diagram file's loader, passes. Nothing is checked while recording;
``build()`` checks everything at once (``blocks.builder.assemble``) and plans the
result, so every problem is one ``file:line: message (hint: ...)`` of one
``DiagramError`` and a diagram that builds can run.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Mapping

from blocks.builder.diagram import Diagram
from blocks.issues import Issue
from blocks.builder.records import (
    Annotation,
    BlockEntry,
    DiagramRecord,
    DiagramSource,
    LogRequest,
    PortEntry,
    ParamsReader,
    Problem,
    ReferenceEntry,
    Site,
    SubsystemEntry,
    WireEntry,
    call_site,
)



def _wiring_svg(diagram: Diagram) -> str:
    """Jupyter's view of a Diagram: its wiring graph. ``blocks.graph`` is a layer above the
    diagram's data, so the view is attached here, where every Diagram is made, and the
    drawing is imported when a diagram is first shown."""
    from blocks.graph import svg_text

    return svg_text(diagram)


Diagram._repr_svg_ = _wiring_svg

class DiagramBuilder(DiagramRecord):
    """Records a diagram, then ``build()`` checks and makes it.

    >>> b = DiagramBuilder("pi", t_end="1 s")
    >>> b.add("ref", "Constant", params={"value": 1.0})
    >>> b.add("gain", "Gain", period="10 ms", params={"k": 2.0})
    >>> b.connect("ref.y", "gain.u")
    >>> b.log("gain.y")
    >>> diagram = b.build()

    ``base_dir`` is where the relative paths it names (``params_file``, an FMU's path)
    lead (default: the current folder). ``trust`` lets it name ``python:`` types and
    params files outside ``base_dir``; a builder made in code is trusted, one the YAML
    loader makes only with ``--trust``. ``where`` (every method) says where a problem with
    the entry is reported; by default it is the line of the call. ``read_params`` reads its
    params files (default: as a diagram file's, YAML; a front end gives its own).
    """

    def __init__(self, name: str = "diagram", description: str = "", t_end: Any = None, *,
                 base_dir: str | Path | None = None, trust: bool = True, where: Site | None = None,
                 read_params: ParamsReader | None = None):
        super().__init__(name, description, t_end, base_dir=base_dir, trust=trust, where=where or call_site(),
                         read_params=read_params)

    # -- what a diagram says ----------------------------------------------------------

    def add(self, name: str, block: Any, *, period: Any = None, offset: Any = None,
            params: Mapping[str, Any] | None = None, params_file: str | None = None,
            units: Mapping[str, Any] | None = None, elements: Mapping[str, Any] | None = None,
            where: Site | None = None) -> None:
        """A block: ``block`` is a registered type name (``"Gain"``), ``"python:mod:Class"``,
        a ``Block`` subclass or a ``Block`` instance (whose parameters are its
        constructor's; it cannot take ``params`` or overrides). ``period`` and ``offset``
        are durations (``"1 ms"``, seconds, a Fraction); without a period it inherits.
        ``params`` may name other blocks for its block-reference parameters. ``units`` and
        ``elements`` give ports the block knows nothing of a unit and element names, by
        port (``units={"y": "rad"}``), as ``annotate`` does."""
        site = where or call_site()
        self.entries.append(BlockEntry(name, block, period, offset, params, params_file, site))
        for key, given in (("units", units), ("elements", elements)):
            if not isinstance(given, Mapping | None):
                self.fail(site.issue(f"block '{name}': '{key}' must map port names to {key}",
                                     "units: {y: rad}, elements: {y: [x, y, theta]}"), name)
        for port in {**(units if isinstance(units, Mapping) else {}),
                     **(elements if isinstance(elements, Mapping) else {})}:
            self.annotate(f"{name}.{port}", units=(units or {}).get(port), elements=(elements or {}).get(port),
                          where=site)

    def annotate(self, signal: str, *, units: Any = None, elements: Any = None, where: Site | None = None) -> None:
        """Give port ``signal`` (``"plant.y"``, an output or input of a block of this diagram
        whose block has none) a unit (one text, or one per element: ``["m", "m", "rad"]``)
        and names of its elements (``["x", "y", "theta"]``), which run.json, CSV columns,
        plots and connections by label then use, and a connection's other end is checked
        against (a connection of two different units is an error)."""
        self.annotations.append(Annotation(signal, units, elements, where or call_site()))

    def add_subsystem(self, name: str, diagram: DiagramRecord | DiagramSource, *,
                      params: Mapping[str, Any] | None = None,
                      bind: Mapping[str, str] | None = None, where: Site | None = None,
                      source: str | None = None) -> None:
        """Another diagram (its builder; ``blocks.read_builder`` reads one from a file) as
        one block: its ports are that diagram's inputs and outputs, its blocks are named
        ``name.block``. ``params`` overrides their parameters by dotted path
        (``{"prop.k": 2.0}``); ``bind`` gives each block reference the diagram leaves
        open a block of this diagram (``{"plant": "hand"}``)."""
        self.entries.append(SubsystemEntry(name, diagram, params, bind, where or call_site(), source))

    def connect(self, src: str, dst: str, *, delay: int = 0, initial: Any = None,
                where: Site | None = None) -> None:
        """A wire from output ``src`` to input ``dst`` (``"block.port"``; a subsystem's
        port is ``"ctrl.e"``). ``delay=1`` hands over the destination's previous hit;
        ``initial`` is the value before that."""
        self.wires.append(WireEntry(src, dst, delay, initial, where or call_site(), initial is not None))

    def input(self, name: str, *targets: str, where: Site | None = None) -> None:
        """An input of the diagram, feeding the inner inputs ``targets`` (``"integ.u"``)."""
        self.inputs.append(PortEntry(name, targets, where or call_site()))

    def output(self, name: str, source: str, *, where: Site | None = None) -> None:
        """An output of the diagram: the inner output ``source`` (``"u.y"``)."""
        self.outputs.append(PortEntry(name, (source,), where or call_site()))

    def reference(self, name: str, stand_in: Any = None, *, where: Site | None = None) -> None:
        """A block reference left to the including diagram, which binds it to one of its
        blocks (``bind: {name: block}``); this diagram's blocks name it as if it were a
        block. ``stand_in`` (a type name or class) makes the block that takes its place
        when the diagram is loaded on its own (``Type.example()``), for validating it; a
        ``Block`` instance stands in itself, so that blocks added as instances that were
        made with it (``hand=plant``) refer to it without it being a block here."""
        self.references.append(ReferenceEntry(name, stand_in, where or call_site()))

    def log(self, signal: str, *, decimate: int = 1, where: Site | None = None) -> None:
        """Record output ``signal`` (``"plant.y"``, inside a subsystem ``"ctrl.integ.y"``)
        at every ``decimate``-th hit."""
        self.logs.append(LogRequest(signal, decimate, where or call_site()))

    def log_all(self, *, where: Site | None = None) -> None:
        """Record every output of every block (those of its subsystems too)."""
        self.logs.append(LogRequest(None, 1, where or call_site(), every=True))

    def fail(self, issue: Issue, name: str | None = None) -> None:
        """A problem found before the builder (by a front end); ``name``: the block it spoils."""
        self.problems.append(Problem(issue, name))

    # -- making the diagram -----------------------------------------------------------

    def build(self, overrides: Mapping[str, Any] | None = None, *,
              origins: Mapping[str, str] | None = None) -> "Diagram":
        """The checked, planned Diagram; DiagramError with every problem otherwise.

        ``overrides`` maps ``block.param[.key...]`` (inside a subsystem
        ``ctrl.block.param``) to a value, as ``--set`` does; ``origins`` says how the user
        gave each, for the messages (default ``--set key=value``)."""
        from blocks.builder.assemble import assemble
        from blocks.engine.schedule import build_schedule

        from blocks.builder.api_args import overrides_mapping

        diagram = assemble(self, overrides_mapping(overrides), dict(origins or {}))
        build_schedule(diagram, diagram.t_end)
        return diagram

