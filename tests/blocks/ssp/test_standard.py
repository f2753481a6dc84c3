"""SSDs as other tools write them (OMSimulator, Dymola, libcosim), valid against the SSP
schemas, run as SSP 1.0 says: unit conversion before a connection's linear transformation,
``ssv`` values converted into their parameter's unit (or refused, saying why), parameter
connectors with units, a binding's prefix before its mapping, top-level inputs held at
their bound value and settable with ``--set``, connections in either direction."""

from __future__ import annotations

import pytest

from blocks import DiagramError, Results, load_diagram, simulate

from blocks.ssp.conversion import UnitError, conversion
from blocks.units import BaseUnit

from .conftest import NAMESPACES, schema_errors, variant, write_ssp

UNITS_FMU = (
    ("<LogCategories>", '<UnitDefinitions><Unit name="m/s2"><BaseUnit m="1" s="-2"/></Unit></UnitDefinitions>\n'
                        "  <LogCategories>"),
    ('<Real start="0.0"/>', '<Real start="0.0" unit="m/s2"/>'),  # x0
    ("<Real/>", '<Real unit="m/s2"/>'),  # y
)
"""The first-order FMU with x0 and y in m/s2, a unit its UnitDefinitions define."""

BASE = 'kg="0" m="1" s="-2" A="0" K="0" mol="0" cd="0" rad="0"'
"""A BaseUnit of an acceleration, every exponent written, as Dymola writes them."""


def root(system: str, units: str = "", experiment: str = '<ssd:DefaultExperiment startTime="0" stopTime="0.3"/>',
         tool: str = "") -> str:
    return (f'<?xml version="1.0" encoding="UTF-8"?>\n<ssd:SystemStructureDescription name="exported" version="1.0" '
            f'{tool} {NAMESPACES}>\n{system}\n{units}\n{experiment}\n</ssd:SystemStructureDescription>\n')


def connectors(*items: tuple[str, str, str | None]) -> str:
    body = "".join(f'<ssd:Connector name="{n}" kind="{k}"><ssc:Real{f" unit={chr(34)}{u}{chr(34)}" if u else ""}/>'
                   "</ssd:Connector>" for n, k, u in items)
    return f"<ssd:Connectors>{body}</ssd:Connectors>"


def inline(*parameters: tuple[str, str, str | None], units: str = "", whole: bool = True) -> str:
    """An inline binding of Real values (name, value, unit); not ``whole``: the ssv:Parameters alone."""
    body = "".join(f'<ssv:Parameter name="{n}"><ssv:Real value="{v}"{f" unit={chr(34)}{u}{chr(34)}" if u else ""}/>'
                   "</ssv:Parameter>" for n, v, u in parameters)
    if not whole:
        return f"<ssv:Parameters>{body}</ssv:Parameters>"
    return ('<ssd:ParameterBindings><ssd:ParameterBinding><ssd:ParameterValues><ssv:ParameterSet version="1.0" '
            f'name="values"><ssv:Parameters>{body}</ssv:Parameters>{units}</ssv:ParameterSet></ssd:ParameterValues>'
            "</ssd:ParameterBinding></ssd:ParameterBindings>")


def unit(name: str, factor: str, prefix: str = "ssc") -> str:
    return f'<{prefix}:Unit name="{name}"><{prefix}:BaseUnit {BASE} factor="{factor}" offset="0"/></{prefix}:Unit>'


# -- libcosim: a linear transformation on a connection that also converts units ---------------------

