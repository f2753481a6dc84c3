"""The step-size annotations of libcosim and OMSimulator, read and written in one place.

libcosim (Open Simulation Platform) reads, in annotations of type
``com.opensimulationplatform``, a component's ``<osp:StepSizeHint value=.../>`` and, on the
``ssd:DefaultExperiment``, ``<osp:Algorithm><osp:FixedStepAlgorithm baseStepSize=.../>``;
a component without a hint steps at the base step, one with a hint every
``ceil(hint / base)`` base steps. OMSimulator reads, in an annotation of type
``org.openmodelica`` on an ``ssd:System``, ``<oms:Annotations><oms:SimulationInformation>
<oms:FixedStepMaster stepSize=.../>``: the step of every component of that system (older
files leave out the ``oms:Annotations`` level, or the prefix).

blocks itself reads and writes, in an annotation of type ``org.hierhand.blocks``, a
component's ``<blocks:Stepping feedthrough="true"/>``: the importer reads the component's
outputs at a communication point after setting that point's inputs (the FMU block's
``feedthrough``), as the diagram it was exported from evaluates it; other tools step it
as they do every FMU (libcosim: on the inputs of the previous communication point).
OMSimulator refuses any ``ssd:Annotations`` inside an ``ssd:Component`` (the schema allows
them), so the writer can put blocks' stepping on the system instead: in a
``<blocks:Components>`` (an annotation holds one element), one ``<blocks:Stepping
component="name" stepSize="..." feedthrough="true"/>`` per component
(``add_system_stepping``), which ``step_hint`` and ``feedthrough`` read as the component's own.
"""

from __future__ import annotations

import math
from fractions import Fraction
from typing import Any

from .xml import BLOCKS_ANNOTATION, OMS_ANNOTATION, OSP_ANNOTATION, annotations, child, children, local, q

ANNOTATIONS = {
    "system": "each component's step and feedthrough as blocks:Stepping on the system, where OMSimulator takes them",
    "components": "libcosim's osp:StepSizeHint and blocks:Stepping in each component (OMSimulator refuses them)",
    "none": "no tool-specific annotations (each tool steps every component at the step it is given; "
            "OMSimulator refuses the file)",
}
"""Where the tool-specific annotations go (``export_ssp``'s ``annotations``)."""

Step = tuple[str, int | None]
"""A step as written (its text) and the line it is written at."""


def step_hint(component: Any) -> Step | None:
    """A component's ``osp:StepSizeHint``, else the stepSize of its ``blocks:Stepping`` on
    its system."""
    for content in annotations(component, OSP_ANNOTATION):
        if content.tag == q("osp", "StepSizeHint") and content.get("value") is not None:
            return content.get("value"), content.sourceline
    stepping = _system_stepping(component)
    if stepping is not None and stepping.get("stepSize") is not None:
        return stepping.get("stepSize"), stepping.sourceline
    return None


def base_step(experiment: Any) -> Step | None:
    """The ``osp:FixedStepAlgorithm`` baseStepSize of an ``ssd:DefaultExperiment``."""
    for content in annotations(experiment, OSP_ANNOTATION):
        algorithm = child(content, "osp", "FixedStepAlgorithm") if content.tag == q("osp", "Algorithm") else None
        if algorithm is not None and algorithm.get("baseStepSize") is not None:
            return algorithm.get("baseStepSize"), algorithm.sourceline
    return None


def system_step(system: Any) -> Step | None:
    """The ``FixedStepMaster`` stepSize of a system's OMSimulator annotation."""
    for content in annotations(system, OMS_ANNOTATION):
        for element in content.iter():
            if isinstance(element.tag, str) and local(element) == "FixedStepMaster" and element.get("stepSize"):
                return element.get("stepSize"), element.sourceline
    return None


