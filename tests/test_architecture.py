"""The core stays free of widgets: app/ imports no ui, no pyqtgraph and Qt only in the worker."""

from __future__ import annotations

import ast
from pathlib import Path

APP = Path(__file__).resolve().parent.parent / "app"
QT_ALLOWED = {
    APP / "link" / name: {"PySide6.QtCore", "PySide6"}
    for name in ("worker.py", "robot_link.py", "link_port.py", "state.py")
}


def _imports(path: Path) -> set[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    names: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.add(node.module)
            if node.module == "PySide6":
                names.update(f"PySide6.{alias.name}" for alias in node.names)
    return names


def test_app_imports_no_widgets_and_qt_only_in_the_worker() -> None:
    offenders: list[str] = []
    files = sorted(APP.rglob("*.py"))
    assert files, "app/ has no modules?"
    for path in files:
        for name in _imports(path):
            root = name.split(".")[0]
            gui = root in {"ui", "pyqtgraph"}
            qt = root in {"PySide6", "shiboken6"} and name not in QT_ALLOWED.get(path, set())
            if gui or qt:
                offenders.append(f"{path.relative_to(APP.parent)} imports {name}")
    assert offenders == []


def test_the_checker_sees_a_widget_import(tmp_path: Path) -> None:
    bad = tmp_path / "bad.py"
    bad.write_text("from PySide6 import QtWidgets\nimport ui.main_window\n", encoding="utf-8")
    assert {"PySide6.QtWidgets", "ui.main_window"} <= _imports(bad)
