"""Hidden tabs are built on first show: the window's first paint does not wait for them."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path
from typing import Any

from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    app_settings_fixture,
    fast_reconnect_fixture,
    link_fixture,
    project_dialogs_fixture,
    translator_fixture,
    window_fixture,
)
from ui.main_window import MainWindow

ROOT = Path(__file__).resolve().parents[2]


def test_the_3d_view_is_built_when_its_tab_comes_to_the_front(qtbot: Any, window: MainWindow) -> None:
    host = window.view3d
    assert not host.built
    tabs = window.work_tabs
    index = tabs.count() - 1
    assert tabs.tabText(index) == "3D"
    tabs.setCurrentIndex(index)
    assert host.built and tabs.currentWidget() is host.panel and tabs.indexOf(host.panel) == index
    assert tabs.tabText(index) == "3D"


def test_asking_for_the_panel_builds_it_in_its_tab(qtbot: Any, window: MainWindow) -> None:
    tabs = window.work_tabs
    count, current = tabs.count(), tabs.currentIndex()
    panel = window.view3d.panel
    assert tabs.count() == count and tabs.currentIndex() == current  # nothing else moved
    assert tabs.indexOf(panel) == count - 1


def test_building_the_window_does_not_import_the_3d_view_nor_pyqtgraph() -> None:
    code = textwrap.dedent("""
        import sys, tempfile
        from pathlib import Path
        from PySide6.QtWidgets import QApplication
        app = QApplication([])
        from app.link.robot_link import RobotLink
        from ui.main_window import MainWindow
        from ui.settings import AppSettings
        tmp = Path(tempfile.mkdtemp())
        link = RobotLink()
        w = MainWindow(link, AppSettings.from_file(tmp / "s.ini"), autosave_dir=tmp / "a")
        print("view3d_panel" if "ui.panels.view3d_panel" in sys.modules else "lazy")
        print("pyqtgraph" if "pyqtgraph" in sys.modules else "lazy")
        w.close(); link.shutdown()
    """)
    out = subprocess.run(
        [sys.executable, "-c", code],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=60,
        env={**__import__("os").environ, "QT_QPA_PLATFORM": "offscreen"},
        check=False,
    )
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.strip().splitlines()[-2:] == ["lazy", "lazy"]  # neither the 3D view nor pyqtgraph
