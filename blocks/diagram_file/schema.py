"""The diagram file's JSON Schema, generated from the registered block types.

Editors read it (VS Code's YAML support, any yaml-language-server, through a first line
``# yaml-language-server: $schema=diagram.schema.json``) to complete block types and their
parameters and to flag a misspelt key, an unknown type or a value of the wrong kind while
the file is written. The loader stays the judge: the schema never refuses what the loader
accepts, so it says only what holds whatever else the file says. It knows the file's keys
(the reader's key lists; a test holds the two together), every registered type's parameters with the JSON types their
documented types allow (``SCHEMA_TYPES``) and their descriptions (units included, as the
blocks document them), and each type's ports in its description; it cannot check that a
connection names ports that exist, which depend on the other blocks and on parameters.
"""

from __future__ import annotations

import ast
import re
from typing import Any, Mapping

from blocks.block import Block
from blocks.registry import PYTHON_PREFIX
from blocks.typeinfo import REQUIRED, TypeInfo, port_details, type_info

SCHEMA_FILE = "diagram.schema.json"
"""The schema's file name beside the shipped diagrams, which their first line names."""
SCHEMA_LINE = f"# yaml-language-server: $schema={SCHEMA_FILE}"
"""The first line of a shipped diagram: where editors find the schema."""

NUMBER = {"type": "number"}
NUMBERS = {"type": "array", "items": NUMBER}
ANY_ARRAY = {"type": "array"}
DURATION = {"anyOf": [NUMBER, {"type": "string"}], "description": "a duration: seconds, or '0.1 ms', '100 us', ..."}
SCALAR_OR_VECTOR = {"anyOf": [NUMBER, NUMBERS]}

SCHEMA_TYPES: dict[str, dict[str, Any]] = {
    "float": NUMBER,
    "int": {"type": "integer"},
    "bool": {"type": "boolean"},
    "str": {"type": "string"},
    "str or path": {"type": "string"},
    "str or int": {"type": ["string", "integer"]},
    "duration": DURATION,
    "mapping": {"type": "object"},
    "scalar or vector": SCALAR_OR_VECTOR,
    "scalar or 9 values": SCALAR_OR_VECTOR,
    "vector": {"anyOf": [NUMBER, ANY_ARRAY]},
    "matrix": {"anyOf": [NUMBER, ANY_ARRAY]},
    "scalar, vector or matrix": {"anyOf": [NUMBER, ANY_ARRAY]},
    "int or list of int": {"anyOf": [{"type": "integer"}, {"type": "array", "items": {"type": "integer"}}]},
}
"""The JSON Schema of each documented parameter type (the numpydoc type text of the blocks'
``Parameters`` sections). Vectors and matrices also take one number, as the blocks do; a
type text ``{'a', 'b'}`` is that set of values; ``list of ...`` is an array; any other text
says nothing (the loader checks it)."""

_SET = re.compile(r"^\{.*\}$")


def parameter_schema(type_text: str, default: Any) -> dict[str, Any]:
    """The schema of one parameter's value from its documented type; ``null`` is allowed
    where the default is None (the block then takes its default)."""
    text = type_text.strip()
    schema: dict[str, Any] = dict(SCHEMA_TYPES.get(text, {}))
    if not schema and _SET.match(text):
        try:
            values = sorted(ast.literal_eval(text), key=repr)
        except (ValueError, SyntaxError, TypeError):
            values = None
        if values is not None:
            schema = {"enum": values}
    elif not schema and text.startswith("list of"):
        schema = {"type": "array"}
    if default is None and schema and "enum" not in schema:
        schema = {"anyOf": [schema, {"type": "null"}]}
    return schema


def type_schema(info: TypeInfo) -> dict[str, Any]:
    """The schema of a block entry's ``params`` for one type: each parameter with its type
    and description; no other key unless the block takes any (``**kwargs``)."""
    properties = {}
    for p in info.parameters:
        schema = {"type": "string", "description": "the name of another block of the diagram"} \
            if p.block_reference else parameter_schema(p.type, p.default)
        described = [p.text] if p.text else []
        if p.default is not REQUIRED:
            described.append(f"default: {p.default!r}")
        if described:
            schema = {**schema, "description": "; ".join(described)}
        properties[p.name] = schema
    schema: dict[str, Any] = {"type": "object", "properties": properties}
    if not info.any_parameter:
        schema["additionalProperties"] = False
    return schema


def _ports_text(info: TypeInfo) -> str:
    if info.inputs is None:
        return f"ports: {info.ports_note}"

    def ports(items) -> str:
        return ", ".join(f"{p.name}[{'n' if p.width is None else p.width}]"
                         + (f" ({port_details(p)})" if port_details(p) else "") for p in items) or "none"

    return f"inputs: {ports(info.inputs)}; outputs: {ports(info.outputs)}; feedthrough: {info.feedthrough}"


