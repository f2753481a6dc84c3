"""Running one block over a sequence of inputs, for the library's reference tests.

``step(block, inputs, n, period)`` binds the block, resolves its open widths from the
inputs, and runs n hits through its Python methods (output, then update, as the executor
does), returning each output port's (n, width) rows. The Python methods of the
library's signal blocks call their C kernels, so this exercises the kernels too.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np

PERIOD = Fraction(1, 1000)


def step(block, inputs: dict | None = None, n: int | None = None, period: Fraction | None = PERIOD,
         t0: float = 0.0) -> dict[str, np.ndarray]:
    """The outputs of ``n`` hits of ``block`` (n: the inputs' length), each input given as
    an (n,) or (n, width) array; time t0 + k * period."""
    inputs = {p: np.asarray(v, dtype=float).reshape(len(v), -1) for p, v in (inputs or {}).items()}
    if n is None:
        n = len(next(iter(inputs.values())))
    block.bind(period)
    open_width = [v.shape[1] for p, v in inputs.items() if block.inputs.get(p) is None]
    if open_width or any(w is None for w in block.outputs.values()):
        block.set_width(open_width[0] if open_width else 1)
    state = block.initial_state()
    dt = float(period) if period is not None else 1.0
    rows: dict[str, list] = {p: [] for p in block.outputs}
    for k in range(n):
        t = t0 + k * dt
        now = {p: v[k] for p, v in inputs.items()}
        out = block.output(t, state, now)
        for p in rows:
            rows[p].append(out[p])
        if state is not None:
            state = block.update(t, state, now)
    return {p: np.array(v).reshape(n, block.outputs[p]) for p, v in rows.items()}


def series(n: int, seed: int = 0, scale: float = 1.0) -> np.ndarray:
    """A reproducible test signal: a random walk plus steps, (n,)."""
    rng = np.random.default_rng(seed)
    walk = np.cumsum(rng.normal(0.0, 0.1, n))
    steps = np.where((np.arange(n) // 37) % 2 == 0, 1.0, -0.5)
    return scale * (walk + steps)


def advanced(block, n: int, period: Fraction = PERIOD) -> np.ndarray:
    """The output ``y`` of an input-less block at its first n hits: the first output, then
    one ``advance`` over the rest (one C call, for long sequences)."""
    block.bind(period)
    state = block.initial_state()
    first = block.output(0.0, state, {})["y"]
    state, rows = block.advance(0.0, state, {}, n - 1)
    return np.vstack((first, rows["y"]))
