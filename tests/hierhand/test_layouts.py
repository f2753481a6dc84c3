"""The flat arrays' layouts: Python's numbers are the C compiler's, and every table adds up.

``hierhand/csrc/layouts.h`` declares each array once (and each kernel type's input ports);
the C enums and the extension's ``LAYOUTS`` and ``INPUT_PORTS`` are all made from it. Here a
small C program, compiled from that header alone (no extension involved), prints every
enum constant by its C name; Python's value of each must be what it prints. The tables
must tile their arrays (each slot where the previous one ends, the last ending at the
size), and the tables built from others must agree with them.
"""

from __future__ import annotations

import shutil
import subprocess
import tomllib
from importlib.metadata import EntryPoint
from pathlib import Path

import numpy as np
import pytest

from blocks import registry
from blocks.registry import block_types
from hierhand import _native, layouts
from hierhand.layouts import (
    DIMENSIONS,
    FINGER_ROW,
    HAND,
    HAND_FINGER,
    HAND_LINK,
    LAYOUTS,
    LINK,
    OUTPUT,
    RECORDS,
    SEGMENT,
)
from hierhand.model.hand_vector import parameter_names
from hierhand.model.plant import HandPlant

CSRC = Path(__file__).resolve().parents[2] / "hierhand" / "csrc"


def c_names() -> list[str]:
    """The C name of every slot, input port, size and dimension."""
    tables = [(layout.c_prefix, layout.slots, layout.c_size) for layout in LAYOUTS.values()]
    tables += [(prefix, slots, count) for _, slots, prefix, count in _native.INPUT_PORTS.values()]
    names = [prefix + slot for prefix, slots, _ in tables for slot, _, _ in slots]
    return names + [size for _, _, size in tables] + [f"HH_{name}" for name in DIMENSIONS]


@pytest.fixture(scope="module")
def c_values(tmp_path_factory) -> dict[str, int]:
    """Every slot's and size's C enum constant, by its C name, as a program compiled from
    layouts.h prints it."""
    compiler = shutil.which("gcc") or shutil.which("cc")
    if compiler is None:
        pytest.skip("no C compiler")
    names = c_names()
    lines = "".join(f'    printf("%s %ld\\n", "{name}", (long)({name}));\n' for name in names)
    folder = tmp_path_factory.mktemp("layouts")
    source = folder / "print_layouts.c"
    source.write_text(f'#include <stdio.h>\n#include "layouts.h"\nint main(void)\n{{\n{lines}    return 0;\n}}\n')
    program = folder / "print_layouts"
    subprocess.run([compiler, "-std=c99", "-Wall", "-Werror", "-I", str(CSRC), "-o", str(program), str(source)],
                   check=True)
    printed = subprocess.run([str(program)], check=True, capture_output=True, text=True).stdout
    return {name: int(value) for name, value in (line.split() for line in printed.splitlines())}


def test_every_python_offset_and_size_is_the_c_compilers(c_values):
    for layout in LAYOUTS.values():
        for slot, offset, _ in layout.slots:
            assert getattr(layout, slot) == offset == c_values[layout.c_prefix + slot], (layout.name, slot)
        assert layout.size == c_values[layout.c_size], layout.name
    assert {name: c_values[f"HH_{name}"] for name in DIMENSIONS} == DIMENSIONS
    assert sorted(c_values) == sorted(c_names())  # the program printed every one


@pytest.mark.parametrize("name", sorted(LAYOUTS))
def test_each_layout_tiles_its_array(name):
    """Slots follow one another without gap or overlap, and the last ends at the size; only
    a last slot may be of variable length (width 0)."""
    layout = LAYOUTS[name]
    end = 0
    for slot, offset, width in layout.slots:
        assert offset == end, f"{name}.{slot} starts at {offset}, the slot before it ends at {end}"
        assert width > 0 or slot == layout.slots[-1][0], f"{name}.{slot} has width 0 but is not last"
        assert layout.slice(slot) == slice(offset, offset + width)
        end = offset + width
    assert end == layout.size
    assert getattr(layouts, name) is layout


def test_the_nested_tables_add_up():
    fingers, links = DIMENSIONS["FINGERS"], DIMENSIONS["LINKS"]
    assert FINGER_ROW.width("LINK0") == links * LINK.size
    assert HAND_FINGER.width("LINK0") == links * HAND_LINK.size
    assert HAND.width("FINGER0") == fingers * HAND_FINGER.size and HAND.size == len(parameter_names())
    assert SEGMENT.size == 1 + HAND.size and SEGMENT.width("HAND") == HAND.size
    assert sum(HandPlant().outputs.values()) == OUTPUT.size and list(HandPlant().outputs)[:2] == ["q", "qd"]
    for kind, record in RECORDS.items():
        for slot, _, width in record.slots:
            if slot == "SEGMENT":
                assert width == SEGMENT.size, kind
            if slot == "GIVEN":
                given = record.name.replace("_RECORD", "_GIVEN")
                assert width == LAYOUTS[given].size, kind


