"""Linear time-invariant blocks: discrete state space and transfer functions.

Both run the discrete model x[k+1] = A x + B u, y = C x + D u at the block period. With
``method`` set, the given matrices (or polynomials) are a continuous-time model that
``bind(period)`` discretises with python-control. These blocks sit in the executor's
hot loop, so everything is precomputed: the 1x1x1 case runs on Python floats (about 3x
faster than a numpy matmul on a 1-vector), larger ones on one ``ndarray.dot`` of a
stacked matrix (``.dot`` skips the ``@`` ufunc dispatch), and ``advance`` uses cached
closed-form chunk matrices.
"""

from __future__ import annotations

from fractions import Fraction
from typing import Any, Mapping

import numpy as np

from blocks.arrays import float_array
from blocks.block import Block, BlockError, Signal
from blocks.library import _kernels

METHODS = ("zoh", "tustin")
"""Discretisation methods accepted by ``method`` (python-control names)."""

CHUNK = 64
"""Longest run of steps that one cached ``advance`` matrix covers."""


class _Unbound:
    """Stands in for the discrete matrices of a continuous model until ``bind``."""

    def __init__(self, block_name: str, method: str):
        self.message = (
            f"{block_name} with method={method!r} is a continuous model: "
            "bind(period) must discretise it before it runs"
        )

    def dot(self, *args: Any) -> np.ndarray:
        raise BlockError(self.message)


def _check_method(method: str | None) -> str | None:
    if method is not None and method not in METHODS:
        raise ValueError(f"parameter 'method' must be None, 'zoh' or 'tustin', got {method!r}")
    return method


def _state_space_matrices(A: Any, B: Any, C: Any, D: Any) -> tuple[np.ndarray, ...]:
    """Validated float matrices A (n,n), B (n,m), C (p,n), D (p,m); D=None means zeros."""
    A = float_array(A, "A", ndim=2)
    n = A.shape[0]
    if A.shape != (n, n) or n == 0:
        raise ValueError(f"parameter 'A' must be a non-empty square matrix, got shape {A.shape}")
    B_arr = float_array(B, "B")
    if B_arr.ndim == 1 and n > 1 and B_arr.size == n:
        B_arr = B_arr.reshape(n, 1)
    B = float_array(B_arr, "B", ndim=2)
    if B.shape[0] != n or B.shape[1] == 0:
        raise ValueError(f"parameter 'B' must have shape ({n}, m) to match A, got {B.shape}")
    m = B.shape[1]
    C = float_array(C, "C", ndim=2)
    if C.shape[1] != n or C.shape[0] == 0:
        raise ValueError(f"parameter 'C' must have shape (p, {n}) to match A, got {C.shape}")
    p = C.shape[0]
    if D is None:
        D = np.zeros((p, m))
    else:
        D = float_array(D, "D", ndim=2)
        if D.shape != (p, m):
            raise ValueError(f"parameter 'D' must have shape ({p}, {m}) to match C and B, got {D.shape}")
    return A, B, C, D


def _initial_vector(x0: Any, n: int) -> np.ndarray:
    if x0 is None:
        return np.zeros(n)
    x0 = float_array(x0, "x0", ndim=1)
    if x0.size != n:
        raise ValueError(f"parameter 'x0' must have {n} entries (one per state), got {x0.size}")
    return x0


def transfer_function_realisation(num: Any, den: Any) -> tuple[np.ndarray, ...]:
    """Controllable canonical (A, B, C, D) of num/den, coefficients in descending powers.

    The state count is the denominator degree (after dropping leading zeros); a pure
    gain has no state. Raises ValueError for an improper or zero-denominator function.
    """
    num = np.trim_zeros(float_array(num, "num", ndim=1), "f")
    den = np.trim_zeros(float_array(den, "den", ndim=1), "f")
    if den.size == 0:
        raise ValueError("parameter 'den' must have a nonzero coefficient")
    if num.size == 0:
        num = np.zeros(1)
    if num.size > den.size:
        raise ValueError(
            f"transfer function is improper: 'num' has degree {num.size - 1} > 'den' degree "
            f"{den.size - 1}; only proper transfer functions have a state-space realisation"
        )
    n = den.size - 1
    a = den[1:] / den[0]
    b = np.concatenate((np.zeros(den.size - num.size), num)) / den[0]
    A = np.zeros((n, n))
    A[:1] = -a
    A[1:, :-1] = np.eye(max(n - 1, 0))
    B = np.zeros((n, 1))
    B[:1, 0] = 1.0
    C = (b[1:] - a * b[0]).reshape(1, n)
    D = np.array([[b[0]]])
    return A, B, C, D