def feedthrough(component: Any) -> bool:
    """Whether a component's ``blocks:Stepping`` (its own, or its system's for it) asks
    for feedthrough."""
    own = [c for c in annotations(component, BLOCKS_ANNOTATION) if c.tag == q("blocks", "Stepping")]
    stepping = own + [s for s in [_system_stepping(component)] if s is not None]
    return any(s.get("feedthrough") in ("true", "1") for s in stepping)


def _system_stepping(component: Any) -> Any:
    """The ``blocks:Stepping`` for ``component`` (by name) on its enclosing system."""
    holder = component.getparent()
    system = holder.getparent() if holder is not None else None
    if system is None:
        return None
    for content in annotations(system, BLOCKS_ANNOTATION):
        for stepping in children(content, "blocks", "Stepping") if content.tag == q("blocks", "Components") else ():
            if stepping.get("component") == component.get("name"):
                return stepping
    return None


def libcosim_period(hint: Fraction, base: Fraction) -> Fraction:
    """The period libcosim runs a component of step-size hint ``hint`` at, on base step ``base``."""
    return base * max(1, math.ceil(hint / base))


def number(value: Fraction) -> str:
    """A duration in seconds as the shortest decimal text that reads back as the same
    double (what an ``xs:double`` attribute holds)."""
    return repr(float(value))


def add_step_hint(component: Any, period: Fraction) -> None:
    """Write a component's ``osp:StepSizeHint``."""
    _annotation(component, OSP_ANNOTATION).append(_make("osp", "StepSizeHint", value=number(period)))


def add_feedthrough(component: Any) -> None:
    """Write a component's ``blocks:Stepping feedthrough="true"``."""
    _annotation(component, BLOCKS_ANNOTATION).append(_make("blocks", "Stepping", feedthrough="true"))


def add_system_stepping(system: Any, name: str, period: Fraction, feedthrough_: bool) -> None:
    """Write, on ``system``, the ``blocks:Stepping`` of its component ``name``."""
    attributes = {"component": name, "stepSize": number(period)}
    if feedthrough_:
        attributes["feedthrough"] = "true"
    annotation = _annotation(system, BLOCKS_ANNOTATION, reuse=True)
    if not len(annotation):
        annotation.append(_make("blocks", "Components"))
    annotation[0].append(_make("blocks", "Stepping", **attributes))


def add_base_step(experiment: Any, step: Fraction) -> None:
    """Write the ``osp:FixedStepAlgorithm`` of an ``ssd:DefaultExperiment``."""
    algorithm = _make("osp", "Algorithm")
    algorithm.append(_make("osp", "FixedStepAlgorithm", baseStepSize=number(step)))
    _annotation(experiment, OSP_ANNOTATION).append(algorithm)


def add_system_step(system: Any, step: Fraction) -> None:
    """Write a system's OMSimulator ``FixedStepMaster``."""
    wrapper = _make("oms", "Annotations")
    info = _make("oms", "SimulationInformation")
    info.append(_make("oms", "FixedStepMaster", description="oms-ma", stepSize=number(step)))
    wrapper.append(info)
    _annotation(system, OMS_ANNOTATION).append(wrapper)


def _make(prefix: str, name: str, **attributes: str) -> Any:
    from lxml import etree

    element = etree.Element(q(prefix, name))
    for key, value in attributes.items():
        element.set(key, value)
    return element


def _annotation(element: Any, kind: str, reuse: bool = False) -> Any:
    """A new ``ssc:Annotation`` of type ``kind`` in ``element``'s ``ssd:Annotations`` (made
    where the schema puts it: after the element's other children that precede it);
    ``reuse``: the one of that type already there, if any."""
    from lxml import etree

    holder = child(element, "ssd", "Annotations")
    if holder is None:
        holder = etree.SubElement(element, q("ssd", "Annotations"))
    if reuse:
        for found in children(holder, "ssc", "Annotation"):
            if found.get("type") == kind:
                return found
    annotation = etree.SubElement(holder, q("ssc", "Annotation"))
    annotation.set("type", kind)
    return annotation