def test_a_connection_converts_its_units_first_and_then_applies_its_linear_transformation(first_order, tmp_path):
    step = ('<ssd:Annotations><ssc:Annotation type="com.opensimulationplatform"><osp:StepSizeHint value="0.1"/>'
            "</ssc:Annotation></ssd:Annotations>")
    src = (f'<ssd:Component name="src" source="resources/fo.fmu">{connectors(("y", "output", "m"))}'
           f'{inline(("x0", "1", None), ("a", "1", None))}{step}</ssd:Component>')
    sink = (f'<ssd:Component name="sink" source="resources/fo.fmu">{connectors(("u", "input", "mm"))}'
            f'{inline(("a", "0", None), ("threshold", "1e6", None))}{step}</ssd:Component>')
    system = (f'<ssd:System name="cosim"><ssd:Elements>{src}{sink}</ssd:Elements><ssd:Connections>'
              '<ssd:Connection startElement="src" startConnector="y" endElement="sink" endConnector="u">'
              '<ssc:LinearTransformation offset="5"/></ssd:Connection></ssd:Connections></ssd:System>')
    units = ('<ssd:Units><ssc:Unit name="m"><ssc:BaseUnit m="1"/></ssc:Unit><ssc:Unit name="mm">'
             '<ssc:BaseUnit m="1" factor="0.001"/></ssc:Unit></ssd:Units>')
    folder = write_ssp(tmp_path / "libcosim", root(system, units), first_order)
    assert schema_errors(folder / "SystemStructure.ssd") == []
    result = simulate(load_diagram(folder))
    # 1 m is 1000 mm, then + 5: the sink (x[k+1] = u[k]) holds 1005 from its second step
    assert result["src.y"][1][1, 0] == 1.0
    assert result["sink.y"][1][1, 0] == 1005.0


# -- Dymola: top-level connectors, parameter connectors, inline values with units ---------------------

def dymola_ssd() -> str:
    body = f"""<ssd:System name="Pendulum">
  {connectors(("push", "input", "mm/s2"), ("acc", "output", "m/s2"))}
  {inline(("push", "2500", "mm/s2"), ("body.x0", "-490.5", "cm/s2"),
          units=f"<ssv:Units>{unit('cm/s2', '0.01')}{unit('mm/s2', '0.001')}</ssv:Units>")}
  <ssd:Elements>
    <ssd:Component name="body" type="application/x-fmu-sharedlibrary" source="resources/fo.fmu">
      {connectors(("u", "input", "m/s2"), ("y", "output", "m/s2"), ("x0", "parameter", "m/s2"), ("a", "parameter", None))}
    </ssd:Component>
  </ssd:Elements>
  <ssd:Connections>
    <ssd:Connection startElement="body" startConnector="u" endConnector="push"/>
    <ssd:Connection startElement="body" startConnector="y" endConnector="acc"/>
  </ssd:Connections>
</ssd:System>"""
    return root(body, f"<ssd:Units>{unit('m/s2', '1')}{unit('mm/s2', '0.001')}</ssd:Units>",
                tool='generationTool="Dymola Version 2024x"')


def test_a_dymola_style_ssd_converts_values_into_their_parameters_units_and_runs_its_top_level_input(
        first_order_library, tmp_path):
    folder = write_ssp(tmp_path / "dymola", dymola_ssd(), variant(first_order_library, *UNITS_FMU))
    assert schema_errors(folder / "SystemStructure.ssd") == []
    diagram = load_diagram(folder)  # no step annotation: the FMU's DefaultExperiment step, 0.1 s
    assert float(diagram.blocks["body"].period) == 0.1
    assert diagram.blocks["body"].params["start_values"]["x0"] == pytest.approx(-4.905, rel=1e-15)
    y = simulate(diagram)["body.y"][1][:, 0]
    assert y[0] == pytest.approx(-4.905, rel=1e-15)  # -490.5 cm/s2
    assert y[1] == pytest.approx(0.5 * -4.905 + 2.5, rel=1e-15)  # x[1] = a x0 + b u, u = 2500 mm/s2
    held = simulate(load_diagram(folder, overrides={"push.value": 5000.0}))["body.y"][1][:, 0]
    assert held[1] == pytest.approx(0.5 * -4.905 + 5.0, rel=1e-15)


def test_set_on_the_command_line_sets_a_top_level_input(first_order_library, tmp_path):
    from blocks.cli import PROGRAM, main

    folder = write_ssp(tmp_path / "dymola", dymola_ssd(), variant(first_order_library, *UNITS_FMU))
    out = tmp_path / "run"
    assert main(PROGRAM, ["run", str(folder), "-o", str(out), "--set", "push.value=-1000", "--quiet"]) == 0
    results = Results.load(out)
    assert results["push.y"][1][0, 0] == -1000.0 and results.unit("push.y") == "mm/s2"
    assert results["body.y"][1][1, 0] == pytest.approx(0.5 * -4.905 - 1.0, rel=1e-15)


