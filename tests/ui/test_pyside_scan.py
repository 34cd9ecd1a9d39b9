"""ui/pyside_scan.py: TeachPad's modules entered in PySide's feature table before they are
imported (PySide then reads none of their sources; the effect itself is checked at start-up by
tests/ui/test_startup_deferred.py)."""

from __future__ import annotations

import sys
import types
from pathlib import Path

import pytest

from ui import pyside_scan
from ui.pyside_scan import IGNORED, USES_PYSIDE, own_module_names, skip_source_scan


def test_the_names_are_every_module_and_package_of_app_and_ui(tmp_path: Path) -> None:
    for path in (
        "app/__init__.py",
        "app/link/__init__.py",
        "app/link/worker.py",
        "ui/main.py",
        "ui/__init__.py",
    ):
        (tmp_path / path).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / path).write_text("")
    (tmp_path / "app" / "__pycache__").mkdir()
    (tmp_path / "app" / "__pycache__" / "stale.py").write_text("")  # not a package: skipped
    (tmp_path / "ui" / "notes.txt").write_text("")
    assert sorted(own_module_names(str(tmp_path))) == ["app", "app.link", "app.link.worker", "ui", "ui.main"]


def test_the_real_tree_names_the_window_and_the_link() -> None:
    names = set(own_module_names())
    assert {"ui.main", "ui.main_window", "app.link.robot_link", "app.points", "ui.panels.jog_panel"} <= names
    assert not any("__pycache__" in name for name in names)


def test_own_and_standard_modules_entered_once_others_left_alone(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    table = {"ui.main": -1, "json": 0, "numpy": 0}  # a name already there keeps its value
    monkeypatch.setitem(
        sys.modules, "shibokensupport.feature", types.SimpleNamespace(pyside_feature_dict=table)
    )
    entered = skip_source_scan()
    assert entered == len(set(own_module_names())) - 1 + len(sys.stdlib_module_names) - 1
    assert table["ui.main"] == -1 and table["json"] == 0 and table["numpy"] == 0
    assert table["app.link.robot_link"] == USES_PYSIDE == 0  # what PySide's scan would say
    assert table["typing"] == table["argparse"] == IGNORED == -1  # no standard module says "PySide6"
    assert "pymodbus" not in table and "json.decoder" not in table  # only names it can vouch for
    assert skip_source_scan() == 0  # nothing new the second time


def test_without_pysides_table_nothing_is_entered(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "shibokensupport.feature", types.SimpleNamespace())
    assert skip_source_scan() == 0
    monkeypatch.delitem(sys.modules, "shibokensupport.feature")
    assert pyside_scan.skip_source_scan() == 0
