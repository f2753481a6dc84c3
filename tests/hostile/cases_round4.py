"""Corpus cases of hardening round 3's classes: unit texts that would compute, numbers from
SSPs and diagrams that would make exact arithmetic or memory explode, paths that leave
their folder, foreign modules in the working folder, control characters on the way to the
terminal, and inputs that used to end in an internal error.

Each case is a class member of its own: the limits are checked before the work they guard
(``blocks.units.unit_problem``, ``blocks.timebase.parse_duration``,
``blocks.limits.check_block_size``), so a refusal here takes no longer than a valid load.
"""

from __future__ import annotations

import subprocess
from pathlib import Path

from tests.blocks.ssp.conftest import ssd
from tests.blocks.ssp.test_import import FIRST_ORDER, component, values

from .cases_fmu import fmu
from .cases_round3 import ASCII_LOCALE, ssp
from .corpus import ROOT, Case

TOY = """\
name: {name}
time: {{t_end: 5 ms}}
blocks:
  ramp: {{type: Ramp, period: 1 ms, params: {{slope: 1.0}}}}
  g: {{type: Gain, params: {{k: 2.0}}}}
connections: [ramp.y -> g.u]
log: [ramp.y, g.y]
{extra}"""


def toy(name: str = "toy", extra: str = "") -> str:
    return TOY.format(name=name, extra=extra)


def blocks(*lines: str, log: str = "[c.y]") -> str:
    """A diagram of a 3-wide Constant ``c`` and the blocks (and connections) in ``lines``."""
    return ("name: b\ntime: {t_end: 5 ms}\nblocks:\n  c: {type: Constant, period: 1 ms, params: {value: [1, 2, 3]}}\n"
            + "".join(f"  {line}\n" for line in lines if not line.startswith("connections"))
            + "".join(f"{line}\n" for line in lines if line.startswith("connections")) + f"log: {log}\n")


def with_unit(unit: str) -> str:
    """An SSD whose component's output connector declares ``unit``."""
    connectors = FIRST_ORDER.replace('name="y" kind="output"><ssc:Real/>', f'name="y" kind="output"><ssc:Real unit="{unit}"/>')
    return ssd(f"<ssd:Elements>{component('a', connectors=connectors)}</ssd:Elements>")


def two_components(connection: str, extra: str = "", units: str = "", names: tuple[str, str] = ("a", "b")) -> str:
    """An SSD of two first-order components wired by ``connection`` (its attributes and body)."""
    a, b = names
    text = ssd(f"<ssd:Elements>{component(a)}{component(b)}{extra}</ssd:Elements><ssd:Connections>"
               f"{connection.format(a=a, b=b)}</ssd:Connections>")
    return text.replace("<ssd:DefaultExperiment", units + "<ssd:DefaultExperiment") if units else text


def no_raw_controls(folder: Path, proc: subprocess.CompletedProcess) -> None:
    """A ``check``: nothing the command wrote holds a raw escape, bell or carriage return."""
    for text in (proc.stdout, proc.stderr):
        assert not any(c in text for c in "\x1b\x07\r\x9b\u202e"), repr(text)


def no_numpy_warning(folder: Path, proc: subprocess.CompletedProcess) -> None:
    assert "Warning" not in proc.stderr, proc.stderr


def ran_in(path: str):
    """A ``check``: the FMU was written at ``path`` (inside the -o folder)."""
    def check(folder: Path, proc: subprocess.CompletedProcess) -> None:
        assert (folder / path).is_file(), sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))
    return check


FOREIGN = "raise SystemExit('imported from the working folder')\n"
SUBSYSTEM = ("name: s\ninputs: {x: [g.u]}\noutputs: {x: g.y}\nblocks:\n  g: {type: Gain, params: {k: 2.0}}\n")
SWEEP_ARGS = ("--grid", "g.k=1,2", "--metric", "m=final(g.y)", "-q")

