"""Small blocks used by the executor tests (loaded with ``python:`` types and trust)."""

from __future__ import annotations

import os

import numpy as np

from blocks import Block, BlockError, EndRun, ParameterError


class Accumulator(Block):
    """x[k+1] = x[k] + u; y = x. No feedthrough; reference-loop advance only."""

    def __init__(self, width: int = 1):
        self.inputs = {"u": width}
        self.outputs = {"y": width}
        self.feedthrough = False
        self.width = width

    def initial_state(self):
        return np.zeros(self.width)

    def output(self, t, state, inputs):
        return {"y": state.copy()}

    def update(self, t, state, inputs):
        return state + inputs["u"]


class FastAccumulator(Accumulator):
    """The same equations with an overridden (closed-form) ``advance``."""

    def advance(self, t, state, inputs, n):
        steps = np.arange(1, n + 1)[:, None]
        rows = state[None, :] + steps * inputs["u"][None, :]
        return rows[-1].copy(), {"y": rows}


class ReadyAccumulator(FastAccumulator):
    """The fast accumulator that creates the file ``path`` when an ``advance`` call begins
    with at least ``after`` hits already done (u = 1): the sign a test waits for that a run
    has logged the hits before that call (the executor logs each call's rows before the next)."""

    def __init__(self, path: str = "", after: int = 0):
        super().__init__()
        self.path, self.after = path, after

    def advance(self, t, state, inputs, n):
        if state[0] >= self.after and not os.path.exists(self.path):
            with open(self.path, "a", encoding="utf-8"):
                pass
        return super().advance(t, state, inputs, n)


class ChunkStart(FastAccumulator):
    """The accumulator whose ``advance`` outputs, at every hit of a call, the time ``t``
    that call was given: the logged values show the start time of each advance chunk."""

    def advance(self, t, state, inputs, n):
        state, rows = super().advance(t, state, inputs, n)
        return state, {"y": np.full_like(rows["y"], t)}


class SplitFeedthrough(Block):
    """Two outputs: ``direct`` = u (feedthrough), ``held`` = state (none); state <- u."""

    def __init__(self):
        self.inputs = {"u": 1}
        self.outputs = {"direct": 1, "held": 1}
        self.feedthrough = {"direct": {"u"}, "held": set()}

    def initial_state(self):
        return np.array([1.0])

    def output(self, t, state, inputs):
        return {"direct": inputs["u"].copy(), "held": state.copy()}

    def update(self, t, state, inputs):
        return inputs["u"].copy()


class FailAfter(Block):
    """Passes u through until ``t_fail``, then raises a BlockError on port y."""

    def __init__(self, t_fail: float = 0.005):
        self.inputs = {"u": 1}
        self.outputs = {"y": 1}
        self.t_fail = t_fail

    def output(self, t, state, inputs):
        if t >= self.t_fail:
            raise BlockError("value out of range", port="y")
        return {"y": inputs["u"].copy()}


class Clock(Block):
    """y = t, so tests can see exactly when a block fired."""

    time_varying = True
    outputs = {"y": 1}

    def output(self, t, state, inputs):
        return {"y": np.array([t])}


class CappedAccumulator(Accumulator):
    """An Accumulator whose update fails once the state would pass ``limit``."""

    def __init__(self, limit: float = 1.0):
        super().__init__(1)
        self.limit = float(limit)

    def update(self, t, state, inputs):
        new = state + inputs["u"]
        if new[0] > self.limit:
            raise BlockError(f"state passes {self.limit:g}", port="y")
        return new


class FastCappedAccumulator(CappedAccumulator):
    """The same, advanced in closed form; a failing span hands back the rows it completed."""

    def advance(self, t, state, inputs, n):
        rows = state[None, :] + np.arange(1, n + 1)[:, None] * inputs["u"][None, :]
        over = np.flatnonzero(rows[:, 0] > self.limit)
        if over.size:
            raise BlockError(f"state passes {self.limit:g}", port="y", rows={"y": rows[:over[0]]})
        return rows[-1].copy(), {"y": rows}


class Model(Block):
    """y = value: a block that other blocks refer to (its ``value`` is their model)."""

    def __init__(self, value: float = 1.0):
        self.value = float(value)
        self.outputs = {"y": 1}
        self.feedthrough = False

    def describe(self):
        return f"value {self.value:g}"

    def output(self, t, state, inputs):
        return {"y": np.array([self.value])}


class ScaleByModel(Block):
    """y = source.value * u: ``source`` (and the optional ``spare``) are block references."""

    block_params = ("source", "spare")

    def __init__(self, source, spare=None, offset: float = 0.0):
        if not isinstance(source, Model):
            raise ValueError(f"parameter 'source' must be a Model block, got {type(source).__name__}")
        self.source, self.spare, self.offset = source, spare, float(offset)
        self.inputs = {"u": 1}
        self.outputs = {"y": 1}

    def output(self, t, state, inputs):
        return {"y": self.source.value * inputs["u"] + self.offset}


class Weights(Block):
    """y = weights (a list parameter with a tuple default); ``extra`` defaults to None but
    stands for the list [1.0, 2.0, 3.0] (its ``param_default``)."""

    def __init__(self, weights=(1.0, 2.0), extra=None):
        self.weights = np.asarray(weights, dtype=float)
        self.extra = np.asarray([1.0, 2.0, 3.0] if extra is None else extra, dtype=float)
        self.outputs = {"y": self.weights.size, "extra": self.extra.size}
        self.feedthrough = False

    @classmethod
    def param_default(cls, name):
        return [1.0, 2.0, 3.0] if name == "extra" else super().param_default(name)

    def output(self, t, state, inputs):
        return {"y": self.weights.copy(), "extra": self.extra.copy()}


