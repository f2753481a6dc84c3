"""Units in an exported SSD: the definitions of the connectors' units, taken from the FMUs.

A connector's ``ssc:Real unit`` names a unit that the SSD's ``ssd:Units`` defines by its
exponents of the SI base units, factor and offset (``ssc:BaseUnit``), the same attributes
as an FMU's ``UnitDefinitions`` (FMI 2 and 3); so the definitions are copied from the
FMUs the components are, and a unit an FMU does not define is left off its connectors.
"""

from __future__ import annotations

import zipfile
from pathlib import Path
from typing import Any

from .. import units
from .xml import MAX_XML_BYTES, local, q

BASE_ATTRIBUTES = (*units.BASE_ATTRIBUTES.values(), "factor", "offset")
"""The attributes of an ``ssc:BaseUnit``, as of an FMU's ``BaseUnit``."""


def unit_definitions(fmu: str | Path) -> dict[str, dict[str, str]]:
    """The units ``fmu``'s modelDescription defines: name -> its BaseUnit's attributes."""
    from lxml import etree

    with zipfile.ZipFile(fmu) as archive:
        info = archive.getinfo("modelDescription.xml")
        if info.file_size > MAX_XML_BYTES:
            return {}
        data = archive.read(info)
    parser = etree.XMLParser(resolve_entities=False, no_network=True, load_dtd=False)
    root = etree.fromstring(data, parser)
    found = {}
    for holder in root:
        if isinstance(holder.tag, str) and local(holder) == "UnitDefinitions":
            for unit in holder:
                if not isinstance(unit.tag, str) or local(unit) != "Unit" or not unit.get("name"):
                    continue
                base = next((e for e in unit if isinstance(e.tag, str) and local(e) == "BaseUnit"), None)
                attributes = {} if base is None else {k: v for k, v in base.attrib.items() if k in BASE_ATTRIBUTES}
                found[unit.get("name")] = attributes
    return found


def add_units(root: Any, units: dict[str, dict[str, str]]) -> None:
    """Write ``ssd:Units`` (``ssc:Unit`` each with its ``ssc:BaseUnit``) into the SSD's root."""
    from lxml import etree

    holder = etree.SubElement(root, q("ssd", "Units"))
    for name in sorted(units):
        unit = etree.SubElement(holder, q("ssc", "Unit"))
        unit.set("name", name)
        base = etree.SubElement(unit, q("ssc", "BaseUnit"))
        for key in BASE_ATTRIBUTES:
            if key in units[name]:
                base.set(key, units[name][key])
