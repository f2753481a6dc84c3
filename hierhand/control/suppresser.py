"""The suppresser block: lets voluntary motion override the grasping reflex, joint by joint.

Its law is ``suppresser_kernel`` (compiled, ``hierhand/csrc/suppresser.c``).
"""

from __future__ import annotations

from typing import Any, Mapping

import numpy as np

from blocks import Block
from blocks.arrays import flat_float64, float_array
from blocks.kernel import Kernel, address

from ..kernels import KERNELS
from ..model.port_info import DescribesHandPorts

from .suppresser_kernel import (
    N_OUT,
    O_SHARE,
    O_TAU,
    O_TAU_G_EFF,
    PASS,
    check_steepness,
    mode_code,
    pack_params,
    suppress_output,
)


class Suppresser(DescribesHandPorts, Block):
    """Actuator command ``tau = tau_g * sigmoid(S_a (S_b - g(tau_m))) + tau_m`` per joint.

    An optional input ``tau_ff`` (zero when unconnected) is added to the command
    unsuppressed: the manipulation controller's feedforward (finger gravity, the object's
    weight), which is not voluntary motion and must not weigh against the grasp.

    ``mode: magnitude`` (default) uses g = |tau_m|: the larger the manipulation torque of
    a joint, in either direction, the more its grasping torque is suppressed, as the
    paper's prose describes. ``mode: signed`` is the paper's literal formula (g = tau_m),
    which only suppresses against positive manipulation torques. ``enabled: false``
    passes tau_g through unchanged, for the paper's comparison run without suppression.

    The nine joints are done in one native call (``suppress_output``).

    Parameters
    ----------
    S_a : scalar or 9 values
        sigmoid steepness, 1/(N m)
    S_b : scalar or 9 values
        manipulation torque, N m, at which the grasping torque is halved
    mode : str
        'magnitude' (suppress by |tau_m|) or 'signed' (the paper's literal formula)
    enabled : bool
        false passes the grasping torque through unsuppressed
    """

    type_name = "Suppresser"

    def __init__(self, S_a: Any = 100.0, S_b: Any = 0.1, mode: str = "magnitude", enabled: bool = True):
        code = mode_code(mode)
        self.S_a = float_array(S_a, "S_a", ndim=1, width=9, broadcast=True)
        self.S_b = float_array(S_b, "S_b", ndim=1, width=9, broadcast=True)
        check_steepness(self.S_a)
        self.mode = mode
        self.enabled = bool(enabled)
        self.inputs = {"tau_g": 9, "tau_m": 9, "tau_ff": 9}
        self.input_defaults = {"tau_ff": np.zeros(9)}
        self.outputs = {"tau": 9, "tau_g_eff": 9, "share": 3}
        self.feedthrough = True
        self._params = pack_params(self.S_a, self.S_b, code if self.enabled else PASS)

    def output(self, t: float, state: Any, inputs: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
        """One native call on the parameters packed in ``__init__`` (so S_a, S_b or the mode
        changed on the object afterwards are not seen). Inputs the native call refuses for
        their type (lists, other dtypes, strided views) are converted to float64 first;
        inputs of the wrong width raise ``ValueError`` naming the port."""
        out = np.empty(N_OUT)
        tau_g, tau_m, tau_ff = inputs["tau_g"], inputs["tau_m"], inputs.get("tau_ff", self.input_defaults["tau_ff"])
        try:
            suppress_output(self._params, tau_g, tau_m, tau_ff, out)
        except TypeError:
            suppress_output(self._params, flat_float64(tau_g), flat_float64(tau_m), flat_float64(tau_ff), out)
        return {"tau": out[O_TAU:O_TAU + 9], "tau_g_eff": out[O_TAU_G_EFF:O_TAU_G_EFF + 9],
                "share": out[O_SHARE:O_SHARE + 3]}

    def kernel(self) -> Kernel | None:
        """``output`` in C: the same native law on the parameters packed in ``__init__``
        (stateless, no period needed)."""
        return Kernel(context=address(self._params), output=KERNELS["Suppresser.output"], owners=(self._params,),
                      nogil=True)
