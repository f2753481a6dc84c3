"""SSPs written to the standard by hand, run as diagrams (``blocks.ssp.reader``) against the
equivalent diagrams built in Python; their bad references each one error at its SSD line."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from blocks import DiagramBuilder, DiagramError, load_diagram, simulate
from blocks.ssp import read_ssp

from .conftest import NO_STEP, hint, schema_errors, ssd, variant, write_ssp

FIRST_ORDER = """
<ssd:Connectors>
  <ssd:Connector name="u" kind="input"><ssc:Real/></ssd:Connector>
  <ssd:Connector name="y" kind="output"><ssc:Real/></ssd:Connector>
  <ssd:Connector name="z[1]" kind="output"><ssc:Real/></ssd:Connector>
  <ssd:Connector name="z[2]" kind="output"><ssc:Real/></ssd:Connector>
</ssd:Connectors>"""


def component(name: str, extra: str = "", step: str | None = "0.1", connectors: str = FIRST_ORDER) -> str:
    return (f'<ssd:Component name="{name}" source="resources/fo.fmu">{connectors}{extra}'
            f'{hint(step) if step else ""}</ssd:Component>')


def values(*pairs: tuple[str, str, str]) -> str:
    """An inline parameter binding of (name, type, value)."""
    body = "".join(f'<ssv:Parameter name="{n}"><ssv:{t} value="{v}"/></ssv:Parameter>' for n, t, v in pairs)
    return ('<ssd:ParameterBindings><ssd:ParameterBinding><ssd:ParameterValues><ssv:ParameterSet version="1.0" '
            f'name="values"><ssv:Parameters>{body}</ssv:Parameters></ssv:ParameterSet></ssd:ParameterValues>'
            "</ssd:ParameterBinding></ssd:ParameterBindings>")


def native(fmu, blocks: dict, wires: list, t_end="1 s"):
    """The diagram built in Python: ``blocks`` name -> (type, period, params)."""
    b = DiagramBuilder("native", t_end=t_end)
    for name, (kind, period, params) in blocks.items():
        if kind == "FMU":
            params = {"path": str(fmu), **params}
        b.add(name, kind, period=period, params=params)
    for src, dst in wires:
        b.connect(src, dst)
    b.log_all()
    return b.build()


def same(a, b, signals):
    ra, rb = simulate(a), simulate(b)
    assert ra.status == rb.status == "complete"
    for s in signals:
        np.testing.assert_array_equal(ra[s][0], rb[s][0])
        np.testing.assert_array_equal(ra[s][1], rb[s][1], err_msg=s)


def chain_ssd() -> str:
    """src -> (z[1] * 2 + 0.5) -> sink.u; src -> (y) -> mid.u (an element connector and a
    plain one), with inline values on src and mid."""
    return ssd(f"""
<ssd:Elements>
  {component("src", values(("x0", "Real", "1.0"), ("a", "Real", "0.8"), ("scale", "Integer", "3")))}
  {component("mid", values(("b", "Real", "0.5")))}
  {component("sink")}
</ssd:Elements>
<ssd:Connections>
  <ssd:Connection startElement="src" startConnector="z[1]" endElement="sink" endConnector="u">
    <ssc:LinearTransformation factor="2" offset="0.5"/>
  </ssd:Connection>
  <ssd:Connection startElement="src" startConnector="y" endElement="mid" endConnector="u"/>