def diagram_schema(types: Mapping[str, type[Block]] | None = None) -> dict[str, Any]:
    """The JSON Schema (draft 2020-12) of a diagram file whose blocks are of ``types``
    (default: every registered type)."""
    if types is None:
        from blocks.registry import block_types

        types = block_types()
    infos = [type_info(cls) for _, cls in sorted(types.items())]
    names = [i.name for i in infos]
    signal = {"type": "string", "description": "block.port, or some of its elements: block.port[1], "
                                               "block.port[0:3], block.port[label]"}
    units = {"anyOf": [{"type": "string"}, {"type": "array", "items": {"type": "string"}}],
             "description": "one unit ('rad', 'N m', '1'), or one per element"}
    labels = {"type": "array", "items": {"type": ["string", "number"]}, "description": "one name per element"}
    by_port = {"units": {"type": "object", "additionalProperties": {"$ref": "#/$defs/units"}},
               "elements": {"type": "object", "additionalProperties": {"$ref": "#/$defs/labels"}}}
    block_properties = {
        "type": {"anyOf": [{"enum": names}, {"type": "string", "pattern": f"^{PYTHON_PREFIX}"}],
                 "description": "a registered block type ('hierhand blocks' lists them), or "
                                "python:module:Class with --trust"},
        "period": DURATION, "offset": DURATION,
        "params": {"type": "object"},
        "params_file": {"type": "string", "description": "a YAML file of parameters, relative to the diagram"},
        "description": {"type": "string"},
        **by_port,
    }
    block = {"type": "object", "required": ["type"], "additionalProperties": False, "properties": block_properties,
             "allOf": [{"if": {"properties": {"type": {"const": i.name}}, "required": ["type"]},
                        "then": {"properties": {"params": {"$ref": f"#/$defs/params/{i.name}"}},
                                 "description": " ".join(filter(None, [i.summary, _ports_text(i)]))}}
                       for i in infos]}
    subsystem_properties = {
        "diagram": {"type": "string", "description": "another diagram file, relative to this one"},
        "params": {"type": "object", "description": "its blocks' parameters by dotted path, e.g. prop.k"},
        "bind": {"type": "object", "additionalProperties": {"type": "string"},
                 "description": "its references, each bound to a block of this diagram"},
        "description": {"type": "string"},
    }
    subsystem = {"type": "object", "required": ["diagram"], "additionalProperties": False,
                 "properties": subsystem_properties}
    connection = {"type": "object", "required": ["from", "to"], "additionalProperties": False,
                  "properties": {"from": signal, "to": signal, "delay": {"enum": [0, 1]}, "initial": {}}}
    log_entry = {"type": "object", "required": ["signal"], "additionalProperties": False,
                 "properties": {"signal": signal, "decimate": {"type": "integer", "minimum": 1}}}
    time = {"type": "object", "additionalProperties": False, "properties": {"t_end": DURATION}}
    top = {
        "version": {"const": 1},
        "name": {"type": "string"},
        "description": {"type": "string"},
        "time": time,
        "blocks": {"type": "object", "minProperties": 1,
                   "additionalProperties": {"if": {"type": "object", "required": ["diagram"]},
                                            "then": {"$ref": "#/$defs/subsystem"},
                                            "else": {"$ref": "#/$defs/block"}}},
        "connections": {"type": "array", "items": {"anyOf": [
            {"type": "string", "pattern": "->", "description": "src.port -> dst.port"},
            {"$ref": "#/$defs/connection"}]}},
        "inputs": {"type": "object", "additionalProperties": {
            "anyOf": [{"type": "string"}, {"type": "array", "items": {"type": "string"}}]}},
        "outputs": {"type": "object", "additionalProperties": {"type": "string"}},
        "references": {"anyOf": [{"type": "array", "items": {"type": "string"}},
                                 {"type": "object", "additionalProperties": {"type": "string"}}]},
        "log": {"anyOf": [{"const": "all"}, {"type": "array", "items": {
            "anyOf": [{"type": "string"}, {"$ref": "#/$defs/log_entry"}]}}]},
        **by_port,
    }
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": "blocks diagram file",
        "description": "A multirate block diagram (generated from the registered block types by "
                       "'hierhand schema'; the loader's checks go further).",
        "type": "object",
        "required": ["blocks"],
        "additionalProperties": False,
        "properties": top,
        "$defs": {"block": block, "subsystem": subsystem, "connection": connection, "log_entry": log_entry,
                  "units": units, "labels": labels,
                  "params": {i.name: type_schema(i) for i in infos}},
    }
