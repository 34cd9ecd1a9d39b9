"""The child programs the benchmarks and tools start from a string (``python -c CHILD``: the
simulator in its own interpreter, a GUI in its own process) import what they name: a string is
not seen by the import checks, and one such child imported ``SimConfig`` from ``app.sim`` after
that package stopped handing names on -- every measurement with the simulator in its own process
was lost from ``make bench`` without a failing test."""

from __future__ import annotations

import ast
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
IMPORT_LINE = re.compile(r"^\s*(from app[\w.]* import [^\n#]+|import app[\w.]*[^\n#]*)", re.MULTILINE)


def _child_imports() -> dict[str, list[str]]:
    """File -> the ``app`` import lines inside its string constants (docstrings left out)."""
    found: dict[str, list[str]] = {}
    for path in sorted([*ROOT.glob("benchmarks/*.py"), *ROOT.glob("tools/*.py")]):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        docstrings = {
            id(node.body[0].value)
            for node in ast.walk(tree)
            if isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef)
            and node.body
            and isinstance(node.body[0], ast.Expr)
            and isinstance(node.body[0].value, ast.Constant)
        }
        for node in ast.walk(tree):
            if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docstrings:
                lines = [m.group(1).strip().rstrip("\\").strip() for m in IMPORT_LINE.finditer(node.value)]
                if lines:
                    found.setdefault(str(path.relative_to(ROOT)), []).extend(lines)
    return found


def test_the_children_started_from_strings_import_what_they_name() -> None:
    children = _child_imports()
    assert "benchmarks/gui_common.py" in children  # the finder sees the simulator's child
    lines = sorted({line for found in children.values() for line in found})
    done = subprocess.run(
        [sys.executable, "-c", "\n".join(lines)], cwd=ROOT, capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, (done.stderr[-1500:], children)
