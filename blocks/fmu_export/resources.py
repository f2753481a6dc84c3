"""``resources/diagram.bin``: everything an exported FMU knows of its diagram, for its binary.

The layout is ``BLK_EXPORT_RESOURCE``'s in ``blocks/csrc/export_instance.h``: little-endian
int64 words (doubles as their IEEE 754 bits, exact), the op table as ``OpTable.pack``
writes it, the blocks' records and initial states, the variables' offsets, the tunables'
slots, the follow and link rules, and a checksum of it all. The binary reads and checks it when it is
instantiated, so one compiled library serves every diagram whose kinds it holds.
"""

from __future__ import annotations

import sys
import zlib

import numpy as np

from blocks.engine.compiled import native
from .plan import Plan
from .variables import Variables


class _Words:
    def __init__(self):
        self.parts: list[bytes] = []

    def int(self, *values: int) -> None:
        self.parts.append(np.array(values, dtype="<i8").tobytes())

    def doubles(self, values) -> None:
        array = np.ascontiguousarray(values, dtype="<f8").ravel()
        self.int(array.size)
        self.parts.append(array.tobytes())

    def counted(self, values) -> None:
        array = np.asarray(values, dtype="<i8").ravel()
        self.int(array.size)
        self.parts.append(array.tobytes())

    def string(self, text: str) -> None:
        data = text.encode()
        self.int(len(data))
        self.parts.append(data + b"\0" * (-len(data) % 8))

    def bytes(self) -> bytes:
        return b"".join(self.parts)


def resource_file(plan: Plan, variables: Variables, token: str, model: str) -> bytes:
    """The resource file's bytes."""
    if sys.byteorder != "little":
        raise RuntimeError("exported FMUs are written on little-endian hosts only")
    magic, version = native().EXPORT_FORMAT
    w = _Words()
    w.int(magic, version)
    w.string(token)
    w.string(model)
    w.int(plan.grid, variables.vr_input, variables.vr_output, variables.vr_param, plan.initial_outputs,
          plan.between, plan.lazy)
    packed = plan.table.pack()
    w.int(len(packed) // 8)
    w.parts.append(packed)
    w.int(len(plan.blocks))
    for b in plan.blocks:
        w.string(b.name)
        w.string(b.record.kind)
        w.doubles(b.record.values)
        w.int(int(b.built_state))
        w.doubles(b.state)
    w.int(len(variables.inputs))
    for v in variables.inputs:
        w.parts.append(np.array([v.start], dtype="<f8").tobytes())
        w.counted(v.offsets)
    w.counted([v.offsets[0] for v in variables.outputs])
    w.int(len(variables.parameters))
    for p in variables.parameters:
        w.int(p.block, p.slot, int(p.finite))
        w.string(p.name)
    w.int(len(variables.follows))
    for f in variables.follows:
        w.int(f.block, f.slot)
        w.counted(f.when)
        w.counted(f.unless)
    w.int(len(variables.links))
    for link in variables.links:
        w.int(link.block, link.slot, link.source, link.source_slot, link.length)
    w.int(magic)
    data = w.bytes()
    return data + np.array([zlib.crc32(data)], dtype="<i8").tobytes()  # the checksum the binary checks first
