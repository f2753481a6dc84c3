"""Runs every case of the hostile-input corpus (``cases_*.py``) through the command line."""

from __future__ import annotations

import importlib
import pkgutil
from pathlib import Path

import pytest

from .corpus import Case, run, verify


def all_cases() -> list[Case]:
    cases: list[Case] = []
    for info in pkgutil.iter_modules([str(Path(__file__).parent)]):
        if info.name.startswith("cases_"):
            cases += importlib.import_module(f"{__package__}.{info.name}").CASES
    names = [c.name for c in cases]
    assert len(names) == len(set(names)), "corpus case names must be unique"
    return cases


@pytest.mark.parametrize("case", all_cases(), ids=lambda c: c.name)
def test_case(case: Case, tmp_path: Path):
    from tests.forked_cli import shared

    folder = tmp_path / "case"
    folder.mkdir()
    verify(case, folder, run(case, folder, shared()))
