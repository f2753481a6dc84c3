"""The step-size annotations of libcosim and OMSimulator, read and written in one place.

libcosim (Open Simulation Platform) reads, in annotations of type
``com.opensimulationplatform``, a component's ``<osp:StepSizeHint value=.../>`` and, on the
``ssd:DefaultExperiment``, ``<osp:Algorithm><osp:FixedStepAlgorithm baseStepSize=.../>``;
a component without a hint steps at the base step, one with a hint every
``ceil(hint / base)`` base steps. OMSimulator reads, in an annotation of type
``org.openmodelica`` on an ``ssd:System``, ``<oms:Annotations><oms:SimulationInformation>
<oms:FixedStepMaster stepSize=.../>``: the step of every component of that system (older
files leave out the ``oms:Annotations`` level, or the prefix).
"""

from __future__ import annotations

import math
from fractions import Fraction
from typing import Any

from .xml import OMS_ANNOTATION, OSP_ANNOTATION, annotations, child, local, q

Step = tuple[str, int | None]
"""A step as written (its text) and the line it is written at."""


def step_hint(component: Any) -> Step | None:
    """A component's ``osp:StepSizeHint``."""
    for content in annotations(component, OSP_ANNOTATION):
        if content.tag == q("osp", "StepSizeHint") and content.get("value") is not None:
            return content.get("value"), content.sourceline
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


def _annotation(element: Any, kind: str) -> Any:
    """A new ``ssc:Annotation`` of type ``kind`` in ``element``'s ``ssd:Annotations`` (made
    where the schema puts it: after the element's other children that precede it)."""
    from lxml import etree

    holder = child(element, "ssd", "Annotations")
    if holder is None:
        holder = etree.SubElement(element, q("ssd", "Annotations"))
    annotation = etree.SubElement(holder, q("ssc", "Annotation"))
    annotation.set("type", kind)
    return annotation