class _LinearBlock(Block):
    """Shared machinery: discretisation, the run-time kernels and the advance cache.

    ``A``, ``B``, ``C``, ``D`` are the discrete matrices in use (``None`` for a
    continuous model until ``bind``); the state is the 1-D array x of that realisation.
    """

    def _configure(self, A: np.ndarray, B: np.ndarray, C: np.ndarray, D: np.ndarray,
                   x0: np.ndarray, method: str | None) -> None:
        self.method = method
        # A stateless gain is the same at every period, so only a model with states is kept
        # for discretisation.
        self._continuous = (A, B, C, D, x0) if method is not None and A.shape[0] else None
        self._n, self._m, self._p = A.shape[0], B.shape[1], C.shape[0]
        self.inputs = {"u": self._m}
        self.outputs = {"y": self._p}
        if self._continuous is None:
            self._set_discrete(A, B, C, D, x0)
            return
        unbound = _Unbound(type(self).__name__, method)
        self.A = self.B = self.C = self.D = None
        self._AB = self._CD = self._C = unbound
        self._scalar = False
        self._ft_path = True
        self._x0 = x0
        self._chunks: dict[int, tuple[np.ndarray, np.ndarray]] = {}
        self._scalar_chunks: dict[int, tuple[np.ndarray, np.ndarray, float, float]] = {}
        # Until the period is known, assume the feedthrough a discretised model can have:
        # zoh keeps D; tustin adds a multiple of C (I - A T/2)^-1 B, which is zero for
        # every T only when all Markov parameters C A^k B are.
        ft = bool(np.any(D != 0))
        if method == "tustin":
            power = B
            for _ in range(self._n):
                ft = ft or bool(np.any(C @ power != 0))
                power = A @ power
        self.feedthrough = ft

    def _set_discrete(self, A: np.ndarray, B: np.ndarray, C: np.ndarray, D: np.ndarray,
                      x0: np.ndarray) -> None:
        self.A, self.B, self.C, self.D = A, B, C, D
        self._AB = np.ascontiguousarray(np.hstack((A, B)))
        self._CD = np.ascontiguousarray(np.hstack((C, D)))
        self._C = np.ascontiguousarray(C)
        self._x0 = x0
        self.feedthrough = bool(np.any(D != 0))
        # A stateless pure gain goes through the feedthrough branch even when D == 0.
        self._ft_path = self.feedthrough or self._n == 0
        self._scalar = (self._n, self._m, self._p) == (1, 1, 1)
        if self._scalar:
            self._a, self._b = float(A[0, 0]), float(B[0, 0])
            self._c, self._d = float(C[0, 0]), float(D[0, 0])
        self._chunks = {}
        self._scalar_chunks = {}

    def bind(self, period: Fraction | None) -> None:
        """Discretise a continuous model (``method`` given) at ``period``."""
        super().bind(period)
        if self._continuous is None:
            return
        if period is None:
            raise ValueError(
                f"{type(self).__name__} with method={self.method!r} needs an explicit sample period"
            )
        if period <= 0:
            raise ValueError(f"{type(self).__name__} period must be positive, got {period}")
        import control  # deferred: importing python-control takes about a second

        A, B, C, D, x0 = self._continuous
        T = float(period)
        sysd = control.ss(A, B, C, D).sample(T, method=self.method)
        Ad, Bd, Cd, Dd = (np.array(M, dtype=float) for M in (sysd.A, sysd.B, sysd.C, sysd.D))
        if self.method == "tustin":
            # The bilinear realisation's state is w = (I - A T/2) x - (T/2) B u; map the
            # continuous x0 assuming zero input at t = 0 so that y(0) = C x0.
            x0 = (np.eye(self._n) - 0.5 * T * A) @ x0
        self._set_discrete(Ad, Bd, Cd, Dd, x0)

    def initial_state(self) -> Signal | None:
        return None if self._n == 0 else self._x0.copy()

    def output(self, t: float, state: Any, inputs: Mapping[str, Signal]) -> dict[str, Signal]:
        if self._scalar:
            if self._ft_path:
                return {"y": np.array((self._c * state.item() + self._d * inputs["u"].item(),))}
            return {"y": np.array((self._c * state.item(),))}
        if self._ft_path:
            if state is None:
                return {"y": self.D.dot(inputs["u"])}
            return {"y": self._CD.dot(np.concatenate((state, inputs["u"])))}
        return {"y": self._C.dot(state)}

    def update(self, t: float, state: Any, inputs: Mapping[str, Signal]) -> Any:
        if self._scalar:
            return np.array((self._a * state.item() + self._b * inputs["u"].item(),))
        return self._AB.dot(np.concatenate((state, inputs["u"])))

    def _chunk(self, c: int) -> tuple[np.ndarray, np.ndarray]:
        """Matrices mapping z = [x; u] to the c outputs stacked, and to the state after c steps."""
        maps = self._chunks.get(c)
        if maps is None:
            n, m = self._n, self._m
            step = np.zeros((n + m, n + m))
            step[:n] = self._AB
            step[n:, n:] = np.eye(m)
            power = np.eye(n + m)
            rows = []
            for _ in range(c):
                power = step @ power
                rows.append(self._CD @ power)
            maps = (np.ascontiguousarray(np.vstack(rows)), np.ascontiguousarray(power[:n]))
            self._chunks[c] = maps
        return maps

    def _all_chunks(self) -> tuple[np.ndarray, list[np.ndarray]]:
        """``_chunk(CHUNK)``'s output map and every ``_chunk(c)``'s state map, c = 1..CHUNK,
        by the very operations ``_chunk`` does (its products for c are the first c of
        those for CHUNK), in CHUNK steps instead of CHUNK (CHUNK + 1) / 2."""
        n, m = self._n, self._m
        step = np.zeros((n + m, n + m))
        step[:n] = self._AB
        step[n:, n:] = np.eye(m)
        power = np.eye(n + m)
        rows, xmaps = [], []
        for _ in range(CHUNK):
            power = step @ power
            rows.append(self._CD @ power)
            xmaps.append(np.ascontiguousarray(power[:n]))
        return np.ascontiguousarray(np.vstack(rows)), xmaps

    def advance(self, t: float, state: Any, inputs: Mapping[str, Signal], n: int):
        """Closed form for a held input: x_{k+i} = A^i x + (sum_{j<i} A^j) B u, in chunks."""
        u = inputs["u"]
        p = self._p
        if state is None:
            return None, {"y": np.tile(self.D.dot(u), (max(n, 0), 1))}
        if n <= 0:
            return state, {"y": np.empty((0, p))}
        if self._scalar:
            return self._advance_scalar(state.item(), u.item(), n)
        nx = self._n
        z = np.concatenate((state, u))
        if n <= CHUNK:
            ymap, xmap = self._chunk(n)
            return xmap.dot(z), {"y": ymap.dot(z).reshape(n, p)}
        out = np.empty((n, p))
        done = 0
        while done < n:
            c = min(n - done, CHUNK)
            ymap, xmap = self._chunk(c)
            out[done:done + c] = ymap.dot(z).reshape(c, p)
            x = xmap.dot(z)
            z[:nx] = x
            done += c
        return x, {"y": out}

    def _advance_scalar(self, x: float, u: float, n: int):
        """``advance`` of the 1x1x1 model: each chunk's products written out as two-term
        sums (first * x) + (second * u), elementwise, which the C kernel's products equal
        to the bit (``ndarray.dot`` would leave the order and fusing to BLAS)."""
        if n <= CHUNK:
            yx, yu, xx, xu = self._scalar_chunk(n)
            return np.array((xx * x + xu * u,)), {"y": yx * x + yu * u}
        out = np.empty((n, 1))
        done = 0
        while done < n:
            c = min(n - done, CHUNK)
            yx, yu, xx, xu = self._scalar_chunk(c)
            out[done:done + c] = yx * x + yu * u
            x = xx * x + xu * u
            done += c
        return np.array((x,)), {"y": out}

    def _scalar_chunk(self, c: int) -> tuple[np.ndarray, np.ndarray, float, float]:
        """``_chunk(c)`` of the 1x1x1 model split by column: the output map's x and u
        columns (contiguous, c x 1) and the state map's two numbers."""
        parts = self._scalar_chunks.get(c)
        if parts is None:
            ymap, xmap = self._chunk(c)
            parts = (ymap[:, :1].copy(), ymap[:, 1:].copy(), float(xmap[0, 0]), float(xmap[0, 1]))
            self._scalar_chunks[c] = parts
        return parts

    def kernel(self):
        """C output, update and advance (blocks/csrc/library.c, ``lti_*``), reading the
        matrices in use and every ``_chunk`` map; None for a continuous model not yet
        bound. The 1x1x1 model and a stateless 1x1 gain match the Python methods to the
        bit (their products are the same float operations); larger ones compute the
        same products to round-off (library.c's ``matvec``, see ``blocks.library._kernels``)."""
        if self.A is None:
            return None
        return _kernels.cached(self, (id(self._AB), self.period), self._build_kernel)

    def _build_kernel(self):
        n, m, p = self._n, self._m, self._p
        header = np.zeros(14 + 2 * CHUNK)
        scalar = self._scalar
        header[:9] = (n, m, p, scalar, self._ft_path,
                      self._a if scalar else 0.0, self._b if scalar else 0.0,
                      self._c if scalar else 0.0, self._d if scalar else 0.0)
        header[13] = CHUNK
        parts = [header]
        size = header.size

        def place(matrix: np.ndarray) -> int:
            nonlocal size
            offset = size
            parts.append(np.ascontiguousarray(matrix, dtype=float).ravel())
            size += parts[-1].size
            return offset

        header[12] = place(self._AB)
        header[11] = place(self.D)
        if n:
            header[9] = place(self._CD)
            header[10] = place(self._C)
            # chunk c's output map is the first c * p rows of chunk CHUNK's
            ymap, xmaps = self._all_chunks()
            header[14:14 + CHUNK] = place(ymap)
            for c in range(1, CHUNK + 1):
                header[13 + CHUNK + c] = place(xmaps[c - 1])
        return _kernels.make_kernel(np.concatenate(parts), "lti_output", "lti_update", "lti_advance",
                                    self._AB)