def test_each_input_port_is_read_where_its_block_declares_it(c_values):
    """inputs[i] of a kernel is the block's i-th input port: the C index of each port is its
    position in the block's ``inputs``, its width the port's."""
    from hierhand.control.grasp_reflex import GraspReflex
    from hierhand.control.joint_low_pass import JointLowPass
    from hierhand.control.manipulation_pd import ManipulationPD
    from hierhand.control.suppresser import Suppresser
    from hierhand.model import Hand

    hand = Hand.default()
    blocks = {"PLANT_INPUTS": HandPlant(), "REFLEX_INPUTS": GraspReflex(hand=hand),
              "MANIP_INPUTS": ManipulationPD(hand=hand), "SUPPRESS_INPUTS": Suppresser(),
              "JOINT_LOW_PASS_INPUTS": JointLowPass()}
    assert set(blocks) == set(_native.INPUT_PORTS)
    for name, block in blocks.items():
        count, slots, prefix, count_name = _native.INPUT_PORTS[name]
        assert list(block.inputs.items()) == [(slot.lower(), width) for slot, _, width in slots], name
        assert [c_values[prefix + slot] for slot, _, _ in slots] == list(range(count)) and c_values[count_name] == count


def test_every_kernel_type_has_its_record_layout():
    from hierhand import _native

    kinds = {name.split(".")[0] for name in _native.kernels()}
    assert set(RECORDS) == kinds
    assert RECORDS["GraspReflex"] is layouts.REFLEX_RECORD and RECORDS["JointLowPass"] is layouts.JOINT_LOW_PASS_RECORD


def test_the_records_block_classes_are_hierhands_registered_types_with_no_line_of_their_own_in_pyproject():
    """A new block type is registered by its record's line in layouts.h (its class named
    there), through hierhand's one ``blocks.types`` entry point: every class named there is
    the registered type of its name, one per kernel type, and pyproject.toml lists none."""
    types = block_types()
    named = [EntryPoint("", reference, "").load() for reference in layouts.BLOCK_CLASSES]
    assert {cls.registered_name() for cls in named} == set(RECORDS)
    assert all(types[cls.registered_name()] is cls for cls in named)
    assert {name for name, cls in types.items() if cls.__module__.startswith("hierhand.")} == set(RECORDS)
    with open(CSRC.parents[1] / "pyproject.toml", "rb") as f:
        declared = tomllib.load(f)["project"]["entry-points"][registry.ENTRY_POINT_GROUP]
    assert [v for v in declared.values() if v.startswith("hierhand.")] == ["hierhand.layouts:BLOCK_CLASSES"]


# The hand-file name of each slot of the hand vector (hand_params.c's table), as the oracle.
_HAND_NAMES = {"GX": "gravity[1]", "GY": "gravity[2]", "OBJ_MASS": "object.mass", "OBJ_INERTIA": "object.inertia",
               "OBJ_SIZE": "object.size[1]", "OBJ_POS": "object.pos[1]", "OBJ_ANGLE": "object.angle",
               "OBJ_SPACING": "object.surface_spacing", "K_N": "contact.k_n", "C_N": "contact.c_n",
               "K_T": "contact.k_t", "C_T": "contact.c_t", "MU_S": "contact.mu_s", "MU_D": "contact.mu_d"}
_FINGER_NAMES = {"BASE": "base[1]", "BASE_ANGLE": "base_angle", "DAMPING": "damping[1]",
                 "ARMATURE": "armature[1]", "TIP_RADIUS": "tip_radius", "Q0": "q0[1]"}
_LINK_NAMES = {"LENGTH": "length", "MASS": "mass", "INERTIA": "inertia", "COM_ALONG": "com[1]",
               "COM_ACROSS": "com[2]"}


def test_the_hand_vectors_slots_name_the_numbers_the_c_core_names_there():
    """hand_params.c names each number of the hand vector in a table of its own; the name at
    each slot of HAND, HAND_FINGER and HAND_LINK is that slot's."""
    names = parameter_names()
    found = {names[getattr(HAND, slot)]: name for slot, name in _HAND_NAMES.items()}
    for f in range(DIMENSIONS["FINGERS"]):
        finger = HAND.FINGER0 + f * HAND_FINGER.size
        for slot, name in _FINGER_NAMES.items():
            found[names[finger + getattr(HAND_FINGER, slot)]] = f"fingers[{f + 1}].{name}"
        for link in range(DIMENSIONS["LINKS"]):
            at = finger + HAND_FINGER.LINK0 + link * HAND_LINK.size
            for slot, name in _LINK_NAMES.items():
                found[names[at + getattr(HAND_LINK, slot)]] = f"fingers[{f + 1}].links[{link + 1}].{name}"
    assert all(actual == expected for actual, expected in found.items()), \
        [(a, e) for a, e in found.items() if a != e]
    assert len(found) == len(_HAND_NAMES) + 3 * (len(_FINGER_NAMES) + 3 * len(_LINK_NAMES))


def test_a_record_of_the_wrong_length_is_refused_before_c_sees_it():
    from hierhand.records import record

    with pytest.raises(ValueError, match="a JointLowPass record holds the 2 values of JOINT_LOW_PASS_RECORD, not 3"):
        record("JointLowPass", [0.1, 0.001, 5.0])
    assert record("JointLowPass", [0.1, 0.001]).values.tolist() == [0.1, 0.001]
    assert np.array_equal(record("ManipulationPD", np.zeros(layouts.MANIP_RECORD.size + 6)).values,
                          np.zeros(layouts.MANIP_RECORD.size + 6))  # open-ended: waypoints follow
