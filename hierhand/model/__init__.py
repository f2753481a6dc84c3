"""The hand/object model: hand file, kinematics, dynamics, contact and the plant block.

Public API: ``load_hand(path_or_dict) -> Hand``, ``Hand.default()``, ``Hand`` (mass matrix,
bias, tip positions and Jacobians), ``HandPlant`` (the block), ``HandFileError``.
"""

from .kernel_cache import invalidate_if_stale, model_dispatchers

invalidate_if_stale(model_dispatchers())

from .hand import Hand, load_hand  # noqa: E402 - after the cache check, before any kernel runs
from .handfile import HandFileError, HandParams  # noqa: E402
from .plant import ContactWrenches, HandPlant, StateViews  # noqa: E402

__all__ = ["Hand", "HandFileError", "HandParams", "HandPlant", "ContactWrenches", "StateViews", "load_hand"]
