"""Arguments for the compiled laws: what ``hierhand._native`` takes is C-contiguous float64.

The native calls refuse anything else with ``TypeError`` rather than copying behind the
caller's back, so that the blocks' hot paths never convert. The Python side converts on
that refusal (or up front, for the user-facing functions) with ``flat_float64``.
"""

from __future__ import annotations

from typing import Any

import numpy as np


def flat_float64(x: Any) -> np.ndarray:
    """A 1-D C-contiguous float64 array of ``x`` (a list, another dtype, a strided view);
    ``x`` itself where it already is one."""
    return np.ascontiguousarray(x, dtype=np.float64).reshape(-1)
