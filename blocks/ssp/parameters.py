"""An SSD's parameter bindings: values inline or in ``.ssv`` files, renamed and scaled by
``ssm:ParameterMapping``, each with the file and line it was written at.

A binding (``ssd:ParameterBinding``) gives a parameter set (``ssv:ParameterSet``: inline in
``ssd:ParameterValues``, or the ``.ssv`` file its ``source`` names), optionally a mapping
(inline ``ssm:ParameterMapping`` or an ``.ssm`` file) and a ``prefix`` put before every
name. A mapping entry maps the set's parameter ``source`` to the name ``target``, through
its ``ssc:LinearTransformation`` if it has one; parameters no entry names keep their
names. Values are Real / Float as float, integers as int, Boolean as bool, String as str.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
import math
from typing import Any, Callable

from .package import Package, PackageError
from .xml import XmlError, child, children, elements, local, q, shown

FLOATS = ("Real", "Float64", "Float32")
INTEGERS = ("Integer", "Int8", "UInt8", "Int16", "UInt16", "Int32", "UInt32", "Int64", "UInt64")
PARAMETER_SET_TYPE = "application/x-ssp-parameter-set"
MAPPING_TYPE = "application/x-ssp-parameter-mapping"


@dataclass(frozen=True)
class Value:
    """A parameter's value as a binding gives it, and where it is written."""

    name: str
    value: Any
    file: str
    line: int | None


class BindingError(ValueError):
    """A binding that cannot be read: where (file, line) and what."""

    def __init__(self, file: str, line: int | None, message: str, hint: str = ""):
        super().__init__(message)
        self.file, self.line, self.hint = file, line, hint


Reader = Callable[[Path], tuple[Any, str]]
"""Reads an XML file of the package: its root element and its text (kept for the hash)."""


def binding_values(package: Package, ssd_file: str, bindings: Any, read: Reader) -> list[Value]:
    """Every value the ``ssd:ParameterBindings`` element ``bindings`` gives, in order (a
    later binding of a name wins); BindingError for one that cannot be read."""
    values: list[Value] = []
    for binding in children(bindings, "ssd", "ParameterBinding"):
        line = binding.sourceline
        kind = binding.get("type", PARAMETER_SET_TYPE)
        if kind != PARAMETER_SET_TYPE:
            raise BindingError(ssd_file, line, f"ssd:ParameterBinding of type '{kind}' is not supported",
                               f"parameter sets of type {PARAMETER_SET_TYPE} (.ssv) are")
        if binding.get("sourceBase", "SSD") != "SSD":
            raise BindingError(ssd_file, line, "ssd:ParameterBinding with sourceBase='component' is not supported",
                               "put the .ssv file into the SSP and name it relative to the SSD")
        prefix = binding.get("prefix", "")
        source = binding.get("source")
        inline = child(binding, "ssd", "ParameterValues")
        if source is not None:
            file, root = _read(package, ssd_file, line, source, read)
            given = _parameter_set(root, file)
        elif inline is not None:
            found = child(inline, "ssv", "ParameterSet")
            if found is None:
                raise BindingError(ssd_file, inline.sourceline, "ssd:ParameterValues holds no ssv:ParameterSet")
            given = _parameter_set(found, ssd_file)
        else:
            raise BindingError(ssd_file, line, "ssd:ParameterBinding gives neither a 'source' nor ssd:ParameterValues",
                               "source='resources/values.ssv' or an inline ssv:ParameterSet")
        mapping = _mapping(package, ssd_file, child(binding, "ssd", "ParameterMapping"), read)
        for v in given:
            if v.name in mapping:
                target, factor, offset = mapping[v.name]
                value = v.value
                if factor != 1.0 or offset != 0.0:
                    if not isinstance(value, float):
                        raise BindingError(v.file, v.line, f"parameter '{v.name}': a linear transformation maps "
                                           "only Real values")
                    value = factor * value + offset
                v = Value(target, value, v.file, v.line)
            values.append(Value(prefix + v.name, v.value, v.file, v.line))
    return values


def _read(package: Package, ssd_file: str, line: int | None, source: str, read: Reader) -> tuple[str, Any]:
    try:
        path = package.resolve(source)
    except PackageError as exc:
        raise BindingError(ssd_file, line, f"parameter source {exc}") from None
    file = package.where(path)
    try:
        root, _ = read(path)
    except XmlError as exc:
        raise BindingError(file, exc.line, str(exc)) from None
    return file, root


