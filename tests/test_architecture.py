"""The core stays free of widgets: app/ imports no ui, no pyqtgraph and Qt only in the worker."""

from __future__ import annotations

import ast
import functools
import os
import subprocess
import sys
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


# --- No import circles; every module imports alone (issue 22) ------------------------------------

ROOT = APP.parent
PACKAGES = ("app", "ui")
# The circles that remain, each as its set of modules; this list must be exactly what the code
# holds, so that removing a circle fails this test until its line here goes too.
# Issue 22: none left (the worker's parts see each other through the narrow views of
# app/link/host.py, which imports no part).
KNOWN_CIRCLES: list[frozenset[str]] = []


@functools.cache
def _parsed(path: Path) -> ast.Module:  # each file once for all the checks below (read-only)
    return ast.parse(path.read_text(encoding="utf-8"), filename=str(path))


def _module_names(root: Path, packages: tuple[str, ...]) -> dict[str, Path]:
    names: dict[str, Path] = {}
    for package in packages:
        for path in sorted((root / package).rglob("*.py")):
            parts = list(path.relative_to(root).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts.pop()
            names[".".join(parts)] = path
    return names


def _with_packages(name: str, known: dict[str, Path]) -> set[str]:
    """The module ``name`` names (an attribute imported from a module: the module) and every
    package above it, those of ``known``."""
    while name and name not in known:
        name = name.rpartition(".")[0]
    found = set()
    while name:
        if name in known:
            found.add(name)
        name = name.rpartition(".")[0]
    return found


def _import_targets(module: str, path: Path, known: dict[str, Path]) -> set[str]:
    """The modules of ``known`` that importing ``module`` runs: every import statement anywhere in
    it (module level, under ``if TYPE_CHECKING:``, inside functions), and the packages above each
    module named (importing ``a.b.c`` runs ``a/b/__init__.py``; so does loading ``module`` itself)."""

    def with_packages(name: str) -> set[str]:
        return _with_packages(name, known)

    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    targets = with_packages(package)
    for node in ast.walk(_parsed(path)):
        if isinstance(node, ast.Import):
            for alias in node.names:
                targets |= with_packages(alias.name)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                up = package.split(".")[: len(package.split(".")) - (node.level - 1)]
                base = ".".join(up + ([node.module] if node.module else []))
            for alias in node.names:
                targets |= with_packages(f"{base}.{alias.name}")
    targets.discard(module)
    return targets


def import_circles(root: Path, packages: tuple[str, ...] = PACKAGES) -> list[frozenset[str]]:
    """The strongly connected groups of two or more modules in the import graph (Tarjan)."""
    known = _module_names(root, packages)
    graph = {name: sorted(_import_targets(name, path, known)) for name, path in known.items()}
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    circles: list[frozenset[str]] = []

    def visit(name: str) -> None:  # recursion depth is bounded by the longest import chain
        index[name] = low[name] = len(index)
        stack.append(name)
        for target in graph[name]:
            if target not in index:
                visit(target)
                low[name] = min(low[name], low[target])
            elif target in stack:
                low[name] = min(low[name], index[target])
        if low[name] == index[name]:
            group = {stack.pop()}
            while name not in group:
                group.add(stack.pop())
            if len(group) > 1:
                circles.append(frozenset(group))

    for name in graph:
        if name not in index:
            visit(name)
    return circles


def test_no_import_circles_but_the_known_ones() -> None:
    circles = sorted(sorted(circle) for circle in import_circles(ROOT))
    assert circles == sorted(sorted(circle) for circle in KNOWN_CIRCLES)


def test_the_circle_finder_sees_type_only_lazy_and_package_circles(tmp_path: Path) -> None:
    pkg = tmp_path / "pkg"
    (pkg / "sub").mkdir(parents=True)
    (pkg / "__init__.py").write_text("", encoding="utf-8")
    (pkg / "a.py").write_text(
        "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from pkg.b import B\n", encoding="utf-8"
    )
    (pkg / "b.py").write_text("from pkg import a\nB = 1\n", encoding="utf-8")
    (pkg / "e.py").write_text("def f() -> None:\n    from pkg import f\n", encoding="utf-8")
    (pkg / "f.py").write_text("import pkg.e\n", encoding="utf-8")
    (pkg / "sub" / "__init__.py").write_text("from .c import C\n", encoding="utf-8")
    (pkg / "sub" / "c.py").write_text("C = 1\n", encoding="utf-8")  # loading it runs sub/__init__.py
    (pkg / "sub" / "d.py").write_text("from pkg.b import B\n", encoding="utf-8")  # no circle
    found = sorted(sorted(circle) for circle in import_circles(tmp_path, ("pkg",)))
    assert found == [["pkg.a", "pkg.b"], ["pkg.e", "pkg.f"], ["pkg.sub", "pkg.sub.c"]]


# Imports each module named on the command line with none of the project's modules loaded before
# it (third-party ones stay loaded: they are not what is checked, and reloading Qt is slow); prints
# one line per module that fails.
_IMPORT_ALONE = """
import importlib, sys, traceback
roots = set(sys.argv[1].split(","))
for name in sys.argv[2:]:
    for loaded in [m for m in sys.modules if m.split(".")[0] in roots]:
        del sys.modules[loaded]
    try:
        importlib.import_module(name)
    except BaseException as exc:
        line = traceback.format_exception_only(type(exc), exc)[-1].strip()
        print(f"{name}: {line}")
"""


def modules_that_fail_alone(root: Path, packages: tuple[str, ...], cache: Path) -> list[str]:
    env = dict(os.environ, PYTHONPYCACHEPREFIX=str(cache), PYTHONPATH=str(root))
    env.pop("PYTHONDONTWRITEBYTECODE", None)  # each module is compiled once, not once per import
    names = list(_module_names(root, packages))
    done = subprocess.run(
        [sys.executable, "-c", _IMPORT_ALONE, ",".join(packages), *names],
        cwd=root,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    return done.stdout.splitlines()


def test_every_module_imports_alone(tmp_path: Path) -> None:
    assert modules_that_fail_alone(ROOT, PACKAGES, tmp_path) == []


def test_the_alone_check_sees_a_module_that_needs_another_first(tmp_path: Path) -> None:
    pkg = tmp_path / "pkg"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("", encoding="utf-8")
    (pkg / "first.py").write_text("from pkg.second import TWO\nONE = 1\n", encoding="utf-8")
    (pkg / "second.py").write_text("from pkg.first import ONE\nTWO = ONE + 1\n", encoding="utf-8")
    failed = modules_that_fail_alone(tmp_path, ("pkg",), tmp_path / "cache")
    assert [line.split(":")[0] for line in failed] == ["pkg.first", "pkg.second"]


# --- One of each (issue 22) -------------------------------------------------------------------------


def _top_level(path: Path) -> list[ast.stmt]:
    return _parsed(path).body


def test_no_two_classes_share_a_name() -> None:
    """Two classes of one name (two ``UploadRun``, two ``ProfileError``) are two ideas under one
    word: a reader, an import and an ``except`` can take the wrong one."""
    homes: dict[str, list[str]] = {}
    for name, path in _module_names(ROOT, PACKAGES).items():
        for node in _top_level(path):
            if isinstance(node, ast.ClassDef) and not node.name.startswith("_"):
                homes.setdefault(node.name, []).append(name)
    assert {name: where for name, where in homes.items() if len(where) > 1} == {}


def test_the_gvs_teachpad_reserves_are_named_only_in_registers() -> None:
    """A GV number given a name anywhere but app/protocol/registers.py (the simulator, the
    controller's model, excepted) is a reserved register defined twice, or one to move there."""
    named: list[str] = []
    for name, path in _module_names(ROOT, PACKAGES).items():
        if name == "app.protocol.registers" or name.startswith("app.sim"):
            continue
        for node in _top_level(path):
            target: ast.expr | None = node.target if isinstance(node, ast.AnnAssign) else None
            if isinstance(node, ast.Assign) and len(node.targets) == 1:
                target = node.targets[0]
            value = getattr(node, "value", None)
            literal = isinstance(value, ast.Constant) and isinstance(value.value, int)
            if isinstance(target, ast.Name) and "GV" in target.id.upper().split("_") and literal:
                named.append(f"{name}.{target.id}")
    assert named == []


def test_no_module_re_exports_what_it_imports() -> None:
    """A name is imported from the module that defines it: no ``__all__`` entry and no
    ``import x as x`` hands on an imported name (strict mypy refuses every other way), so no
    module stays an import's home "so older imports keep working" (that made circles)."""
    assert re_exports(ROOT) == []


def re_exports(root: Path) -> list[str]:
    """``module.name`` for each imported name a module of app/ or ui/ hands on."""
    handed_on: list[str] = []
    for name, path in _module_names(root, PACKAGES).items():
        body = _top_level(path)
        imported: set[str] = set()
        exported: set[str] = set()
        for node in ast.walk(ast.Module(body=body, type_ignores=[])):
            if isinstance(node, ast.Import | ast.ImportFrom):
                for alias in node.names:
                    local = alias.asname or alias.name.split(".")[0]
                    imported.add(local)
                    if alias.asname is not None and alias.asname == alias.name.rpartition(".")[2]:
                        exported.add(local)
            elif isinstance(node, ast.Assign) and any(
                isinstance(target, ast.Name) and target.id == "__all__" for target in node.targets
            ):
                exported |= set(ast.literal_eval(node.value))
        defined = {
            target.id
            for node in body
            for target in ast.walk(node)
            if isinstance(target, ast.Name) and isinstance(target.ctx, ast.Store)
        } | {node.name for node in body if isinstance(node, ast.ClassDef | ast.FunctionDef)}
        handed_on += [f"{name}.{n}" for n in sorted(exported & imported - defined)]
    return handed_on