</ssd:Connections>""")


def test_components_element_connectors_values_and_a_linear_transformation_run_as_the_native_diagram(
        first_order, tmp_path):
    path = write_ssp(tmp_path / "chain", chain_ssd(), first_order, archive=True)
    fmu = tmp_path / "fo.fmu"
    fmu.write_bytes(first_order)
    want = native(fmu, {
        "src": ("FMU", "100 ms", {"start_values": {"x0": 1.0, "a": 0.8, "scale": 3}}),
        "mid": ("FMU", "100 ms", {"start_values": {"b": 0.5}}),
        "sink": ("FMU", "100 ms", {}),
        "k": ("Gain", None, {"k": 2.0}), "c": ("Bias", None, {"bias": 0.5})},
        [("src.z[1]", "k.u"), ("k.y", "c.u"), ("c.y", "sink.u"), ("src.y", "mid.u")])
    got = load_diagram(path)
    assert got.t_end == 1
    same(got, want, ["src.y", "src.z", "mid.y", "sink.y"])
    sink = simulate(got)["sink.y"][1][:, 0]
    z1 = simulate(got)["src.z"][1][:, 0]
    assert sink[2] == pytest.approx(0.5 * sink[1] + 2 * z1[1] + 0.5)  # x' = a x + b u, b = 1


def test_a_folder_and_its_ssd_file_load_as_the_archive_does(first_order, tmp_path):
    folder = write_ssp(tmp_path / "chain", chain_ssd(), first_order)
    assert schema_errors(folder / "SystemStructure.ssd") == []
    archive = write_ssp(tmp_path / "chain", chain_ssd(), first_order, archive=True)
    same(load_diagram(folder), load_diagram(archive), ["sink.y", "mid.y"])
    same(load_diagram(folder / "SystemStructure.ssd"), load_diagram(archive), ["sink.y"])


SSV = """<?xml version="1.0" encoding="UTF-8"?>
<ssv:ParameterSet version="1.0" name="plant" xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues">
  <ssv:Parameters>
    <ssv:Parameter name="pole"><ssv:Real value="0.9"/></ssv:Parameter>
    <ssv:Parameter name="start"><ssv:Real value="2"/></ssv:Parameter>
    <ssv:Parameter name="b"><ssv:Real value="0.25"/></ssv:Parameter>
    <ssv:Parameter name="frozen"><ssv:Boolean value="false"/></ssv:Parameter>
  </ssv:Parameters>
</ssv:ParameterSet>
"""
SSM = """<?xml version="1.0" encoding="UTF-8"?>
<ssm:ParameterMapping version="1.0" xmlns:ssm="http://ssp-standard.org/SSP1/SystemStructureParameterMapping"
    xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon">
  <ssm:MappingEntry source="pole" target="a"/>
  <ssm:MappingEntry source="start" target="x0"><ssc:LinearTransformation factor="0.5" offset="0.25"/></ssm:MappingEntry>
</ssm:ParameterMapping>
"""


def test_ssv_files_with_a_mapping_and_a_systems_prefixed_binding_set_the_components_parameters(first_order, tmp_path):
    binding = ('<ssd:ParameterBindings><ssd:ParameterBinding source="resources/plant.ssv">'
               '<ssd:ParameterMapping source="resources/plant.ssm"/></ssd:ParameterBinding></ssd:ParameterBindings>')
    # the prefix comes first, so the mapping maps prefixed names (SSP 1.0, 5.2.3.1)
    system_binding = ('<ssd:ParameterBindings><ssd:ParameterBinding source="resources/other.ssv" prefix="other.">'
                      '<ssd:ParameterMapping><ssm:ParameterMapping version="1.0"><ssm:MappingEntry source="other.pole" '
                      'target="other.a"/><ssm:MappingEntry source="pole" target="other.b"/></ssm:ParameterMapping>'
                      '</ssd:ParameterMapping></ssd:ParameterBinding></ssd:ParameterBindings>')
    text = ssd(f"{system_binding}<ssd:Elements>{component('plant', binding)}{component('other')}</ssd:Elements>")
    other_ssv = SSV.replace('<ssv:Parameter name="start"><ssv:Real value="2"/></ssv:Parameter>', "")
    folder = write_ssp(tmp_path / "values", text, first_order, {"resources/plant.ssv": SSV,
                                                                 "resources/plant.ssm": SSM,
                                                                 "resources/other.ssv": other_ssv})
    assert schema_errors(folder / "SystemStructure.ssd") == []
    diagram = load_diagram(folder)
    plant, other = diagram.blocks["plant"].params, diagram.blocks["other"].params
    # a parameter no entry of the mapping names is not applied (SSP 1.0, 7.1)
    assert plant["start_values"] == {"a": 0.9, "x0": 1.25}
    assert other["start_values"] == {"a": 0.9}
    result = simulate(diagram)
    assert result["plant.y"][1][1, 0] == pytest.approx(0.9 * 1.25)


def test_a_nested_system_is_a_subsystem_with_its_connectors_as_ports(first_order, tmp_path):
    inner = f"""
