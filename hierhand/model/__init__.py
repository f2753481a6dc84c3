"""The hand/object model: hand file, the plant block, and the kinematics and dynamics
of the C core (``hierhand/csrc``) for Python callers.

Public API: ``load_hand(path_or_dict) -> Hand``, ``Hand.default()``, ``Hand`` (mass matrix,
bias, tip positions and Jacobians), ``HandPlant`` (the block), ``HandFileError``,
``hand_of(block)`` (the hand a plant block simulates, for the blocks that refer to it) and
``ObjectSupport`` (the block carrying the object until the hand-over).
"""

from .hand import Hand, load_hand
from .hand_source import hand_of
from .handfile import HandFileError, HandParams
from .plant import ContactWrenches, HandPlant, StateViews
from .support import ObjectSupport

__all__ = ["Hand", "HandFileError", "HandParams", "HandPlant", "ContactWrenches", "ObjectSupport", "StateViews",
           "hand_of", "load_hand"]