def _parameter_set(root: Any, file: str) -> list[Value]:
    if root.tag != q("ssv", "ParameterSet"):
        raise BindingError(file, root.sourceline, f"expected an ssv:ParameterSet, found <{local(root)}>")
    out = []
    for parameter in children(child(root, "ssv", "Parameters"), "ssv", "Parameter"):
        name = parameter.get("name")
        typed = elements(parameter)
        if not name or not typed:
            raise BindingError(file, parameter.sourceline, "ssv:Parameter needs a name and a typed value",
                               "<ssv:Parameter name='k'><ssv:Real value='2'/></ssv:Parameter>")
        out.append(Value(name, _value(typed[0], name, file), file, parameter.sourceline))
    return out


def _value(element: Any, name: str, file: str) -> Any:
    kind, text = local(element), element.get("value")
    line = element.sourceline
    try:
        if kind in FLOATS and text is not None:
            return finite(text)
        if kind in INTEGERS and text is not None:
            value, (low, high) = _whole(text), integer_range(kind)
            if not low <= value <= high:
                raise BindingError(file, line, f"parameter '{name}': {value} is out of the range of an ssv:{kind} "
                                   f"({low} to {high})")
            return value
        if kind == "Boolean" and text is not None:
            if text.strip() not in ("true", "false", "1", "0"):
                raise ValueError(text)
            return text.strip() in ("true", "1")
        if kind == "String" and text is not None:
            return text
    except BindingError:
        raise
    except ValueError:
        raise BindingError(file, line, f"parameter '{name}': {shown(text)} is not an ssv:{kind} value") from None
    raise BindingError(file, line, f"parameter '{name}': values of type ssv:{kind} are not supported",
                       "Real, Float64, Float32, Integer and IntN, Boolean and String values are")


def _whole(text: str) -> int:
    """A whole number of at most 24 characters (an Int64 has 20); ValueError otherwise."""
    if len(text.strip()) > 24:
        raise ValueError(text)
    return int(text.strip())


def integer_range(kind: str) -> tuple[int, int]:
    """The values an ``ssv`` integer type holds (``Integer`` is 32 bits, as in FMI)."""
    bits = 32 if kind == "Integer" else int(kind.removeprefix("U").removeprefix("Int"))
    return (0, 2**bits - 1) if kind.startswith("U") else (-2 ** (bits - 1), 2 ** (bits - 1) - 1)


def finite(text: str) -> float:
    """A real number written in the XML; ValueError for one that is not finite (``INF``,
    ``NaN``, ``1e999``): no parameter, factor or offset is meant to be."""
    value = float(text)
    if not math.isfinite(value):
        raise ValueError(text)
    return value


def _mapping(package: Package, ssd_file: str, element: Any, read: Reader) -> dict[str, tuple[str, float, float]]:
    """source name -> (target name, factor, offset) of an ``ssd:ParameterMapping``."""
    if element is None:
        return {}
    line = element.sourceline
    kind = element.get("type", MAPPING_TYPE)
    if kind != MAPPING_TYPE:
        raise BindingError(ssd_file, line, f"ssd:ParameterMapping of type '{kind}' is not supported",
                           f"mappings of type {MAPPING_TYPE} (.ssm) are")
    if element.get("source") is not None:
        if element.get("sourceBase", "SSD") != "SSD":
            raise BindingError(ssd_file, line, "ssd:ParameterMapping with sourceBase='component' is not supported")
        file, root = _read(package, ssd_file, line, element.get("source"), read)
    else:
        file, root = ssd_file, child(element, "ssm", "ParameterMapping")
        if root is None:
            raise BindingError(ssd_file, line, "ssd:ParameterMapping has neither a 'source' nor an inline "
                               "ssm:ParameterMapping")
    if root.tag != q("ssm", "ParameterMapping"):
        raise BindingError(file, root.sourceline, f"expected an ssm:ParameterMapping, found <{local(root)}>")
    out = {}
    for entry in children(root, "ssm", "MappingEntry"):
        factor, offset = 1.0, 0.0
        for transformation in elements(entry):
            what = local(transformation)
            if what == "Annotations":
                continue
            if what != "LinearTransformation":
                raise BindingError(file, transformation.sourceline, f"ssc:{what} in a parameter mapping is not "
                                   "supported", "ssc:LinearTransformation is")
            try:
                factor = finite(transformation.get("factor", "1"))
                offset = finite(transformation.get("offset", "0"))
            except ValueError:
                raise BindingError(file, transformation.sourceline, "ssc:LinearTransformation: factor and offset "
                                   "must be numbers") from None
        source, target = entry.get("source"), entry.get("target")
        if not source or not target:
            raise BindingError(file, entry.sourceline, "ssm:MappingEntry needs 'source' and 'target'")
        out[source] = (target, factor, offset)
    return out
