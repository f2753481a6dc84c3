"""FMU variables grouped into ports, on stand-ins for fmpy's variables (through real FMUs:
test_block and test_conformance)."""

from __future__ import annotations

from types import SimpleNamespace as V

import pytest

from blocks.fmu.ports import group_variables


def test_grouping_rules():
    def var(name, vr, type="Real"):
        return V(name=name, valueReference=vr, type=type, dimensions=[], shape=())

    ports = group_variables([var("A[2,1]", 3), var("A[1,1]", 1), var("A[1,2]", 2), var("A[2,2]", 4),
                             var("body.v", 5), var("q[1]", 7), var("q[2]", 6)], "output", "F", 2)
    assert {n: (p.width, p.vrs) for n, p in ports.items()} == {
        "A": (4, [1, 2, 3, 4]), "body_v": (1, [5]), "q": (2, [7, 6])}
    assert ports["A"].labels == ["1,1", "1,2", "2,1", "2,2"] and ports["q"].labels == ["1", "2"]
    assert ports["body_v"].labels is None
    with pytest.raises(ValueError, match="'x' is both a variable and the vector"):
        group_variables([var("x", 1), var("x[1]", 2)], "input", "F", 2)
    with pytest.raises(ValueError, match=r"'a.b' and 'a_b' both map to the port name 'a_b'"):
        group_variables([var("a.b", 1), var("a_b", 2)], "input", "F", 2)
    with pytest.raises(ValueError, match="indices must start at 1"):
        group_variables([var("x[0]", 1), var("x[1]", 2)], "input", "F", 2)


def test_vector_ports_take_the_units_of_their_scalars():
    def var(name, vr, unit=None, declared=None):
        return V(name=name, valueReference=vr, type="Real", dimensions=[], shape=(), unit=unit,
                 declaredType=None if declared is None else V(unit=declared))

    ports = group_variables([var("p[1]", 1, "m"), var("p[2]", 2, declared="m"),  # own unit or its type's
                             var("pose[1]", 3, "m"), var("pose[2]", 4, "rad"), var("pose[3]", 5),
                             var("n[1]", 6), var("n[2]", 7), var("s", 8, declared="s")], "output", "F", 2)
    assert ports["p"].units == "m"
    assert ports["pose"].units == ["m", "rad", ""]  # "" where a scalar declares none
    assert ports["n"].units is None and ports["s"].units == "s"
