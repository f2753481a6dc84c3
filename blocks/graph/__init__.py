"""The wiring of a diagram as DOT text or a drawn SVG/PNG/PDF (networkx + matplotlib).

Both show each block as a record: its name, type and rate on top, its input ports down
the left edge and its output ports down the right edge, and every connection as a wire
from an output port to an input port. Blocks stand in layers from left to right along
the data flow; the wires that close a loop (into a block without feedthrough, or through
a delay) run back right to left in a channel above or below the blocks. Delayed wires
are dashed and marked ``z^-1``. Colours give the rates, as Simulink's sample-time
colours do: one colour per distinct effective period (an inherited block takes the
colour of the rate it resolves to), with a legend.

The drawing needs no Graphviz: the layout is done here (longest-path layers, a few
barycenter passes against crossings) and drawn with matplotlib. The DOT text is for
those who have Graphviz.

A diagram with subsystems is drawn as its top file wrote it, each subsystem one box with
its ports and the rates of the blocks inside (yellow when they differ, as Simulink colours
a hybrid subsystem); ``expand`` draws every block, each subsystem a frame around its own
(a cluster in the DOT text).

Modules: ``view`` (what is shown: boxes, wires, frames), ``rates`` (periods and their
colours), ``ports`` (what a box shows), ``layout`` (layers and their order), ``drawing``
(matplotlib), ``dot`` (Graphviz text).
"""

from __future__ import annotations

from .dot import to_dot
from .drawing import draw, draw_picture, geometry, render, svg_text
from .layout import crossings, layered
from .ports import is_feedthrough
from .rates import effective_rate, rate_colors
from .view import Picture, picture

__all__ = ["Picture", "crossings", "draw", "draw_picture", "effective_rate", "geometry", "is_feedthrough", "layered",
           "picture", "rate_colors", "render", "svg_text", "to_dot"]