class DiscreteStateSpace(_LinearBlock):
    """Discrete state-space model x[k+1] = A x + B u, y = C x + D u (optionally from continuous).

    Parameters
    ----------
    A : matrix
        state matrix, n x n
    B : matrix
        input matrix, n x m (a length-n list is taken as a column)
    C : matrix
        output matrix, p x n
    D : matrix
        feedthrough matrix, p x m; omitted means zero (no feedthrough)
    x0 : vector
        initial state, n entries (of the continuous model when method is given); default zeros
    method : {None, 'zoh', 'tustin'}
        None if A, B, C, D are discrete; 'zoh' or 'tustin' to discretise a continuous model
        at the block period
    """

    def __init__(self, A: Any, B: Any, C: Any, D: Any = None, x0: Any = None,
                 method: str | None = None):
        method = _check_method(method)
        A, B, C, D = _state_space_matrices(A, B, C, D)
        self._configure(A, B, C, D, _initial_vector(x0, A.shape[0]), method)


class DiscreteTransferFunction(_LinearBlock):
    """Single-input single-output transfer function num(z)/den(z) (or num(s)/den(s) with method).

    Parameters
    ----------
    num : vector
        numerator coefficients, highest power first
    den : vector
        denominator coefficients, highest power first; degree >= numerator degree
    method : {None, 'zoh', 'tustin'}
        None if num/den are in z; 'zoh' or 'tustin' to discretise num(s)/den(s) at the block period
    x0 : vector
        initial state of the controllable canonical realisation (denominator degree entries);
        default zeros
    """

    def __init__(self, num: Any, den: Any, method: str | None = None, x0: Any = None):
        method = _check_method(method)
        A, B, C, D = transfer_function_realisation(num, den)
        self.num = float_array(num, "num", ndim=1)
        self.den = float_array(den, "den", ndim=1)
        self._configure(A, B, C, D, _initial_vector(x0, A.shape[0]), method)
