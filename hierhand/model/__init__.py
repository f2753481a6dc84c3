"""The hand/object model: hand file, the plant block, and the kinematics and dynamics
of the C core (``hierhand/csrc``) for Python callers.

Public API: ``load_hand(path_or_dict) -> Hand``, ``Hand.default()``, ``Hand`` (mass matrix,
bias, tip positions and Jacobians), ``HandPlant`` (the block), ``HandFileError``.
"""

from .hand import Hand, load_hand
from .handfile import HandFileError, HandParams
from .plant import ContactWrenches, HandPlant, StateViews

__all__ = ["Hand", "HandFileError", "HandParams", "HandPlant", "ContactWrenches", "StateViews", "load_hand"]
