"""The hand a controller models, taken from the block that simulates it: ``hand_of(source)``.

The hand is given once, on the plant. ``GraspReflex``, ``ManipulationPD`` and
``ObjectSupport`` have a block-reference parameter ``hand`` (``hand: plant`` in a
diagram; the loader passes the plant block), so ``--set plant.object.mass=0.36`` changes
the model of every block at once; in an exported FMU their records' hand segments are
linked to the plant's (``hand_link``). The plant may be a ``HandPlant`` or the FMU that
``hierhand fmu export`` makes of it; from Python a ``Hand`` will do as well.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from blocks import Block
from blocks.engine.kernel import Link

from ..layouts import PLANT_RECORD, SEGMENT
from .hand import Hand, load_hand
from .handfile import HandFileError, default_hand_dict
from .hand_vector import hand_dict, parameter_names
from .plant import HandPlant

if TYPE_CHECKING:
    from blocks.fmu import FMU

EXPECTED = "expected a HandPlant or an FMU exported by 'hierhand fmu export'"
EXPECTED_FROM_PYTHON = "expected a HandPlant, an FMU exported by 'hierhand fmu export', or a Hand"


class ModelsTheHand:
    """Mixin of the blocks that model the hand they act on: the block-reference parameter
    ``hand``, and a documentation instance on the default hand (``hierhand blocks``).

    A block that says more about its ``hand`` documents it in its own docstring, which
    wins (``blocks.typeinfo`` reads the nearest class first).

    Parameters
    ----------
    hand : HandPlant or FMU
        the block that simulates the hand (hand: plant); an FMU must be one exported by
        'hierhand fmu export'; the hand is given once, on that block (from Python: the
        block or a Hand)
    """

    block_params = ("hand",)

    @classmethod
    def example(cls):
        return cls(hand=Hand.default())


def hand_of(source: Any, param: str = "hand") -> Hand:
    """The ``Hand`` of a plant block (``HandPlant`` or exported FMU) or a ``Hand`` itself.

    ValueError naming ``param`` and what it got otherwise, e.g. "parameter 'hand': block
    'support' is a Step; expected a HandPlant or an FMU exported by 'hierhand fmu export'".
    """
    if isinstance(source, Hand):
        return source
    if isinstance(source, HandPlant):
        return source.hand
    from blocks.fmu import FMU  # here, not at import: most plants are HandPlants, and it costs 8 ms

    if isinstance(source, FMU):
        missing = [name for name in parameter_names() if name not in source.parameter_values()]
        if not missing:
            return fmu_hand(source)
        more = f" and {len(missing) - 1} more" if len(missing) > 1 else ""
        what = f"{_block(source)} is an FMU ({source.path.name}) without the hand's parameters (no {missing[0]}{more})"
    elif isinstance(source, Block):
        kind = source.registered_name()
        what = f"{_block(source)} is {'an' if kind[:1] in 'AEIOU' else 'a'} {kind}"
    elif isinstance(source, str):
        what = f"got the text {source!r} (a block's name is resolved only in a diagram)"
    else:
        what = f"got a {type(source).__name__}"
    in_diagram = isinstance(source, Block) and source.name is not None
    raise ValueError(f"parameter '{param}': {what}; {EXPECTED if in_diagram else EXPECTED_FROM_PYTHON}")


def hand_link(source: Any, slot: int) -> tuple[Link, ...]:
    """The link of a record's hand segment at ``slot`` to the plant block ``source``, whose
    record holds its own at ``PLANT_RECORD.SEGMENT`` (no link when the hand was given
    otherwise, as a ``Hand``)."""
    return (Link(slot, SEGMENT.size, source, PLANT_RECORD.SEGMENT),) if isinstance(source, HandPlant) else ()


def fmu_hand(fmu: "FMU") -> Hand:
    """The hand an exported plant FMU simulates, from its parameter values (the block's
    start values over the FMU's defaults). Finger names are not FMU parameters: the
    fingers get the default hand's names (thumb, fore, middle)."""
    values = fmu.parameter_values()
    data = hand_dict([values[name] for name in parameter_names()])
    for finger, default in zip(data["fingers"], default_hand_dict()["fingers"]):
        finger["name"] = default["name"]
    try:
        return load_hand(data)
    except HandFileError as exc:
        raise HandFileError(exc.errors, f"(the parameters of FMU '{fmu.path.name}')") from None


def _block(source: Block) -> str:
    return f"block '{source.name}'" if source.name else "the block"
