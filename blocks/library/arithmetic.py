"""Memoryless arithmetic: products and quotients, absolute value, sign, bias, min/max, and a
Math block of a fixed set of functions. Each is elementwise over a width inferred from the
connections (unless a vector parameter fixes it); their kernels are in lib_math.c."""

from __future__ import annotations

from typing import Any

from blocks.library import _params
from blocks.library.kernel_block import SINGULAR, KernelBlock
from blocks.limits import MAX_PORT_WIDTH, check_block_size


class Elementwise(KernelBlock):
    """One input ``u`` and one output ``y`` of the same width, with feedthrough."""

    def _ports(self, width: int | None) -> None:
        self.inputs, self.outputs = {"u": width}, {"y": width}
        self.feedthrough = True


class Abs(Elementwise):
    """The absolute value of the input, elementwise: y = |u|."""

    kernel_name = "abs"

    def __init__(self):
        self._ports(None)


class Sign(Elementwise):
    """The sign of the input, elementwise: 1 where u > 0, -1 where u < 0, 0 where u = 0
    (NaN stays NaN), as Simulink's Sign block."""

    kernel_name = "sign"

    def __init__(self):
        self._ports(None)


class Bias(Elementwise):
    """Adds a constant to the input: y = u + bias.

    Parameters
    ----------
    bias : scalar or vector
        what is added; a vector (one per element) fixes the width
    """

    kernel_name = "bias"

    def __init__(self, bias: Any = 0.0):
        self.bias = _params.elementwise("bias", bias)
        self._ports(_params.common_width(bias=self.bias))

    def context_numbers(self):
        return (_params.spread(self.bias, self.outputs["y"]),)


class MinMax(KernelBlock):
    """The smallest (or largest) value: of the elements of one input, or elementwise of
    several inputs, as Simulink's MinMax block; a NaN anywhere gives NaN.

    Parameters
    ----------
    function : {'min', 'max'}
        which extreme
    inputs : int
        number of inputs ``u0, u1, ...``; with 1 the input is ``u`` and the output its
        extreme element (width 1)
    """

    kernel_name = "minmax"

    def __init__(self, function: str = "min", inputs: int = 1):
        self.function = _params.choice("function", function, ("min", "max"))
        self.count = _params.integer("inputs", inputs, minimum=1, maximum=64)
        if self.count == 1:
            self.inputs, self.outputs = {"u": None}, {"y": 1}
        else:
            self.inputs, self.outputs = {f"u{j}": None for j in range(self.count)}, {"y": None}
        self.feedthrough = True

    def context_numbers(self):
        return (float(self.function == "max"), self.count, next(iter(self.inputs.values())))


UNARY = ("exp", "log", "log10", "sqrt", "square", "reciprocal", "sin", "cos", "tan", "asin", "acos", "atan",
         "sinh", "cosh", "tanh")
BINARY = ("atan2", "pow", "hypot", "mod", "rem")
MATH_FUNCTIONS = {**{f: i for i, f in enumerate(UNARY)}, **{f: 20 + i for i, f in enumerate(BINARY)}}
"""Math's functions and their codes in lib_math.c."""


class Math(Elementwise):
    """A mathematical function (exp, log, sqrt, sin, atan2, mod, ...), elementwise.

    Of ``u`` for the one-argument functions, of ``u0`` and ``u1`` for the two-argument
    ones. Outside a function's domain the result is
    IEEE 754's (log of a negative number is NaN, of 0 is -inf), as C's math library gives.

    Parameters
    ----------
    function : str
        one of exp, log (natural), log10, sqrt, square (u^2), reciprocal (1/u), sin, cos,
        tan, asin, acos, atan, sinh, cosh, tanh, or of two inputs: atan2 (atan2(u0, u1)),
        pow (u0^u1), hypot (sqrt(u0^2 + u1^2)), mod (MATLAB's mod: the sign of u1,
        mod(u0, 0) = u0), rem (MATLAB's rem: the sign of u0, rem(u0, 0) = NaN)
    """

    kernel_name = "math"

    def __init__(self, function: str = "exp"):
        self.function = _params.choice("function", function, tuple(MATH_FUNCTIONS))
        if self.function in BINARY:
            self.inputs, self.outputs = {"u0": None, "u1": None}, {"y": None}
            self.feedthrough = True
        else:
            self._ports(None)

    def context_numbers(self):
        return (MATH_FUNCTIONS[self.function],)


MULTIPLICATIONS = ("elementwise", "matrix")


