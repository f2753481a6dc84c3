"""The diagram file's JSON Schema: the reader's keys, each type's parameters, and the wrong
diagrams that both the loader and the schema refuse."""

from __future__ import annotations

import json

import jsonschema
import pytest
import yaml

import blocks
from blocks.diagram_file import reader
from blocks.diagram_file.schema import diagram_schema, parameter_schema
from blocks.registry import block_types
from blocks.typeinfo import REQUIRED, type_info

SCHEMA = diagram_schema()
VALIDATOR = jsonschema.Draft202012Validator(SCHEMA)

GOOD = """
name: t
time: {t_end: 10 ms}
blocks:
  ref: {type: Constant, params: {value: 1.0}}
  g: {type: Gain, period: 1 ms, params: {k: 2.0}, units: {y: m}}
  s: {type: Sum, params: {signs: "+-"}}
  pid: {type: PID, period: 1 ms, params: {P: 2.0, I: [1.0], form: ideal, lower: -1.0}}
connections:
  - ref.y -> g.u
  - g.y -> s.u0
  - {from: ref.y, to: s.u1, delay: 1, initial: 0.0}
  - s.y -> pid.u
log: [s.y, {signal: pid.y, decimate: 2}]
"""

WRONG = {
    "unknown type": GOOD.replace("type: Gain,", "type: Gian,"),
    "unknown key of a block": GOOD.replace("g: {type: Gain, period: 1 ms", "g: {type: Gain, perod: 1 ms"),
    "unknown top-level key": GOOD.replace("log: [", "logs: ["),
    "unknown key in time": GOOD.replace("t_end: 10 ms", "t_stop: 10 ms"),
    "misspelt parameter": GOOD.replace("params: {k: 2.0}", "params: {kk: 2.0}"),
    "a boolean for a number": GOOD.replace("params: {k: 2.0}", "params: {k: yes}"),
    "a text for a number": GOOD.replace("params: {k: 2.0}", "params: {k: abc}"),
    "a number for a text": GOOD.replace('signs: "+-"', "signs: 3"),
    "a value not among the choices": GOOD.replace("form: ideal", "form: serial"),
    "a delay of 2": GOOD.replace("delay: 1,", "delay: 2,"),
    "a decimation of 0": GOOD.replace("decimate: 2", "decimate: 0"),
    "a list for a period": GOOD.replace("period: 1 ms, params: {k", "period: [1], params: {k"),
}


def schema_errors(text: str) -> list[str]:
    return [e.message for e in VALIDATOR.iter_errors(yaml.safe_load(text))]


def test_the_schema_is_a_valid_json_schema_and_plain_json():
    jsonschema.Draft202012Validator.check_schema(SCHEMA)
    assert json.loads(json.dumps(SCHEMA)) == SCHEMA


def test_the_schema_knows_exactly_the_keys_the_reader_reads():
    defs = SCHEMA["$defs"]
    assert set(SCHEMA["properties"]) == set(reader.TOP_KEYS)
    assert set(SCHEMA["properties"]["time"]["properties"]) == set(reader.TIME_KEYS)
    assert set(defs["block"]["properties"]) == set(reader.BLOCK_KEYS)
    assert set(defs["subsystem"]["properties"]) == set(reader.SUBSYSTEM_KEYS)
    assert set(defs["connection"]["properties"]) == set(reader.CONNECTION_KEYS)
    assert set(defs["log_entry"]["properties"]) == set(reader.LOG_KEYS)


def test_every_registered_type_is_in_the_schema_with_its_parameters():
    types = block_types()
    assert set(SCHEMA["$defs"]["params"]) == set(types)
    for name, cls in types.items():
        assert set(SCHEMA["$defs"]["params"][name]["properties"]) == set(cls.parameters()), name


@pytest.mark.parametrize("name", sorted(block_types()))
def test_each_parameter_schema_admits_the_block_s_own_default(name):
    """The types the schema gives parameters come from their documentation: each must at
    least admit the value the block itself defaults to."""
    for p in type_info(block_types()[name]).parameters:
        if p.default is REQUIRED or p.block_reference:
            continue
        value = json.loads(json.dumps(p.default)) if not isinstance(p.default, tuple) else list(p.default)
        jsonschema.validate(value, parameter_schema(p.type, p.default))


def test_a_good_diagram_loads_and_validates():
    blocks.loads_diagram(GOOD)
    assert schema_errors(GOOD) == []


@pytest.mark.parametrize("case", sorted(WRONG))
def test_a_wrong_diagram_is_refused_by_the_loader_and_by_the_schema(case):
    text = WRONG[case]
    assert text != GOOD
    with pytest.raises(blocks.DiagramError):
        blocks.loads_diagram(text)
    assert schema_errors(text), f"the schema accepts a diagram with {case}"


def test_a_python_type_and_a_subsystem_entry_pass_the_schema():
    data = yaml.safe_load(GOOD)
    data["blocks"]["g"]["type"] = "python:mymod:Twice"
    data["blocks"]["sub"] = {"diagram": "pi.yaml", "params": {"prop.k": 2}, "bind": {"plant": "g"}}
    assert list(VALIDATOR.iter_errors(data)) == []
    data["blocks"]["sub"]["type"] = "Gain"  # a subsystem entry has no type
    assert list(VALIDATOR.iter_errors(data))
