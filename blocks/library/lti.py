"""Linear time-invariant blocks: discrete state space and transfer functions.

Both run the discrete model x[k+1] = A x + B u, y = C x + D u at the block period. With
``method`` set, the given matrices (or polynomials) are a continuous-time model that
``bind(period)`` discretises with python-control. Their steps are library.c's ``lti_*``
kernels, which read the stacked matrices [A B] and [C D] and, for ``advance`` over a held
input, closed-form chunk matrices, all computed here once per discretisation.
"""

from __future__ import annotations

from fractions import Fraction
from typing import Any

import numpy as np

from blocks.arrays import float_array
from blocks.block import Signal
from blocks.library.kernel_block import Advancing
from blocks.limits import check_block_size

METHODS = ("zoh", "tustin")
"""Discretisation methods accepted by ``method`` (python-control names)."""

CHUNK = 64
"""Longest run of steps that one ``advance`` matrix of the context covers."""


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
    _check_size(n, m, p)
    if D is None:
        D = np.zeros((p, m))
    else:
        D = float_array(D, "D", ndim=2)
        if D.shape != (p, m):
            raise ValueError(f"parameter 'D' must have shape ({p}, {m}) to match C and B, got {D.shape}")
    return A, B, C, D


def _check_size(n: int, m: int, p: int) -> None:
    """ValueError before a model of ``n`` states, ``m`` inputs and ``p`` outputs is built
    whose matrices, and the CHUNK maps of its kernel's context, would hold too much."""
    check_block_size(("steps per advance map", CHUNK), ("states + outputs", n + p), ("states + inputs", n + m))


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
    _check_size(n, 1, 1)
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


class _LinearBlock(Advancing):
    """Shared machinery: discretisation and the kernel's context.

    ``A``, ``B``, ``C``, ``D`` are the discrete matrices in use (``None`` for a
    continuous model until ``bind``); the state is the 1-D array x of that realisation.
    """

    kernel_name = "lti"

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
        self.A = self.B = self.C = self.D = None
        self._x0 = x0
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
        self._x0 = x0
        self.feedthrough = bool(np.any(D != 0))
        # A stateless pure gain goes through the feedthrough branch even when D == 0.
        self._ft_path = self.feedthrough or self._n == 0
        self._scalar = (self._n, self._m, self._p) == (1, 1, 1)
        self._matrices = object()  # these matrices in the kernel's cache key: new ones, a new context

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

    def _all_chunks(self) -> tuple[np.ndarray, list[np.ndarray]]:
        """The maps of c steps with a held input u from z = [x; u], c = 1..CHUNK: the
        outputs of CHUNK steps stacked (those of c steps are its first c p rows) and the
        state after each c, from the powers S^c of the step matrix S = [[A, B], [0, I]]:
        rows [C D] S^c, state S^c[:n]."""
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

    def not_ready(self) -> str:
        if self.A is None:
            return (f"with method={self.method!r} it is a continuous model: "
                    "bind(period) must discretise it before it runs")
        return super().not_ready()

    def kernel(self):
        """None for a continuous model not yet bound."""
        return None if self.A is None else super().kernel()

    def cache_key(self):
        return self._matrices

    def context_numbers(self):
        """library.c's lti context: a header of sizes, the 1x1x1 model's four numbers and
        the offsets (from this header's start) of the matrices that follow: [A B], D,
        [C D], C and every chunk's maps (``_all_chunks``)."""
        n, m, p = self._n, self._m, self._p
        header = np.zeros(14 + 2 * CHUNK)
        scalar = self._scalar
        header[:5] = (n, m, p, scalar, self._ft_path)
        if scalar:
            header[5:9] = (self.A[0, 0], self.B[0, 0], self.C[0, 0], self.D[0, 0])
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
            header[10] = place(self.C)
            # chunk c's output map is the first c * p rows of chunk CHUNK's
            ymap, xmaps = self._all_chunks()
            header[14:14 + CHUNK] = place(ymap)
            for c in range(1, CHUNK + 1):
                header[13 + CHUNK + c] = place(xmaps[c - 1])
        return parts


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
