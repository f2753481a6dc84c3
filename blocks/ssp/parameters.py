"""An SSD's parameter bindings: values inline or in ``.ssv`` files, renamed and scaled by
``ssm:ParameterMapping``, each with the file and line it was written at.

A binding (``ssd:ParameterBinding``) gives a parameter set (``ssv:ParameterSet``: inline in
``ssd:ParameterValues``, or the ``.ssv`` file its ``source`` names), optionally a mapping
(inline ``ssm:ParameterMapping`` or an ``.ssm`` file) and a ``prefix``. As SSP 1.0 says
(5.2.3), the prefix is put before every name of the set first, and the mapping then
applies to the prefixed names: an entry maps the parameter ``source`` to the name
``target`` (one source may go to several targets, two sources never to one), and a
parameter no entry names is not applied. Values are Real / Float as float, integers as
int, Boolean as bool, String as str, Enumeration as its item's name (``Value.enumeration``). A Real value may carry a unit (defined in the set's
``ssv:Units``, or by name); ``value`` converts it into the unit of the parameter it lands
on and then applies the entry's ``ssc:LinearTransformation`` (SSP 1.0, 7.1.1: the
transformation after the unit conversion, or instead of it with
``suppressUnitConversion``).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Callable

from .conversion import Definitions, UnitError, conversion, definition, read_definitions
from .package import Package, PackageError
from .xml import XmlError, child, children, elements, finite, local, q, shown, whole

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
    unit: str | None = None
    """The unit the value is written in (``ssv:Real unit``), if any."""
    units: Definitions = field(default_factory=dict, compare=False)
    """The unit definitions of the file it is written in (its set's ``ssv:Units``)."""
    transform: tuple[float, float] | None = None
    """The (factor, offset) of its mapping entry's linear transformation, if any."""
    convert: bool = True
    """False where its mapping entry suppresses the unit conversion."""
    enumeration: bool = False
    """An ``ssv:Enumeration`` value: ``value`` the item's name, which its FMU variable's type numbers."""

    def value_in(self, unit: str | None, *tables: Definitions) -> Any:
        """The value for a parameter of unit ``unit`` (None: it declares none): converted
        from the unit it is written in (definitions: the set's, then ``tables``), then
        transformed by its mapping entry; BindingError where it cannot be converted."""
        value = self.value
        if self.unit and self.convert and isinstance(value, float) and not self._dimensionless():
            if not unit:
                raise BindingError(self.file, self.line, f"parameter '{self.name}' is given in '{self.unit}', but "
                                   "the parameter declares no unit to convert it into",
                                   "leave out the value's unit to set it as it is, or declare the parameter's unit "
                                   "(its FMU variable's, or a kind='parameter' connector's ssc:Real unit)")
            try:
                factor, offset = conversion(self.unit, unit, self.units, *tables)
            except UnitError as exc:
                raise BindingError(self.file, self.line, f"parameter '{self.name}' = {value!r} {self.unit} cannot be "
                                   f"set in the parameter's unit '{unit}': {exc}",
                                   "give the value in the parameter's unit, define both units (ssc:Unit), or set "
                                   "suppressUnitConversion on a mapping entry") from None
            value = factor * value + offset
        if self.transform is not None:
            value = self.transform[0] * value + self.transform[1]
        return value

    def _dimensionless(self) -> bool:
        found = definition(self.unit, self.units)
        return found is not None and not found.exponents and found.factor == 1.0 and found.offset == 0.0


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
            v = replace(v, name=prefix + v.name)
            if mapping is None:
                values.append(v)
                continue
            for target, transform, convert in mapping.get(v.name, ()):
                if transform is not None and not isinstance(v.value, float):
                    raise BindingError(v.file, v.line, f"parameter '{v.name}': a linear transformation maps "
                                       "only Real values")
                values.append(replace(v, name=target, transform=transform, convert=convert))
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
    try:
        units = read_definitions(child(root, "ssv", "Units"))
    except UnitError as exc:
        raise BindingError(file, exc.line, str(exc)) from None
    out = []
    for parameter in children(child(root, "ssv", "Parameters"), "ssv", "Parameter"):
        name = parameter.get("name")
        typed = [e for e in elements(parameter) if local(e) != "Annotations"]
        if not name or not typed:
            raise BindingError(file, parameter.sourceline, "ssv:Parameter needs a name and a typed value",
                               "<ssv:Parameter name='k'><ssv:Real value='2'/></ssv:Parameter>")
        out.append(Value(name, _value(typed[0], name, file), file, parameter.sourceline, typed[0].get("unit") or None,
                         units, enumeration=local(typed[0]) == "Enumeration"))
    return out


def _value(element: Any, name: str, file: str) -> Any:
    kind, text = local(element), element.get("value")
    line = element.sourceline
    try:
        if kind in FLOATS and text is not None:
            return finite(text)
        if kind in INTEGERS and text is not None:
            value, (low, high) = whole(text), integer_range(kind)
            if not low <= value <= high:
                raise BindingError(file, line, f"parameter '{name}': {value} is out of the range of an ssv:{kind} "
                                   f"({low} to {high})")
            return value
        if kind == "Boolean" and text is not None:
            if text.strip() not in ("true", "false", "1", "0"):
                raise ValueError(text)
            return text.strip() in ("true", "1")
        if kind in ("String", "Enumeration") and text is not None:
            return text
    except BindingError:
        raise
    except ValueError:
        raise BindingError(file, line, f"parameter '{name}': {shown(text)} is not an ssv:{kind} value") from None
    raise BindingError(file, line, f"parameter '{name}': values of type ssv:{kind} are not supported",
                       "Real, Float64, Float32, Integer and IntN, Boolean, String and Enumeration values are")


def integer_range(kind: str) -> tuple[int, int]:
    """The values an ``ssv`` integer type holds (``Integer`` is 32 bits, as in FMI)."""
    bits = 32 if kind == "Integer" else int(kind.removeprefix("U").removeprefix("Int"))
    return (0, 2**bits - 1) if kind.startswith("U") else (-2 ** (bits - 1), 2 ** (bits - 1) - 1)


Entry = tuple[str, "tuple[float, float] | None", bool]
"""A mapping entry: its target, its linear transformation's (factor, offset), whether it converts units."""


def _mapping(package: Package, ssd_file: str, element: Any, read: Reader) -> dict[str, list[Entry]] | None:
    """source name -> its entries, of an ``ssd:ParameterMapping`` (None: the binding has none)."""
    if element is None:
        return None
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
    out: dict[str, list[Entry]] = {}
    targets: set[str] = set()
    for entry in children(root, "ssm", "MappingEntry"):
        transform = None
        for transformation in elements(entry):
            what = local(transformation)
            if what == "Annotations":
                continue
            if what != "LinearTransformation":
                raise BindingError(file, transformation.sourceline, f"ssc:{what} in a parameter mapping is not "
                                   "supported", "ssc:LinearTransformation is")
            try:
                transform = finite(transformation.get("factor", "1")), finite(transformation.get("offset", "0"))
            except ValueError:
                raise BindingError(file, transformation.sourceline, "ssc:LinearTransformation: factor and offset "
                                   "must be numbers") from None
        source, target = entry.get("source"), entry.get("target")
        if source == "" and target:
            continue  # an entry of no source maps nothing (OMSimulator writes them for unmapped targets)
        if not source or not target:
            raise BindingError(file, entry.sourceline, "ssm:MappingEntry needs 'source' and 'target'")
        if target in targets:
            raise BindingError(file, entry.sourceline, f"ssm:MappingEntry: two entries map to '{target}'",
                               "a parameter mapping maps one source to each target (SSP 1.0, 7.1)")
        targets.add(target)
        convert = entry.get("suppressUnitConversion") not in ("true", "1")
        out.setdefault(source, []).append((target, transform, convert))
    return out