<ssd:System name="pair">
  <ssd:Connectors>
    <ssd:Connector name="drive" kind="input"><ssc:Real/></ssd:Connector>
    <ssd:Connector name="out" kind="output"><ssc:Real/></ssd:Connector>
  </ssd:Connectors>
  <ssd:ParameterBindings><ssd:ParameterBinding><ssd:ParameterValues><ssv:ParameterSet version="1.0" name="p">
    <ssv:Parameters><ssv:Parameter name="first.x0"><ssv:Real value="1"/></ssv:Parameter></ssv:Parameters>
  </ssv:ParameterSet></ssd:ParameterValues></ssd:ParameterBinding></ssd:ParameterBindings>
  <ssd:Elements>{component("first")}{component("second")}</ssd:Elements>
  <ssd:Connections>
    <ssd:Connection startConnector="drive" endElement="first" endConnector="u"/>
    <ssd:Connection startElement="first" startConnector="y" endElement="second" endConnector="u"/>
    <ssd:Connection startElement="second" startConnector="y" endConnector="out"/>
  </ssd:Connections>
</ssd:System>"""
    text = ssd(f"""<ssd:Elements>{component("source", values(("x0", "Real", "2"), ("a", "Real", "1")))}{inner}
{component("sink")}</ssd:Elements>
<ssd:Connections>
  <ssd:Connection startElement="source" startConnector="y" endElement="pair" endConnector="drive"/>
  <ssd:Connection startElement="pair" startConnector="out" endElement="sink" endConnector="u"/>