def test_an_unbound_top_level_input_holds_the_start_value_of_the_fmu_input_it_feeds(first_order_library, tmp_path):
    text = dymola_ssd().replace('<ssv:Parameter name="push"><ssv:Real value="2500" unit="mm/s2"/></ssv:Parameter>', "")
    fmu = variant(first_order_library, *UNITS_FMU, ('<Real start="0.0"/>', '<Real start="2.0"/>'))  # u starts at 2
    folder = write_ssp(tmp_path / "dymola", text, fmu)
    assert schema_errors(folder / "SystemStructure.ssd") == []
    result = simulate(load_diagram(folder))
    assert result["push.y"][1][0, 0] == pytest.approx(2000.0, rel=1e-15)  # 2 m/s2 in the connector's mm/s2
    assert result["body.y"][1][1, 0] == pytest.approx(0.5 * -4.905 + 2.0, rel=1e-15)


@pytest.mark.parametrize("value, message", [
    ('<ssv:Real value="3" unit="s"/>', "'s' does not convert to unit 'm/s2'"),
    ('<ssv:Real value="3" unit="zorks"/>', "unit 'zorks' is defined nowhere"),
])
def test_a_value_that_cannot_be_converted_into_its_parameters_unit_is_refused_at_its_line(
        first_order_library, tmp_path, value, message):
    text = dymola_ssd().replace('<ssv:Real value="-490.5" unit="cm/s2"/>', value)
    folder = write_ssp(tmp_path / "bad", text, variant(first_order_library, *UNITS_FMU))
    with pytest.raises(DiagramError) as caught:
        load_diagram(folder)
    (issue,) = caught.value.issues
    assert message in issue.message and "body.x0" in issue.message
    assert issue.line == next(i for i, t in enumerate(text.splitlines(), 1) if 'name="body.x0"' in t)


def test_a_value_with_a_unit_for_a_parameter_without_one_is_refused(first_order, tmp_path):
    text = dymola_ssd().replace('name="body.x0"><ssv:Real value="-490.5" unit="cm/s2"/>',
                                'name="body.a"><ssv:Real value="0.5" unit="cm/s2"/>')
    folder = write_ssp(tmp_path / "bad", text, first_order)
    with pytest.raises(DiagramError, match="declares no unit to convert it into"):
        load_diagram(folder)


# -- OMSimulator: an .ssv and an .ssm at the system, units the .ssv does not define -------------------

OMS_SSV = ("<?xml version='1.0' encoding='utf-8'?>\n<ssv:ParameterSet xmlns:ssc=\"http://ssp-standard.org/SSP1/"
           'SystemStructureCommon" xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues" '
           'version="1.0" name="parameters">' + inline(("body.x0", "-490.5", "cm/s2"), ("gain_pct", "50", None),
                                                       ("sink.threshold", "1e9", None), ("sink.a", "0", None),
                                                       ("sink.b", "7", None), whole=False) + "</ssv:ParameterSet>\n")
OMS_SSM = """<?xml version='1.0' encoding='utf-8'?>
<ssm:ParameterMapping xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon"
    xmlns:ssm="http://ssp-standard.org/SSP1/SystemStructureParameterMapping" version="1.0">
  <ssm:MappingEntry source="body.x0" target="body.x0"><ssc:LinearTransformation factor="2" offset="1"/></ssm:MappingEntry>
  <ssm:MappingEntry source="gain_pct" target="body.a"><ssc:LinearTransformation factor="0.01"/></ssm:MappingEntry>
  <ssm:MappingEntry source="sink.threshold" target="sink.threshold"/>
  <ssm:MappingEntry source="sink.a" target="sink.a"/>
  <ssm:MappingEntry source="" target="sink.b"/>
</ssm:ParameterMapping>
"""


