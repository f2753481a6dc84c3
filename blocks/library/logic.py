"""Comparisons, logic and switches: Relational, Compare, Logic, Switch, MultiportSwitch.

Truth values are numbers: a comparison or a logic operator outputs 1.0 or 0.0, and any
non-zero input (NaN included) counts as true. Kernels in lib_math.c."""

from __future__ import annotations

from typing import Any

from blocks.library import _params
from blocks.library.kernel_block import OUT_OF_RANGE, KernelBlock

RELATIONS = ("<", "<=", "==", "!=", ">=", ">")
"""Relational operators, in lib_math.c's order."""


class Relational(KernelBlock):
    """Compares two inputs elementwise: y = 1 where ``u0 op u1``, else 0 (IEEE 754: any
    comparison with NaN is false, except '!=').

    Parameters
    ----------
    op : {'<', '<=', '==', '!=', '>=', '>'}
        the comparison
    """

    kernel_name = "relational"

    def __init__(self, op: str = "<="):
        self.op = _params.choice("op", op, RELATIONS)
        self.inputs, self.outputs = {"u0": None, "u1": None}, {"y": None}
        self.feedthrough = True

    def context_numbers(self):
        return (RELATIONS.index(self.op),)


class Compare(KernelBlock):
    """Compares the input with a constant elementwise: y = 1 where ``u op constant``, else 0
    (Simulink's Compare To Constant; ``constant: 0`` is Compare To Zero).

    Parameters
    ----------
    op : {'<', '<=', '==', '!=', '>=', '>'}
        the comparison
    constant : scalar or vector
        what the input is compared with; a vector fixes the width
    """

    kernel_name = "compare"

    def __init__(self, op: str = "<=", constant: Any = 0.0):
        self.op = _params.choice("op", op, RELATIONS)
        self.constant = _params.elementwise("constant", constant, allow_inf=True)
        width = _params.common_width(constant=self.constant)
        self.inputs, self.outputs = {"u": width}, {"y": width}
        self.feedthrough = True

    def context_numbers(self):
        return (RELATIONS.index(self.op), _params.spread(self.constant, self.outputs["y"]))


OPERATORS = ("and", "or", "nand", "nor", "xor", "nxor", "not")
"""Logic operators, in lib_math.c's order."""


class Logic(KernelBlock):
    """A logic operator (and, or, nand, nor, xor, nxor, not) over its inputs, elementwise.

    y = 1 if it holds, else 0 (xor: an odd number of true inputs; nxor: an even number). With one input, every operator but
    'not' applies across that input's elements (width-1 output), as in Simulink; 'not'
    takes one input and negates each element.

    Parameters
    ----------
    op : {'and', 'or', 'nand', 'nor', 'xor', 'nxor', 'not'}
        the operator
    inputs : int
        number of inputs ``u0, u1, ...`` (the input is ``u`` when there is one); 'not' has one
    """

    kernel_name = "logic"

    def __init__(self, op: str = "and", inputs: int = 2):
        self.op = _params.choice("op", op, OPERATORS)
        self.count = _params.integer("inputs", inputs, minimum=1, maximum=64)
        if self.op == "not" and self.count != 1:
            raise ValueError(f"parameter 'inputs' must be 1 for op 'not', got {self.count}")
        if self.count == 1:
            self.inputs = {"u": None}
            self.outputs = {"y": None if self.op == "not" else 1}
        else:
            self.inputs, self.outputs = {f"u{j}": None for j in range(self.count)}, {"y": None}
        self.feedthrough = True

    def context_numbers(self):
        return (OPERATORS.index(self.op), self.count, next(iter(self.inputs.values())))


CRITERIA = (">=", ">", "nonzero")
"""Switch criteria: control >= threshold, control > threshold, control != 0."""


class Switch(KernelBlock):
    """Passes ``u0`` where the control passes the criterion, else ``u1`` (Simulink's Switch,
    whose inputs 1, 2, 3 are ``u0``, ``control``, ``u1``).

    Parameters
    ----------
    criterion : {'>=', '>', 'nonzero'}
        u0 passes while control >= threshold, control > threshold, or control != 0
    threshold : float
        the threshold of '>=' and '>'
    elementwise : bool
        false: a scalar control switches the whole vector; true: the control has the
        data's width and switches each element on its own
    """

    kernel_name = "threshold_switch"

    def __init__(self, criterion: str = ">=", threshold: float = 0.0, elementwise: bool = False):
        self.criterion = _params.choice("criterion", criterion, CRITERIA)
        self.threshold = _params.number("threshold", threshold, allow_inf=True)
        self.elementwise = _params.flag("elementwise", elementwise)
        self.inputs = {"u0": None, "control": None if self.elementwise else 1, "u1": None}
        self.outputs = {"y": None}
        self.feedthrough = True

    def context_numbers(self):
        return (CRITERIA.index(self.criterion), self.threshold, float(self.elementwise))


DEFAULTS = ("error", "last")
"""What MultiportSwitch does with a control that names no data input."""


class MultiportSwitch(KernelBlock):
    """Passes the data input the control names (Simulink's Multiport Switch).

    ``control`` (scalar), truncated toward zero, selects ``u0`` at ``base``, ``u1`` at ``base + 1``, ... (Simulink's Multiport Switch
    with contiguous data ports; its default is one-based).

    Parameters
    ----------
    inputs : int
        number of data inputs ``u0, u1, ...``
    base : {0, 1}
        the control value that selects u0
    default : {'error', 'last'}
        a control out of range (or NaN) stops the run, or selects the last data input
    """

    kernel_name = "multiport_switch"

    def __init__(self, inputs: int = 2, base: int = 0, default: str = "error"):
        self.count = _params.integer("inputs", inputs, minimum=1, maximum=63)
        self.base = _params.integer("base", base, minimum=0, maximum=1)
        self.default = _params.choice("default", default, DEFAULTS)
        self.inputs = {"control": 1, **{f"u{j}": None for j in range(self.count)}}
        self.outputs = {"y": None}
        self.feedthrough = True

    def context_numbers(self):
        return (self.count, self.base, float(self.default == "last"))

    def failure_text(self, code: int, which: int) -> str:
        if code == OUT_OF_RANGE:
            last = self.base + self.count - 1
            return (f"control selects no data input (it must be {self.base} to {last} once truncated; "
                    "default: last uses the last input instead)")
        return super().failure_text(code, which)
