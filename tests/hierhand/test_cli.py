"""The hierhand command's own advice: how to make the plant FMU a diagram misses."""

from __future__ import annotations

import shutil
from pathlib import Path

from hierhand.cli import main

DIAGRAMS = Path(__file__).resolve().parents[2] / "diagrams"


def test_a_missing_exported_plant_fmu_is_made_with_fmu_export(tmp_path, monkeypatch, capsys):
    (tmp_path / "diagrams").mkdir()
    for name in ("regrasp_fmu.yaml", "controller.yaml"):
        shutil.copy(DIAGRAMS / name, tmp_path / "diagrams" / name)
    monkeypatch.chdir(tmp_path)
    assert main(["validate", "diagrams/regrasp_fmu.yaml"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert err.startswith("diagrams/regrasp_fmu.yaml:15: block 'plant' (FMU): FMU file not found")
    assert err.endswith("(hint: make it with 'hierhand fmu export --fmi 2 -o fmu/HandPlant_fmi2.fmu')")


def test_any_other_missing_fmu_keeps_the_general_hint(tmp_path, monkeypatch, capsys):
    (tmp_path / "d.yaml").write_text("time: {t_end: 1 s}\nblocks:\n"
                                     "  f: {type: FMU, period: 1 ms, params: {path: other.fmu}}\n")
    monkeypatch.chdir(tmp_path)
    assert main(["validate", "d.yaml"]) == 2
    err = capsys.readouterr().err
    assert "FMU file not found" in err and "hierhand blocks" not in err
    assert err.strip().endswith("(hint: check the path; an FMU that a tool exports must be exported before "
                                "a diagram can use it)")


def subcommands(parser):
    """Each (name, parser) of ``parser``'s subcommands, nested ones (``fmu info``) too."""
    import argparse

    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield name, sub
                for inner, subsub in subcommands(sub):
                    yield f"{name} {inner}", subsub


def test_every_command_has_a_description_in_its_help():
    from blocks.cli.program import build_parser
    from hierhand.cli import PROGRAM

    found = dict(subcommands(build_parser(PROGRAM)))
    assert {"run", "validate", "graph", "plot", "blocks", "fmu", "fmu info", "fmu export", "animate"} <= set(found)
    for name, parser in found.items():
        assert parser.description and len(parser.description) > 20, name