def test_an_omsimulator_style_ssd_maps_its_values_converts_their_units_and_then_transforms(
        first_order, first_order_library, tmp_path):
    system = f"""<ssd:System name="root">
  <ssd:ParameterBindings><ssd:ParameterBinding source="resources/root.ssv">
    <ssd:ParameterMapping source="resources/root.ssm"/></ssd:ParameterBinding></ssd:ParameterBindings>
  <ssd:Elements>
    <ssd:Component name="body" type="application/x-fmu-sharedlibrary" source="resources/fo.fmu">
      {connectors(("u", "input", None), ("y", "output", "m/s2"), ("x0", "parameter", "m/s2"), ("a", "parameter", None))}
    </ssd:Component>
    <ssd:Component name="sink" type="application/x-fmu-sharedlibrary" source="resources/plain.fmu">
      {connectors(("u", "input", "mm/s2"), ("y", "output", None), ("threshold", "parameter", None))}
    </ssd:Component>
  </ssd:Elements>
  <ssd:Connections>
    <ssd:Connection startElement="body" startConnector="y" endElement="sink" endConnector="u">
      <ssc:LinearTransformation factor="1" offset="5"/></ssd:Connection>
  </ssd:Connections>
  <ssd:Annotations><ssc:Annotation type="org.openmodelica"><oms:Annotations><oms:SimulationInformation>
    <oms:FixedStepMaster description="oms-ma" stepSize="0.1"/></oms:SimulationInformation></oms:Annotations>
  </ssc:Annotation></ssd:Annotations>
</ssd:System>"""
    units = ('<ssd:Units><ssc:Unit name="m/s2"><ssc:BaseUnit m="1" s="-2"/></ssc:Unit><ssc:Unit name="mm/s2">'
             '<ssc:BaseUnit m="1" s="-2" factor="0.001"/></ssc:Unit></ssd:Units>')
    folder = write_ssp(tmp_path / "oms", root(system, units, tool='generationTool="OMSimulator v3.0.0"'),
                       variant(first_order_library, *UNITS_FMU),
                       {"resources/plain.fmu": first_order, "resources/root.ssv": OMS_SSV, "resources/root.ssm": OMS_SSM})
    assert schema_errors(folder / "SystemStructure.ssd") == []
    diagram = load_diagram(folder)
    body, sink = diagram.blocks["body"].params["start_values"], diagram.blocks["sink"].params["start_values"]
    # -490.5 cm/s2 (read by pint in Modelica's notation) is -4.905 m/s2, then 2 x + 1 (SSP 1.0, 7.1.1)
    assert body == pytest.approx({"x0": 2 * -4.905 + 1, "a": 0.5}, rel=1e-15)
    assert sink == {"threshold": 1e9, "a": 0.0}  # sink.b is the source of no mapping entry: not applied
    result = simulate(diagram)
    # -8.81 m/s2 is -8810 mm/s2, then + 5; the sink (x[k+1] = u[k], b = 1) holds it from its second step
    assert result["sink.y"][1][1, 0] == pytest.approx(-8805.0, rel=1e-15)


def test_an_omsimulator_export_with_system_parameters_and_unnamed_system_ends_runs(first_order, tmp_path):
    """As OMSimulator exports a system whose parameters and inputs are the system's own
    connectors: ``startElement=""`` for the system, the values bound by bare name."""
    ssv = ("<?xml version='1.0' encoding='utf-8'?>\n<ssv:ParameterSet xmlns:ssv=\"http://ssp-standard.org/SSP1/"
           'SystemStructureParameterValues" version="1.0" name="parameters">'
           + inline(("k_cref", "0.25", None), ("Input_cref", "-20", None), ("foo.F_cref", "40", None),
                    ("p.b", "10", None), ("p.a", "0.5", None), whole=False) + "</ssv:ParameterSet>\n")
    system = f"""<ssd:System name="co_sim">
  {connectors(("Input_cref", "input", None), ("Output_cref", "output", None), ("k_cref", "parameter", None))}
  <ssd:ParameterBindings><ssd:ParameterBinding source="resources/values.ssv"/></ssd:ParameterBindings>
  <ssd:Elements>
    <ssd:System name="foo">{connectors(("F_cref", "parameter", None))}</ssd:System>
    <ssd:Component name="p" type="application/x-fmu-sharedlibrary" source="resources/fo.fmu">
      {connectors(("u", "input", None), ("y", "output", None), ("a", "parameter", None), ("b", "parameter", None))}
    </ssd:Component>
  </ssd:Elements>
  <ssd:Connections>
    <ssd:Connection startElement="" startConnector="k_cref" endElement="p" endConnector="b"/>
    <ssd:Connection startElement="" startConnector="Input_cref" endElement="p" endConnector="u"/>
    <ssd:Connection startElement="p" startConnector="y" endElement="" endConnector="Output_cref"/>
  </ssd:Connections>
</ssd:System>"""
    folder = write_ssp(tmp_path / "oms", root(system), first_order, {"resources/values.ssv": ssv})
    assert schema_errors(folder / "SystemStructure.ssd") == []
    diagram = load_diagram(folder)
    assert diagram.blocks["p"].params["start_values"] == {"a": 0.5, "b": 0.25}  # the system's k_cref wins
    y = simulate(diagram)["p.y"][1][:, 0]
    assert y[1] == 0.25 * -20.0  # x[1] = a x0 + b u, x0 = 0, u the input held at its bound -20