class InterruptedAccumulator(FastAccumulator):
    """A FastAccumulator whose ``advance`` raises KeyboardInterrupt at its ``calls``-th call,
    as Ctrl-C does when it lands inside a long span of advanced hits."""

    def __init__(self, calls: int = 3):
        super().__init__(1)
        self.calls = calls
        self.made = 0

    def advance(self, t, state, inputs, n):
        self.made += 1
        if self.made == self.calls:
            raise KeyboardInterrupt
        return super().advance(t, state, inputs, n)


class Touch(Block):
    """A source that creates the file ``path`` when it first computes its output (at t = 0):
    the sign a test waits for that a run has started."""

    outputs = {"y": 1}
    feedthrough = False

    def __init__(self, path: str = ""):
        self.path = path

    def output(self, t, state, inputs):
        with open(self.path, "a", encoding="utf-8"):
            pass
        return {"y": np.zeros(1)}


class Limits(Block):
    """y = sum of ``gains``; every gain must be positive: each negative one is a
    ``ParameterError`` problem at ``("gains", name)``, a non-mapping ``gains`` a ValueError."""

    def __init__(self, gains=None, scale: float = 1.0):
        gains = {} if gains is None else gains
        if not isinstance(gains, dict):
            raise ValueError("gains must be a mapping")
        bad = [(("gains", k), f"gains.{k} must be positive, got {v}") for k, v in gains.items() if v <= 0]
        if bad:
            raise ParameterError(bad)
        self.total = scale * sum(gains.values())
        self.outputs = {"y": 1}

    def output(self, t, state, inputs):
        return {"y": np.array([self.total])}


class StartsFromInput(Block):
    """A unit delay whose first output is its current input: y = u at its first hit, then
    the u of the hit before. Like an FMU whose initial outputs follow the inputs set before
    initialisation: no feedthrough but initial feedthrough. ``u`` defaults to -1."""

    def __init__(self):
        self.inputs = {"u": 1}
        self.outputs = {"y": 1}
        self.input_defaults = {"u": np.array([-1.0])}
        self.feedthrough = False
        self.initial_feedthrough = True

    def initial_state(self):
        return (False, np.zeros(1))

    def output(self, t, state, inputs):
        started, last = state
        return {"y": (last if started else inputs["u"]).copy()}

    def update(self, t, state, inputs):
        return (True, inputs["u"].copy())


class StartsFromOneInput(Block):
    """Unit delays u -> y and w -> z (z starts at 0); only y's first output is its current
    input (initial feedthrough ``{"y": {"u"}}``). Both inputs default to -1."""

    def __init__(self):
        self.inputs = {"u": 1, "w": 1}
        self.outputs = {"y": 1, "z": 1}
        self.input_defaults = {"u": np.array([-1.0]), "w": np.array([-1.0])}
        self.feedthrough = False
        self.initial_feedthrough = {"y": {"u"}}

    def initial_state(self):
        return (False, np.zeros(1), np.zeros(1))

    def output(self, t, state, inputs):
        started, last_u, last_w = state
        return {"y": (last_u if started else inputs["u"]).copy(), "z": last_w.copy()}

    def update(self, t, state, inputs):
        return (True, inputs["u"].copy(), inputs["w"].copy())


class Counter(Block):
    """y = count; each update adds 1 and, once the count reaches ``stop``, raises EndRun
    with the new count as its state (or, with ``give_state`` false, without a state, so
    the count stays where it was). ``u`` is only there to inherit a rate from."""

    input_defaults = {"u": np.zeros(1)}

    def __init__(self, stop: int = 3, give_state: bool = True):
        self.stop, self.give_state = stop, give_state
        self.inputs = {"u": 1}
        self.outputs = {"y": 1}
        self.feedthrough = False

    def initial_state(self):
        return np.zeros(1)

    def output(self, t, state, inputs):
        return {"y": state.copy()}

    def update(self, t, state, inputs):
        new = state + 1.0
        if new[0] >= self.stop:
            if self.give_state:
                raise EndRun(f"the count reached {self.stop}", state=new)
            raise EndRun(f"the count reached {self.stop}")
        return new


class EndInOutput(Block):
    """y = 0 until ``t_end``, then its output raises EndRun (which only update may)."""

    outputs = {"y": 1}
    time_varying = True

    def __init__(self, t_end: float = 0.002):
        self.t_end = t_end

    def output(self, t, state, inputs):
        if t >= self.t_end:
            raise EndRun("done")
        return {"y": np.zeros(1)}


class Labelled(Block):
    """y = [1, 2, ..., width] with the elements named by ``labels`` (None: numbered from 0)
    and the unit(s) ``units`` (None: unknown)."""

    def __init__(self, labels=None, width: int = 3, units=None):
        self.labels = labels
        self.units = units
        self.outputs = {"y": width}
        self.feedthrough = False

    def element_labels(self, port):
        return self.labels

    def port_units(self, port):
        return self.units

    def output(self, t, state, inputs):
        return {"y": np.arange(1.0, self.outputs["y"] + 1)}


class EndInAdvance(FastAccumulator):
    """A FastAccumulator whose ``advance`` raises EndRun (which only update may)."""

    def advance(self, t, state, inputs, n):
        raise EndRun("done")
