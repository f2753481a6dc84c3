"""Signal routing: joining vectors (Concatenate, Mux), splitting them (Demux) and picking
elements (Selector). They work on whole ports; their kernels (lib_math.c) copy."""

from __future__ import annotations

import re
from typing import Any

from blocks.library import _params
from blocks.library.kernel_block import KernelBlock
from blocks.limits import MAX_PORT_WIDTH

MAX_PORTS = 64
"""Most inputs of a Concatenate or Mux, outputs of a Demux."""


def port_widths(value: Any, ports: str) -> list[int]:
    """The ``widths`` parameter: one width per port (a count n: n ports of width 1)."""
    return _params.widths_list("widths", value, ports, MAX_PORTS)


class Concatenate(KernelBlock):
    """Joins its inputs ``u0, u1, ...`` end to end into one vector ``y``.

    Parameters
    ----------
    widths : int or list of int
        the inputs' widths in order; a number n means n inputs of width 1
    """

    kernel_name = "concatenate"

    def __init__(self, widths: Any = 2):
        self.widths = port_widths(widths, "inputs")
        self.inputs = {f"u{j}": w for j, w in enumerate(self.widths)}
        self.outputs = {"y": sum(self.widths)}
        self.feedthrough = True

    def context_numbers(self):
        return (len(self.widths), self.widths)


class Mux(Concatenate):
    """Combines its inputs ``u0, u1, ...`` into one vector ``y``, optionally naming them.

    With ``labels``, the output's elements are then called by the names (``x``, or ``pos.0``,
    ``pos.1`` for an input of width 2), in CSV columns, plots and ``hierhand blocks``.

    Parameters
    ----------
    widths : int or list of int
        the inputs' widths in order; a number n means n scalar inputs
    labels : list of str
        a name for each input; omitted, the elements are numbered
    """

    def __init__(self, widths: Any = 2, labels: Any = None):
        super().__init__(widths)
        if labels is not None:
            if (not isinstance(labels, (list, tuple)) or len(labels) != len(self.widths)
                    or not all(isinstance(x, str) and x for x in labels)):
                raise ValueError(f"parameter 'labels' must be {len(self.widths)} non-empty names, one per input, "
                                 f"got {labels!r}")
            labels = list(labels)
        self.labels = labels

    def element_labels(self, port: str) -> list[str] | None:
        if self.labels is None or port != "y":
            return None
        return [name if w == 1 else f"{name}.{k}" for name, w in zip(self.labels, self.widths) for k in range(w)]


class Demux(KernelBlock):
    """Splits its input ``u`` into consecutive pieces ``y0, y1, ...``.

    Parameters
    ----------
    widths : int or list of int
        the outputs' widths in order; a number n means n outputs of width 1
    """

    kernel_name = "concatenate"

    def __init__(self, widths: Any = 2):
        self.widths = port_widths(widths, "outputs")
        self.inputs = {"u": sum(self.widths)}
        self.outputs = {f"y{j}": w for j, w in enumerate(self.widths)}
        self.feedthrough = True

    def context_numbers(self):
        return (1, sum(self.widths))


_SLICE = re.compile(r"^\s*(-?\d+)?\s*:\s*(-?\d+)?\s*(?::\s*(-?\d+)\s*)?$")


class Selector(KernelBlock):
    """Picks elements of its input ``u`` by index or slice.

    Indices are 0-based, in the order given, repeats allowed: ``indices: [2, 0]`` outputs u[2], u[0]; ``indices: "0:3"`` the first three
    (Python's slice notation, step included).

    Negative indices and open slices (``-1``, ``"2:"``) count from the input's end, so
    they need ``width``. Without it the input's width comes from its connection, and an
    index past it is a load error at the block.

    Parameters
    ----------
    indices : list of int or str
        the elements to output, or a slice 'start:stop[:step]'
    width : int
        the input's width; omit to take it from the connection
    """

    kernel_name = "selector"

    def __init__(self, indices: Any, width: int | None = None):
        self.width = None if width is None else _params.integer("width", width, minimum=1, maximum=MAX_PORT_WIDTH)
        self.indices = self._parse(indices)
        self.inputs, self.outputs = {"u": self.width}, {"y": len(self.indices)}
        self.feedthrough = True
        if self.width is not None:
            self.resolved(self.width)

    def _parse(self, indices: Any) -> list[int]:
        if isinstance(indices, str):
            found = _SLICE.match(indices)
            if found is None:
                raise ValueError(f"parameter 'indices' must be a list of indices or a slice 'start:stop[:step]', "
                                 f"got {indices!r}")
            if any(g is not None and len(g.lstrip("+-")) > 7 for g in found.groups()):  # beyond MAX_PORT_WIDTH
                raise ValueError(f"parameter 'indices': the slice {indices!r} reaches beyond the widest port "
                                 f"({MAX_PORT_WIDTH} elements)")
            start, stop, step = (None if g is None else int(g) for g in found.groups())
            if step == 0:
                raise ValueError("parameter 'indices': a slice step must not be 0")
            if self.width is None and (start is None or stop is None or start < 0 or stop < 0 or (step or 1) < 0):
                raise ValueError(f"parameter 'indices': the slice {indices!r} counts from the input's end; "
                                 "give 'width' too")
            span = range(self.width if self.width is not None else max(start, stop) + 1)[slice(start, stop, step)]
            if len(span) > MAX_PORT_WIDTH:
                raise ValueError(f"parameter 'indices': the slice {indices!r} selects {len(span)} elements, more "
                                 f"than the widest port ({MAX_PORT_WIDTH})")
            picked = list(span)
        elif isinstance(indices, (list, tuple)) and indices:
            picked = [_params.integer("indices", i, minimum=-MAX_PORT_WIDTH, maximum=MAX_PORT_WIDTH - 1)
                      for i in indices]
            if self.width is None and any(i < 0 for i in picked):
                raise ValueError("parameter 'indices': negative indices count from the input's end; give 'width' too")
        else:
            raise ValueError(f"parameter 'indices' must be a non-empty list of indices or a slice, got {indices!r}")
        if not picked:
            raise ValueError(f"parameter 'indices' selects nothing: {indices!r}")
        return picked

    def set_width(self, width: int) -> None:
        self.resolved(width)
        super().set_width(width)

    def resolved(self, width: int) -> list[int]:
        """The indices into an input of ``width`` (negative ones from its end)."""
        out = []
        for i in self.indices:
            j = i + width if i < 0 else i
            if not 0 <= j < width:
                raise ValueError(f"index {i} is out of range for an input of width {width}")
            out.append(j)
        return out

    def context_numbers(self):
        return (len(self.indices), self.resolved(self.inputs["u"]))
