"""The standard block library: sources, arithmetic, routing, logic, tables, discontinuities,
discrete dynamics (delays, integrators, PID, LTI models) and Stop.

``LIBRARY`` lists every block class, for registries and the CLI to enumerate.
"""

from blocks.library.arithmetic import Abs, Bias, Divide, Math, MinMax, Product, Sign
from blocks.library.discrete import DiscreteDerivative, Memory, MovingAverage, UnitDelay, ZeroOrderHold
from blocks.library.from_file import FromFile
from blocks.library.integrator import DiscreteIntegrator
from blocks.library.logic import Compare, Logic, MultiportSwitch, Relational, Switch
from blocks.library.lookup import LookupTable1D, LookupTable2D
from blocks.library.lti import DiscreteStateSpace, DiscreteTransferFunction
from blocks.library.math_blocks import Gain, Saturation, Sum
from blocks.library.noise import BandLimitedWhiteNoise, RandomNumber
from blocks.library.nonlinear import Backlash, DeadZone, Quantizer, RateLimiter
from blocks.library.pid import PID
from blocks.library.routing import Concatenate, Demux, Mux, Selector
from blocks.library.sources import Constant, Ramp, Step
from blocks.library.stop import Stop
from blocks.library.waveforms import Chirp, Pulse, Sine

LIBRARY = (
    Constant,
    Step,
    Ramp,
    Sine,
    Pulse,
    Chirp,
    FromFile,
    RandomNumber,
    BandLimitedWhiteNoise,
    Gain,
    Sum,
    Product,
    Divide,
    Abs,
    Sign,
    Bias,
    MinMax,
    Math,
    Saturation,
    DeadZone,
    Quantizer,
    RateLimiter,
    Backlash,
    Mux,
    Demux,
    Selector,
    Concatenate,
    Switch,
    MultiportSwitch,
    Relational,
    Compare,
    Logic,
    LookupTable1D,
    LookupTable2D,
    UnitDelay,
    Memory,
    ZeroOrderHold,
    DiscreteIntegrator,
    DiscreteDerivative,
    MovingAverage,
    PID,
    DiscreteStateSpace,
    DiscreteTransferFunction,
    Stop,
)

__all__ = [cls.__name__ for cls in LIBRARY] + ["LIBRARY"]
