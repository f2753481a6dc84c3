"""The standard block library: sources, arithmetic, delays and LTI models.

``LIBRARY`` lists every block class, for registries and the CLI to enumerate.
"""

from blocks.library.discrete import UnitDelay, ZeroOrderHold
from blocks.library.lti import DiscreteStateSpace, DiscreteTransferFunction
from blocks.library.math_blocks import Gain, Saturation, Sum
from blocks.library.sources import Constant, Ramp, Step

LIBRARY = (
    Constant,
    Step,
    Ramp,
    Gain,
    Sum,
    Saturation,
    UnitDelay,
    ZeroOrderHold,
    DiscreteStateSpace,
    DiscreteTransferFunction,
)

__all__ = [cls.__name__ for cls in LIBRARY] + ["LIBRARY"]
