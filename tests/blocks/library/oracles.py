"""Numpy statements of the simplest library blocks' steps, the oracles of their C kernels.

The blocks themselves are defined once, by their kernels (``blocks/csrc/library.c``); these
are the numpy code they had before, kept here so that ``test_kernels`` can hold each kernel
to an independent statement of its block: sources, gains, sums, saturation, delays, holds
and the linear blocks, whose ``advance`` is the closed form over chunks of at most
``CHUNK`` hits. Each function takes the (bound, sized) block for its parameters and
returns what its method returned: an output as a flat array, an update's new state, an
advance's (state, rows).
"""

from __future__ import annotations

import numpy as np

from blocks.library.lti import CHUNK

# -- sources ------------------------------------------------------------------------------


def constant(block, t):
    return block.value.copy()


def step(block, t):
    return (block.before if t < block.time else block.after).copy()


def ramp(block, t):
    elapsed = t - block.start
    if elapsed <= 0.0:
        return block.initial.copy()
    return block.initial + block.slope * elapsed


# -- arithmetic ---------------------------------------------------------------------------


def gain(block, u):
    if block.k.ndim == 2:
        return block.k.dot(u)
    return u * block.k


def signed_sum(block, inputs):
    """The first '+' input, the other '+' ones added, the '-' ones subtracted, in port
    order; with no '+' input minus the first; '--' as -(u0 + u1)."""
    ports = [f"u{j}" for j in range(len(block.signs))]
    if block.signs == "--":
        return -(inputs["u0"] + inputs["u1"])
    plus = [inputs[p] for p, s in zip(ports, block.signs) if s == "+"]
    minus = [inputs[p] for p, s in zip(ports, block.signs) if s == "-"]
    total = plus[0].copy() if plus else -minus.pop(0)
    for value in plus[1:]:
        total += value
    for value in minus:
        total -= value
    return total


def saturation(block, u):
    return np.minimum(np.maximum(u, block.lower), block.upper)


# -- discrete -----------------------------------------------------------------------------


def unit_delay_update(block, state, u):
    return u.copy()


def unit_delay_advance(block, state, u, n):
    """Held input: every one of the n following outputs is that input."""
    if n <= 0:
        return state, np.empty((0, state.size))
    return u.copy(), np.tile(u, (n, 1))


# -- linear time-invariant ----------------------------------------------------------------


def _scalar(block) -> bool:
    """One state, one input, one output: products of Python floats."""
    return (block.A.shape[0], block.B.shape[1], block.C.shape[0]) == (1, 1, 1)


def _feedthrough_path(block) -> bool:
    """Whether y = C x + D u (a stateless gain too, even with D = 0) rather than C x."""
    return bool(np.any(block.D != 0)) or block.A.shape[0] == 0


def lti_output(block, state, u):
    C, D = block.C, block.D
    if _scalar(block):
        if _feedthrough_path(block):
            return np.array((float(C[0, 0]) * state.item() + float(D[0, 0]) * u.item(),))
        return np.array((float(C[0, 0]) * state.item(),))
    if _feedthrough_path(block):
        if state is None:
            return D.dot(u)
        return np.hstack((C, D)).dot(np.concatenate((state, u)))
    return np.ascontiguousarray(C).dot(state)


def lti_update(block, state, u):
    A, B = block.A, block.B
    if _scalar(block):
        return np.array((float(A[0, 0]) * state.item() + float(B[0, 0]) * u.item(),))
    return np.hstack((A, B)).dot(np.concatenate((state, u)))


def lti_chunk(block, c):
    """Matrices mapping z = [x; u] to the c outputs stacked, and to the state after c
    steps with u held: [C D] S^i for i = 1..c and S^c[:n], S = [[A, B], [0, I]]."""
    n, m = block.A.shape[0], block.B.shape[1]
    step_matrix = np.zeros((n + m, n + m))
    step_matrix[:n] = np.hstack((block.A, block.B))
    step_matrix[n:, n:] = np.eye(m)
    CD = np.hstack((block.C, block.D))
    power = np.eye(n + m)
    rows = []
    for _ in range(c):
        power = step_matrix @ power
        rows.append(CD @ power)
    return np.ascontiguousarray(np.vstack(rows)), np.ascontiguousarray(power[:n])


def lti_advance(block, state, u, n):
    """Closed form for a held input, x_{k+i} = A^i x + (sum_{j<i} A^j) B u, in chunks of at
    most CHUNK hits; the 1x1x1 model's products written out as two-term sums
    (first * x) + (second * u)."""
    p = block.C.shape[0]
    if state is None:
        return None, np.tile(block.D.dot(u), (max(n, 0), 1))
    if n <= 0:
        return state, np.empty((0, p))
    nx = state.size
    out = np.empty((n, p))
    if _scalar(block):
        x, v = state.item(), u.item()
    else:
        z = np.concatenate((state, u))
    done = 0
    while done < n:
        c = min(n - done, CHUNK)
        ymap, xmap = lti_chunk(block, c)
        if _scalar(block):
            out[done:done + c] = ymap[:, :1].copy() * x + ymap[:, 1:].copy() * v
            x = float(xmap[0, 0]) * x + float(xmap[0, 1]) * v
        else:
            out[done:done + c] = ymap.dot(z).reshape(c, p)
            z[:nx] = xmap.dot(z)
        done += c
    return (np.array((x,)) if _scalar(block) else z[:nx].copy()), out