def test_an_enumeration_value_is_the_number_of_its_item_in_the_fmus_type(first_order_library, tmp_path):
    fmu = variant(first_order_library,
                  ("<LogCategories>", '<TypeDefinitions><SimpleType name="Scale"><Enumeration><Item name="single" '
                                      'value="1"/><Item name="triple" value="3"/></Enumeration></SimpleType>'
                                      "</TypeDefinitions>\n  <LogCategories>"),
                  ('<Integer start="1"/>', '<Enumeration declaredType="Scale" start="1"/>'))
    values = ('<ssd:ParameterBindings><ssd:ParameterBinding><ssd:ParameterValues><ssv:ParameterSet version="1.0" '
              'name="values"><ssv:Parameters><ssv:Parameter name="scale"><ssv:Enumeration value="{}"/>'
              '</ssv:Parameter><ssv:Parameter name="x0"><ssv:Real value="2"/></ssv:Parameter></ssv:Parameters>'
              "</ssv:ParameterSet></ssd:ParameterValues></ssd:ParameterBinding></ssd:ParameterBindings>")
    component = ('<ssd:Component name="c" source="resources/fo.fmu">'
                 f'{connectors(("z[1]", "output", None))}{values}</ssd:Component>')
    folder = write_ssp(tmp_path / "enum", root(f'<ssd:System name="s"><ssd:Elements>{component}</ssd:Elements>'
                                               "</ssd:System>").replace("{}", "triple"), fmu)
    assert schema_errors(folder / "SystemStructure.ssd") == []
    diagram = load_diagram(folder)
    assert diagram.blocks["c"].params["start_values"]["scale"] == 3
    assert simulate(diagram)["c.z"][1][0, 0] == 3 * 2.0  # z[1] = scale x
    folder = write_ssp(tmp_path / "bad", root(f'<ssd:System name="s"><ssd:Elements>{component}</ssd:Elements>'
                                              "</ssd:System>").replace("{}", "double"), fmu)
    with pytest.raises(DiagramError, match="'double' is no item of the FMU's enumeration type of 'scale'"):
        load_diagram(folder)


@pytest.mark.parametrize("source, target, tables, want", [
    ("cm/s2", "m/s2", (), (0.01, 0.0)),  # Modelica's notation, read by pint
    ("[cm/s2]", "m/s2", (), (0.01, 0.0)),  # a unit in brackets, as some tools write values' units
    ("degC", "K", (), (1.0, 273.15)),
    ("kg.m2", "g.cm2", (), (1e7, 0.0)),
    ("a", "b", ({"a": BaseUnit((("m", 1),), 2.0, 1.0), "b": BaseUnit((("m", 1),), 4.0, 0.0)},), (0.5, 0.25)),
    ("m", "m", (), (1.0, 0.0)),
])
def test_units_convert_as_their_definitions_or_pint_say(source, target, tables, want):
    factor, offset = conversion(source, target, *tables)
    assert factor == pytest.approx(want[0], rel=1e-12) and offset == pytest.approx(want[1], rel=1e-12, abs=1e-12)


@pytest.mark.parametrize("source, target, message", [
    ("m", "s", "measure different quantities"),
    ("zorks", "m", "unit 'zorks' is defined nowhere"),
])
def test_units_that_do_not_convert_are_refused(source, target, message):
    with pytest.raises(UnitError, match=message):
        conversion(source, target)