</ssd:Connections>""")
    folder = write_ssp(tmp_path / "nested", text, first_order)
    assert schema_errors(folder / "SystemStructure.ssd") == []
    fmu = folder / "resources" / "fo.fmu"
    got = load_diagram(folder)
    assert sorted(got.blocks) == ["pair.first", "pair.second", "sink", "source"]
    want = native(fmu, {
        "source": ("FMU", "100 ms", {"start_values": {"x0": 2.0, "a": 1.0}}),
        "first": ("FMU", "100 ms", {"start_values": {"x0": 1.0}}),
        "second": ("FMU", "100 ms", {}), "sink": ("FMU", "100 ms", {})},
        [("source.y", "first.u"), ("first.y", "second.u"), ("second.y", "sink.u")])
    ra, rb = simulate(got), simulate(want)
    for a, b in (("pair.first.y", "first.y"), ("pair.second.y", "second.y"), ("sink.y", "sink.y")):
        np.testing.assert_array_equal(ra[a][1], rb[b][1])


def test_units_of_the_ssd_convert_between_connectors_and_must_measure_one_quantity(first_order, tmp_path):
    units = ('<ssd:Units><ssc:Unit name="km"><ssc:BaseUnit m="1" factor="1000"/></ssc:Unit>'
             '<ssc:Unit name="m"><ssc:BaseUnit m="1"/></ssc:Unit><ssc:Unit name="s"><ssc:BaseUnit s="1"/></ssc:Unit>'
             "</ssd:Units>")
    out = FIRST_ORDER.replace('name="y" kind="output"><ssc:Real/>', 'name="y" kind="output"><ssc:Real unit="km"/>')
    into = FIRST_ORDER.replace('name="u" kind="input"><ssc:Real/>', 'name="u" kind="input"><ssc:Real unit="{}"/>')
    for unit, factor in (("m", 1000.0), ("s", None)):
        body = (f'<ssd:Elements>{component("a", values(("x0", "Real", "1")), connectors=out)}'
                f'{component("b", connectors=into.format(unit))}</ssd:Elements><ssd:Connections>'
                '<ssd:Connection startElement="a" startConnector="y" endElement="b" endConnector="u"/>'
                "</ssd:Connections>")
        text = ssd(body).replace("<ssd:DefaultExperiment", units + "<ssd:DefaultExperiment")
        folder = write_ssp(tmp_path / f"units_{unit}", text, first_order)
        assert schema_errors(folder / "SystemStructure.ssd") == []
        if factor is None:
            with pytest.raises(DiagramError, match=r"SystemStructure.ssd:\d+: .*'km' to unit 's': they measure"):
                load_diagram(folder)
            continue
        diagram = load_diagram(folder)
        gains = [s for s in diagram.blocks.values() if s.type_name == "Gain"]
        assert [g.params["k"] for g in gains] == [factor]
        assert diagram.blocks["a"].units == {"y": "km"}


def test_steps_come_from_libcosim_and_omsimulator_annotations_or_the_step_given(first_order, first_order_library,
                                                                               tmp_path):
    oms = ('<ssd:Annotations><ssc:Annotation type="org.openmodelica"><oms:Annotations><oms:SimulationInformation>'
           '<oms:FixedStepMaster description="oms-ma" stepSize="0.05"/></oms:SimulationInformation></oms:Annotations>'
           "</ssc:Annotation></ssd:Annotations>")
    base = ('<ssd:DefaultExperiment startTime="0" stopTime="0.6"><ssd:Annotations><ssc:Annotation '
            'type="com.opensimulationplatform"><osp:Algorithm><osp:FixedStepAlgorithm baseStepSize="0.02"/>'
            "</osp:Algorithm></ssc:Annotation></ssd:Annotations></ssd:DefaultExperiment>")
    cases = {
        "oms": (ssd(f"<ssd:Elements>{component('a', step=None)}</ssd:Elements>{oms}"), None, 0.05),
        "base": (ssd(f"<ssd:Elements>{component('a', step=None)}</ssd:Elements>", experiment=base), None, 0.02),
        "grid": (ssd(f"<ssd:Elements>{component('a', step='0.05')}</ssd:Elements>", experiment=base), None, 0.06),
        "given": (ssd(f"<ssd:Elements>{component('a', step=None)}</ssd:Elements>"), "25 ms", 0.025),
        "the FMU's": (ssd(f"<ssd:Elements>{component('a', step=None)}</ssd:Elements>"), None, 0.1),
    }
    for name, (text, step, period) in cases.items():
        folder = write_ssp(tmp_path / name, text, first_order)
        assert schema_errors(folder / "SystemStructure.ssd") == [], name
        assert float(load_diagram(folder, step=step).blocks["a"].period) == pytest.approx(period), name
    folder = write_ssp(tmp_path / "none", ssd(f"<ssd:Elements>{component('a', step=None)}</ssd:Elements>"),
                       variant(first_order_library, NO_STEP))
    with pytest.raises(DiagramError) as caught:
        load_diagram(folder)
    assert len(caught.value.issues) == 1
    assert "component 'a' has no step size" in str(caught.value) and "--step" in str(caught.value)


def test_set_and_the_command_line_reach_an_ssps_parameters(first_order, tmp_path):
    path = write_ssp(tmp_path / "chain", chain_ssd(), first_order, archive=True)
    diagram = load_diagram(path, overrides={"src.x0": 4.0, "mid.start_values.b": 2.0})
    assert diagram.blocks["src"].params["start_values"]["x0"] == 4.0
    assert diagram.blocks["mid"].params["start_values"]["b"] == 2.0
    with pytest.raises(DiagramError, match="no variable|has no"):
        load_diagram(path, overrides={"src.nothing": 1.0})
    out = tmp_path / "run"
    done = subprocess.run([sys.executable, "-m", "blocks", "run", str(path), "-o", str(out), "--set", "src.x0=4",
                           "--t-end", "0.5"], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    from blocks import Results

    assert Results.load(out)["src.y"][1][0, 0] == 4.0
    done = subprocess.run([sys.executable, "-m", "blocks", "validate", str(path)], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0 and "_lt1_gain" in done.stdout, done.stderr


BAD = {
    "unknown element": ('<ssd:Connection startElement="nobody" startConnector="y" endElement="a" endConnector="u"/>',
                        "startElement 'nobody': no element of that name"),
    "unknown connector": ('<ssd:Connection startElement="a" startConnector="w" endElement="a" endConnector="u"/>',
                          "element 'a' declares no connector of that name"),
    "wrong direction": ('<ssd:Connection startElement="a" startConnector="u" endElement="a" endConnector="u"/>',
                        "both are destinations of data"),
    "other transformation": ('<ssd:Connection startElement="a" startConnector="y" endElement="a" endConnector="u">'
                             '<ssc:BooleanMappingTransformation><ssc:MapEntry source="true" target="false"/>'
                             "</ssc:BooleanMappingTransformation></ssd:Connection>",
                             "ssc:BooleanMappingTransformation on a connection is not supported"),
    "array indices": ('<ssd:Connection startElement="a" startConnector="y" startIndices="1" endElement="a" '
                      'endConnector="u"/>', "startIndices/endIndices"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_each_bad_connection_is_one_error_at_its_line(first_order, tmp_path, case):
    connection, message = BAD[case]
    text = ssd(f"<ssd:Elements>{component('a')}</ssd:Elements>\n<ssd:Connections>\n{connection}\n</ssd:Connections>")
    folder = write_ssp(tmp_path / "bad", text, first_order)
    with pytest.raises(DiagramError) as caught:
        load_diagram(folder)
    line = next(i for i, t in enumerate(text.splitlines(), 1) if t.startswith("<ssd:Connection ") or
                t.startswith("<ssc:") and case == "other transformation")
    issues = caught.value.issues
    assert len(issues) == 1, issues
    assert message in issues[0].message and issues[0].file.endswith("SystemStructure.ssd")
    assert issues[0].line == line or case == "other transformation"


BAD_ELEMENTS = {
    "source outside": ('<ssd:Component name="a" source="../fo.fmu"/>', "lies outside the SSP", 'source="../'),
    "source missing": ('<ssd:Component name="a" source="resources/none.fmu"/>', "is not in the SSP", "none.fmu"),
    "not an FMU": ('<ssd:Component name="a" type="application/x-ssp-definition" source="resources/fo.fmu"/>',
                   "of type 'application/x-ssp-definition' is not supported", "x-ssp-definition"),
    "scheduled": ('<ssd:Component name="a" implementation="ScheduledExecution" source="resources/fo.fmu"/>',
                  "implementation 'ScheduledExecution' is not supported", "Scheduled"),
    "dictionary": ('<ssd:SignalDictionaryReference name="bus" dictionary="d"/>',
                   "ssd:SignalDictionaryReference 'bus' is not supported", "SignalDictionaryReference"),
    "array connector": ('<ssd:Component name="a" source="resources/fo.fmu"><ssd:Connectors><ssd:Connector name="q" '
                        'kind="output"><ssc:Real/><ssc:Dimension size="3"/></ssd:Connector></ssd:Connectors>'
                        f"{hint('0.1')}</ssd:Component>", "array connectors (ssc:Dimension) are not supported", "Dimension"),
    "bad name": ('<ssd:Component name="a b" source="resources/fo.fmu"/>', "is not usable as a block name", 'name="a b"'),
    "value type": (component("a", values(("x0", "Binary", "00"))), "values of type ssv:Binary", "ssv:Binary"),
    "ssv missing": (component("a", '<ssd:ParameterBindings><ssd:ParameterBinding source="resources/none.ssv"/>'
                              "</ssd:ParameterBindings>"), "parameter source 'resources/none.ssv' is not in the SSP", "none.ssv"),
}


@pytest.mark.parametrize("case", sorted(BAD_ELEMENTS))
def test_each_unsupported_or_bad_element_is_one_error_naming_it_at_its_line(first_order, tmp_path, case):
    element, message, marker = BAD_ELEMENTS[case]
    text = ssd(f"<ssd:Elements>\n{element}\n</ssd:Elements>")
    folder = write_ssp(tmp_path / "bad", text, first_order)
    with pytest.raises(DiagramError) as caught:
        load_diagram(folder)
    issues = caught.value.issues
    assert len(issues) == 1, issues
    assert message in issues[0].message, issues[0]
    assert issues[0].line == next(i for i, t in enumerate(text.splitlines(), 1) if marker in t)


def test_a_start_time_other_than_zero_is_refused(first_order, tmp_path):
    text = ssd(f"<ssd:Elements>{component('a')}</ssd:Elements>",
               experiment='<ssd:DefaultExperiment startTime="0.5" stopTime="1"/>')
    with pytest.raises(DiagramError, match=r"SystemStructure.ssd:\d+: ssd:DefaultExperiment startTime '0.5'"):
        load_diagram(write_ssp(tmp_path / "start", text, first_order))


def test_an_unsafe_archive_is_refused_before_anything_is_unpacked(first_order, tmp_path):
    import zipfile

    path = tmp_path / "evil.ssp"
    with zipfile.ZipFile(path, "w") as zf:
        zf.writestr("SystemStructure.ssd", ssd(component("a")))
        zf.writestr("../outside.txt", "x")
    with pytest.raises(DiagramError, match="unsafe SSP archive, not unpacked"):
        load_diagram(path)
    assert not (tmp_path.parent / "outside.txt").exists()


def test_a_broken_ssd_is_one_error_with_its_line(tmp_path):
    folder = tmp_path / "broken"
    folder.mkdir()
    (folder / "SystemStructure.ssd").write_text("<ssd:SystemStructureDescription>\n<oops\n")
    with pytest.raises(DiagramError, match=r"SystemStructure.ssd:\d+: not well-formed XML"):
        read_ssp(folder)
