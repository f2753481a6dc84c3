"""The shipped diagrams name the diagram file's JSON Schema in their first line, validate
against it, and the schema shipped beside them is the one ``hierhand schema`` writes."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import jsonschema
import pytest
import yaml

from blocks.cli.schema import schema_text
from blocks.diagram_file.schema import SCHEMA_FILE, SCHEMA_LINE

ROOT = Path(__file__).resolve().parents[2]
DIAGRAMS = ROOT / "diagrams"
SHIPPED_SCHEMA = DIAGRAMS / SCHEMA_FILE


def test_the_shipped_schema_is_what_hierhand_schema_writes_now():
    """Committed and checked fresh: a block type or parameter added without regenerating
    it ('hierhand schema -o diagrams/diagram.schema.json') fails here."""
    assert SHIPPED_SCHEMA.read_text(encoding="utf-8") == schema_text(), \
        "run: hierhand schema -o diagrams/diagram.schema.json"


@pytest.mark.parametrize("path", sorted(DIAGRAMS.glob("*.yaml")), ids=lambda p: p.name)
def test_every_shipped_diagram_names_the_schema_and_validates(path):
    text = path.read_text(encoding="utf-8")
    assert text.splitlines()[0] == SCHEMA_LINE
    validator = jsonschema.Draft202012Validator(json.loads(SHIPPED_SCHEMA.read_text(encoding="utf-8")))
    assert [e.message for e in validator.iter_errors(yaml.safe_load(text))] == []


def test_hierhand_schema_writes_the_file_and_refuses_a_folder(tmp_path):
    out = tmp_path / "s.json"
    proc = subprocess.run([sys.executable, "-m", "hierhand", "schema", "-o", str(out)], capture_output=True,
                          text=True, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert out.read_text(encoding="utf-8") == schema_text()
    assert "HandPlant" in json.loads(out.read_text(encoding="utf-8"))["$defs"]["params"]
    proc = subprocess.run([sys.executable, "-m", "hierhand", "schema", "-o", str(tmp_path)], capture_output=True,
                          text=True, cwd=tmp_path)
    assert proc.returncode == 2 and len(proc.stderr.splitlines()) == 1 and "folder" in proc.stderr