class Product(KernelBlock):
    """Multiplies and divides its inputs ``u0, u1, ...``, as Simulink's Product block.

    Elementwise (the default), the inputs share one width: u0 (or 1/u0), then each further
    input multiplied or divided in turn. One input is collapsed: the product of its
    elements ('*'), or successive quotients ((1/u_0)/u_1/... for '/'); the output has
    width 1. In matrix mode each input is a row-major matrix of the shape ``shapes`` gives,
    multiplied left to right, a '/' input inverted (it must be square and not singular: a
    singular one stops the run, naming the input).

    Parameters
    ----------
    ops : str or int
        one '*' or '/' per input ('*/' is u0 / u1), or a number of inputs all multiplied
    multiplication : {'elementwise', 'matrix'}
        elementwise products, or matrix products
    shapes : list of [rows, columns]
        matrix mode only: the shape of each input, in order
    """

    kernel_name = "product"

    def __init__(self, ops: Any = "**", multiplication: str = "elementwise", shapes: Any = None):
        if isinstance(ops, str):
            if not ops or set(ops) - {"*", "/"}:
                raise ValueError(f"parameter 'ops' must be a non-empty string of '*' and '/', got {ops!r}")
            self.ops = ops
        else:
            self.ops = "*" * _params.integer("ops", ops, minimum=1, maximum=64)
        self.multiplication = _params.choice("multiplication", multiplication, MULTIPLICATIONS)
        count = len(self.ops)
        names = ["u"] if count == 1 else [f"u{j}" for j in range(count)]
        self.feedthrough = True
        if self.multiplication == "elementwise":
            if shapes is not None:
                raise ValueError("parameter 'shapes' is for multiplication: matrix")
            self.shapes = None
            self.inputs = {p: None for p in names}
            self.outputs = {"y": 1 if count == 1 else None}
            return
        self.shapes = _matrix_shapes(shapes, self.ops)
        self.inputs = {p: r * c for p, (r, c) in zip(names, self.shapes)}
        self.outputs = {"y": self.shapes[0][0] * self.shapes[-1][1]}

    def context_numbers(self):
        divide = [float(op == "/") for op in self.ops]
        if self.shapes is None:
            return (0.0, len(self.ops), next(iter(self.inputs.values())), divide)
        biggest = max(max(r, c) for r, c in self.shapes)
        rows = [r for r, _ in self.shapes]
        cols = [c for _, c in self.shapes]
        return (1.0, len(self.ops), 5 * biggest * biggest, divide, rows, cols)

    def failure_text(self, code: int, which: int) -> str:
        if code == SINGULAR:
            port = list(self.inputs)[which]
            return f"input '{port}' is a singular matrix and cannot be inverted"
        return super().failure_text(code, which)


class Divide(Product):
    """Product with the quotient as its default: y = u0 / u1 (Simulink's Divide block).

    Parameters
    ----------
    ops : str or int
        one '*' or '/' per input ('*/' is u0 / u1, '/' alone 1/u for a scalar), or a number
        of inputs all multiplied
    multiplication : {'elementwise', 'matrix'}
        elementwise quotients, or matrix products with inverses (u0 inv(u1))
    shapes : list of [rows, columns]
        matrix mode only: the shape of each input, in order
    """

    def __init__(self, ops: Any = "*/", multiplication: str = "elementwise", shapes: Any = None):
        super().__init__(ops, multiplication, shapes)


def _matrix_shapes(shapes: Any, ops: str) -> list[tuple[int, int]]:
    """The inputs' [rows, columns], checked to chain: each '/' matrix square, each factor's
    rows the columns of the product before it."""
    if not isinstance(shapes, (list, tuple)) or len(shapes) != len(ops):
        raise ValueError(f"parameter 'shapes' must list [rows, columns] for each of the {len(ops)} inputs, "
                         f"got {shapes!r}")
    checked = []
    for j, shape in enumerate(shapes):
        if not isinstance(shape, (list, tuple)) or len(shape) != 2:
            raise ValueError(f"parameter 'shapes': entry {j} must be [rows, columns], got {shape!r}")
        r, c = (_params.integer("shapes", v, minimum=1) for v in shape)
        check_block_size((f"input {j}'s rows", r), ("columns", c), limit=MAX_PORT_WIDTH, what="elements of a port")
        if ops[j] == "/" and r != c:
            raise ValueError(f"parameter 'shapes': input {j} is inverted ('/') and must be square, got {r}x{c}")
        checked.append((r, c))
    cols = checked[0][1]
    for j, (r, c) in enumerate(checked[1:], start=1):
        if r != cols:
            raise ValueError(f"parameter 'shapes': input {j} has {r} rows, the product before it has {cols} "
                             "columns")
        cols = c
    return checked
