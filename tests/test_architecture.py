"""The core stays free of widgets: app/ imports no ui, no pyqtgraph and Qt only in the worker."""

from __future__ import annotations

import ast
from pathlib import Path

APP = Path(__file__).resolve().parent.parent / "app"
QT_ALLOWED = {
    APP / "link" / name: {"PySide6.QtCore", "PySide6"}
    for name in ("worker.py", "robot_link.py", "link_port.py", "state.py")
}


# --- The tests mirror the code (issue 22) ---------------------------------------------------------
# tests/<area>/ holds the tests of app/<area>/, tests/ui/<area>/ those of ui/<area>/ (tests/ui/ the
# window's and ui/'s own modules), tests/benchmarks/ those of benchmarks/; tests/test_*.py those of
# app/'s own modules and of the suite itself. A test lives with the code it is about: a test of the
# link (the client, the worker, RobotLink driven without a window) in tests/link/. The folders below
# are no code's: they hold ways of testing, named for what they test with.
TESTS = Path(__file__).resolve().parent
SUPPORT_FOLDERS = {
    "fonts": "font sets for the layout tests (make test-fonts)",
    "soak": "make soak: random operator sessions on the real window",
    "integration": "end-to-end workflows across app/ (CLI, plan, points, link) against the simulator",
    "link/hostile": "the link against a malformed-answer server and a misbehaving relay",
    "link/serial": "the link over a serial line (a pty relay)",
}
TOP_PACKAGES = {"ui", "benchmarks"}  # mirrored from the repository's root; every other area is app/'s


def _unmirrored(tests: Path, support: set[str]) -> list[str]:
    """Test folders that name no package of the code (nor a support folder), or lack __init__.py."""
    root = tests.parent
    problems: list[str] = []
    for folder in sorted({p.parent for p in tests.rglob("*.py")} - {tests}):
        rel = folder.relative_to(tests)
        if "__pycache__" in rel.parts:
            continue
        if not (folder / "__init__.py").is_file():
            problems.append(f"tests/{rel.as_posix()} has no __init__.py")
        if any(rel.as_posix() == s or rel.as_posix().startswith(s + "/") for s in support):
            continue
        code = root / rel if rel.parts[0] in TOP_PACKAGES else root / "app" / rel
        if not (code / "__init__.py").is_file():
            problems.append(f"tests/{rel.as_posix()} mirrors no package ({code.relative_to(root)})")
    return problems


def test_every_test_folder_mirrors_a_package_of_the_code() -> None:
    assert _unmirrored(TESTS, set(SUPPORT_FOLDERS)) == []


def test_the_mirror_check_sees_a_folder_of_no_package(tmp_path: Path) -> None:
    tests = tmp_path / "tests"
    for package in ("app/link", "ui/panels"):
        (tmp_path / package).mkdir(parents=True)
        (tmp_path / package / "__init__.py").touch()
    for folder in ("link", "ui/panels", "client", "ui/widgets", "link/hostile"):
        (tests / folder).mkdir(parents=True, exist_ok=True)
        (tests / folder / "test_x.py").touch()
        if folder != "ui/widgets":
            (tests / folder / "__init__.py").touch()
    (tests / "ui" / "__init__.py").touch()
    assert _unmirrored(tests, {"link/hostile"}) == [
        "tests/client mirrors no package (app/client)",
        "tests/ui mirrors no package (ui)",
        "tests/ui/widgets has no __init__.py",
        "tests/ui/widgets mirrors no package (ui/widgets)",
    ]


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