CASES = [
    # -- unit texts are read by a grammar before pint: nothing in them is computed
    Case("unit-that-is-a-tower-of-powers", ("validate", "d.yaml"), 2,
         r"^d\.yaml:\d+: units of ramp\.y: '\(\(kg\)\^12\)\^12' is not a unit: a group raised",
         files={"d.yaml": toy(extra="units: {ramp.y: '((kg)^12)^12'}\n")}),
    Case("unit-with-a-power-of-a-number", ("validate", "d.yaml"), 2, r"^d\.yaml:\d+: units of ramp\.y: 'm \* 10\*\*99999' is not a unit",
         files={"d.yaml": toy(extra="units: {ramp.y: 'm * 10**99999'}\n")}),
    Case("unit-that-calls-python", ("validate", "d.yaml"), 2, r"^d\.yaml:\d+: .*'\.' at character 2 is not part of a unit",
         files={"d.yaml": toy(extra="units: {ramp.y: \"m.__class__.__mro__[1]\"}\n")}),
    Case("ssp-connector-unit-that-computes", ("validate", "s.ssp"), 2,
         r"SystemStructure\.ssd:\d+: units of a\.y: '2\*\*2\*\*2\*\*2\*\*2\*\*2' is not a unit",
         files={"s.ssp": ssp(with_unit("2**2**2**2**2**2"))}),
    # -- numbers from outside are range-checked before they are made exact
    Case("ssp-start-time-of-a-billion-digits", ("validate", "s.ssp"), 2,
         r"SystemStructure\.ssd:\d+: ssd:DefaultExperiment startTime '7e888888888' is not supported",
         files={"s.ssp": ssp(ssd(f"<ssd:Elements>{component('a')}</ssd:Elements>",
                                 experiment='<ssd:DefaultExperiment startTime="7e888888888" stopTime="1"/>'))}),
    Case("ssp-stop-time-far-beyond-a-float", ("validate", "s.ssp"), 2,
         r"SystemStructure\.ssd:\d+: ssd:DefaultExperiment stopTime '3E\+777777777' is not a positive number of "
         r"seconds \(duration .* out of range",
         files={"s.ssp": ssp(ssd(f"<ssd:Elements>{component('a')}</ssd:Elements>",
                                 experiment='<ssd:DefaultExperiment stopTime="3E+777777777"/>'))}),
    Case("ssp-step-hint-of-a-tiny-exponent", ("validate", "s.ssp"), 2,
         r"SystemStructure\.ssd:\d+: component 'a': osp:StepSizeHint '5e-555555555' is not a positive number",
         files={"s.ssp": ssp(ssd(f"<ssd:Elements>{component('a', step='5e-555555555')}</ssd:Elements>"))}),
    Case("period-text-of-twenty-thousand-digits", ("validate", "d.yaml"), 2,
         r"^d\.yaml:\d+: .*period: duration '9{20}'\.\.\. has 20002 characters",
         files={"d.yaml": toy().replace("period: 1 ms", "period: '" + "9" * 20000 + " s'")}),
    Case("ssv-integer-outside-its-type", ("validate", "s.ssp"), 2,
         r"SystemStructure\.ssd:\d+: component 'a': parameter 'n': -129 is out of the range of an ssv:Int8 \(-128 to 127\)",
         files={"s.ssp": ssp(ssd(f"<ssd:Elements>{component('a', values(('n', 'Int8', '-129')))}</ssd:Elements>"))}),
    Case("ssv-unsigned-integer-below-zero", ("validate", "s.ssp"), 2, r"out of the range of an ssv:UInt16",
         files={"s.ssp": ssp(ssd(f"<ssd:Elements>{component('a', values(('n', 'UInt16', '-1')))}</ssd:Elements>"))}),
    Case("ssv-real-that-is-no-finite-number", ("validate", "s.ssp"), 2, r"parameter 'x0': 'INF' is not an ssv:Real",
         files={"s.ssp": ssp(ssd(f"<ssd:Elements>{component('a', values(('x0', 'Real', 'INF')))}</ssd:Elements>"))}),
    Case("ssc-unit-whose-factor-is-zero", ("validate", "s.ssp"), 2, r"ssc:Unit 'mm': its factor is 0",
         files={"s.ssp": ssp(two_components('<ssd:Connection startElement="{a}" startConnector="y" endElement="{b}" '
                                            'endConnector="u"/>',
                                            units='<ssd:Units><ssc:Unit name="mm"><ssc:BaseUnit m="1" factor="0"/>'
                                                  '</ssc:Unit></ssd:Units>'))}),
    Case("moving-average-window-times-width", ("validate", "d.yaml"), 2,
         r"block 'avg' \(MovingAverage\) .*window 600000 x width 100 make 6e\+07 values to hold, more than the limit",
         files={"d.yaml": blocks("w: {type: Constant, period: 1 ms, params: {value: " + str([0.5] * 100) + "}}",
                                 "avg: {type: MovingAverage, params: {window: 600000}}", "connections: [w.y -> avg.u]",
                                 log="[avg.y]")}),
    Case("demux-of-ten-billion-outputs", ("validate", "d.yaml"), 2,
         r"block 'dm' \(Demux\): parameter 'widths' gives 10000000000 outputs; at most 64",
         files={"d.yaml": blocks("dm: {type: Demux, params: {widths: 10000000000}}")}),
    Case("mux-of-widths-beyond-any-port", ("validate", "d.yaml"), 2,
         r"block 'mx' \(Mux\): parameter 'widths': its widths add up to 4000000000",
         files={"d.yaml": blocks("mx: {type: Mux, params: {widths: [2000000000, 2000000000]}}")}),
    Case("transfer-function-of-degree-three-thousand", ("validate", "d.yaml"), 2,
         r"block 'tf' \(DiscreteTransferFunction\): .*states \+ outputs 3000 x states \+ inputs 3000 make",
         files={"d.yaml": blocks("tf: {type: DiscreteTransferFunction, params: {num: [1], den: "
                                 + str([1.0] + [0.0] * 2999) + "}}")}),
    Case("selector-slice-of-a-trillion", ("validate", "d.yaml"), 2,
         r"block 'sel' \(Selector\): parameter 'indices': the slice '0:4000000000000' reaches beyond the widest port",
         files={"d.yaml": blocks("sel: {type: Selector, params: {indices: '0:4000000000000'}}",
                                 "connections: [c.y -> sel.u]")}),
    Case("log-decimate-beyond-any-run", ("validate", "d.yaml"), 2,
         r"^d\.yaml:\d+: log decimate must be a whole number from 1 to \d+, got 123456789012345678901",
         files={"d.yaml": toy().replace("log: [ramp.y, g.y]", "log: [{signal: g.y, decimate: 123456789012345678901}]")}),
    # -- files stay in their folders
    Case("fmu-export-of-a-diagram-named-to-climb", ("fmu", "export", "d.yaml", "-o", "out/"), 0, "",
         files={"d.yaml": toy(name="'../../../climbed'")}, absent=("climbed_fmi2.fmu", "../climbed_fmi2.fmu"),
         check=ran_in("out/_climbed_fmi2.fmu")),
    Case("from-file-reaching-out-of-the-diagram-folder", ("validate", "sub/d.yaml"), 2,
         r"^sub/d\.yaml:\d+: block 'f': path '\.\./private\.csv' is outside the diagram's folder \(hint: .*--trust",
         files={"private.csv": "t,x\n0,1\n1,2\n",
                "sub/d.yaml": "name: f\ntime: {t_end: 5 ms}\nblocks:\n  f: {type: FromFile, period: 1 ms, "
                              "params: {path: ../private.csv}}\nlog: [f.y]\n"}),
    Case("from-file-reaching-out-with-an-absolute-path", ("validate", "d.yaml"), 2,
         r"block 'f': path '/etc/hostname' is outside the diagram's folder",
         files={"d.yaml": "name: f\ntime: {t_end: 5 ms}\nblocks:\n  f: {type: FromFile, period: 1 ms, "
                          "params: {path: /etc/hostname}}\nlog: [f.y]\n"}),
    # -- nothing is imported from the working folder, whatever PYTHONPATH says
    Case("pythonpath-with-an-empty-entry-and-a-foreign-blocks-package", ("validate", "d.yaml"), 0, "",
         files={"d.yaml": toy(), "blocks/__init__.py": FOREIGN, "yaml.py": FOREIGN, "numpy.py": FOREIGN},
         env={"PYTHONPATH": f"{ROOT}::"}),
    Case("pythonpath-of-dot-and-a-foreign-module", ("run", "d.yaml", "-o", "out"), 0, "",
         files={"d.yaml": toy(), "tqdm.py": FOREIGN, "matplotlib/__init__.py": FOREIGN},
         env={"PYTHONPATH": f".:{ROOT}"}),
    # -- control characters from files are escaped on the terminal
    Case("diagram-name-that-retitles-the-terminal", ("run", "d.yaml", "-o", "out"), 0, "",
         files={"d.yaml": toy(name='"\\e]2;owned\\a\\e[2J\\e[3J\\rdone"')}, check=no_raw_controls),
    Case("parameter-text-with-a-bidi-override-in-an-error", ("validate", "d.yaml"), 2,
         r"parameter 'method' must be one of .*\\u202e",
         files={"d.yaml": blocks("h: {type: ZeroOrderHold, params: {}}", "i: {type: DiscreteIntegrator, params: "
                                 "{method: \"ab\\u202e\\x9bcd\"}}", "connections: [c.y -> i.u]")},
         check=no_raw_controls),
    # -- inputs that ended in an internal error
    Case("sweep-output-whose-runs-is-a-file", ("sweep", "d.yaml", "-o", "out", "--keep-results", *SWEEP_ARGS), 2,
         r"^hierhand: error: out/runs is not a folder", files={"d.yaml": toy(), "out/runs": "mine"}),
    Case("sweep-resumed-on-a-csv-of-latin-1", ("sweep", "d.yaml", "-o", "out", *SWEEP_ARGS), 2,
         r"^hierhand: error: out/sweep\.csv: not a sweep's CSV file: .*codec",
         files={"d.yaml": toy(), "out/sweep.csv": "point_hash,status\nd\xe9j\xe0\n".encode("latin-1")}),
    Case("sweep-plot-of-a-field-of-a-megabyte", ("sweep-plot", "out", "--x", "g.k", "--metric", "m", "-o", "p.png"),
         2, r"^hierhand: error: out: cannot read the sweep: field larger than field limit",
         files={"out/sweep.csv": "point_hash,status,error,wall_s,g.k,m\n" + "x" * (1 << 20) + ",ok,,1,1,2\n"}),
    Case("sweep-plot-of-a-metric-that-is-text", ("sweep-plot", "out", "--x", "g.k", "--metric", "m", "-o", "p.png"),
         2, r"^hierhand: error: out: point 'abc'.*its 'm' is not a number \('many'\)",
         files={"out/sweep.csv": "point_hash,status,error,wall_s,g.k,m\nabc,ok,,1,1,many\n",
                "out/sweep.json": '{"parameters": ["g.k"], "metrics": {"m": "final(g.y)"}}'}),
    Case("graph-o-below-a-file", ("graph", "d.yaml", "-o", "f/wiring.dot"), 2,
         r"^hierhand: error: -o f/wiring\.dot: cannot write it: ",
         files={"d.yaml": toy(), "f": "a file"}),
    Case("lookup-breakpoints-a-float-range-apart", ("validate", "d.yaml"), 2,
         r"block 'lut' \(LookupTable1D\): parameter 'breakpoints': the gaps between breakpoints must be finite",
         files={"d.yaml": blocks("lut: {type: LookupTable1D, params: {breakpoints: [-1.0e+308, 1.5e+308], "
                                 "table: [0.0, 1.0]}}", "connections: [c.y -> lut.u]")},
         check=no_numpy_warning),
    Case("subsystem-input-and-output-of-one-name", ("validate", "d.yaml"), 2,
         r"^s\.yaml:\d+: the diagram's output 'x' has the name of one of its inputs",
         files={"s.yaml": SUBSYSTEM,
                "d.yaml": "name: d\ntime: {t_end: 5 ms}\nblocks:\n  ramp: {type: Ramp, period: 1 ms, params: "
                          "{slope: 1.0}}\n  sub: {diagram: s.yaml}\nconnections: [ramp.y -> sub.x]\nlog: [ramp.y]\n"}),
    Case("set-error-names-the-command-line", ("validate", "d.yaml", "--set", "g.k=[[1, 2], [3]]"), 2,
         r"^--set g\.k=\[\[1, 2\], \[3\]\]: block 'g' \(Gain\)", files={"d.yaml": toy()}),
    Case("ssp-conversion-beside-a-component-named-as-its-blocks", ("validate", "s.ssp"), 0, "",
         files={"s.ssp": ssp(two_components(
             '<ssd:Connection startElement="{a}" startConnector="y" endElement="{b}" endConnector="u">'
             '<ssc:LinearTransformation factor="3" offset="1"/></ssd:Connection>',
             extra=component("_lt1_bias") + component("_lt1")))}),
    Case("ssd-connector-of-element-zero", ("validate", "s.ssp"), 2, r"SystemStructure\.ssd:\d+: .*z\[0\]",
         files={"s.ssp": ssp(ssd("<ssd:Elements>" + component(
             "a", connectors=FIRST_ORDER.replace('name="z[1]"', 'name="z[0]"')) + component("b")
             + '</ssd:Elements><ssd:Connections><ssd:Connection startElement="a" startConnector="z[0]" '
             'endElement="b" endConnector="u"/></ssd:Connections>'))}),
    Case("ssp-member-of-a-non-ascii-name-in-an-ascii-locale", ("validate", "s.ssp"), 2, r"s\.ssp",
         files={"s.ssp": ssp(ssd(f"<ssd:Elements>{component('a').replace('resources/fo.fmu', 'resources/fö.fmu')}"
                                 "</ssd:Elements>"), **{"resources__fö.fmu": fmu()})},
         env=ASCII_LOCALE),
]
