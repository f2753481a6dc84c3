"""The framework stands alone: no module of ``blocks`` imports ``hierhand``, and importing the
framework's command line and sweeps loads no application code."""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_no_framework_module_imports_the_application():
    offenders = []
    for path in sorted((ROOT / "blocks").rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            names = ([a.name for a in node.names] if isinstance(node, ast.Import)
                     else [node.module or ""] if isinstance(node, ast.ImportFrom) and node.level == 0 else [])
            offenders += [f"{path.relative_to(ROOT)}:{node.lineno}" for n in names if n.split(".")[0] == "hierhand"]
    assert not offenders


def test_importing_the_command_line_and_sweeps_loads_no_application_code():
    code = ("import sys, blocks.cli, blocks.sweep, blocks.sweep.plan, blocks.sweep.plot; "
            "print(sorted(m for m in sys.modules if m.split('.')[0] in ('hierhand', 'distributed', 'matplotlib')))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True)
    assert out.stdout.strip() == "[]"
