"""The numba plant kernels behind the HandPlant interface, to compare the C core with them."""

import numpy as np

from hierhand.model.kernel import advance_kernel, output_kernel, step_kernel
from hierhand.model.layout import N_OUTPUTS
from hierhand.model.plant import _PORT_COLUMNS, _PORT_SLICES, HandPlant


class NumbaHandPlant(HandPlant):
    """HandPlant stepped by the numba kernels it had before the C core."""

    def bind(self, period) -> None:
        super().bind(period)
        self._body = self.hand.body.copy()
        self._body[-1] = self.dt  # B_DT is the last body slot
        self._fingers = np.ascontiguousarray(self.hand.fingers)
        self._edges = np.ascontiguousarray(self.hand.edges)

    def output(self, t, state, inputs):
        row = np.empty(N_OUTPUTS)
        code, which = output_kernel(state, self._fingers, self._body, self._edges, row)
        assert code == 0
        return {name: row[sl] for name, sl in _PORT_SLICES}

    def update(self, t, state, inputs):
        code, _, _ = step_kernel(state, inputs["tau"], inputs["f_ext"], self._fingers, self._body, self._edges)
        assert code == 0
        return state

    def advance(self, t, state, inputs, n):
        rows = np.empty((n, N_OUTPUTS))
        code, _, _ = advance_kernel(state, inputs["tau"], inputs["f_ext"], self._fingers, self._body, self._edges,
                                    rows)
        assert code == 0
        return state, {name: rows[index] for name, index in _PORT_COLUMNS}
