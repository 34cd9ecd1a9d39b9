"""Hidden tabs are built on first show: the window's first paint does not wait for them."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path
from typing import Any

import pytest
from PySide6.QtWidgets import QLabel, QTabWidget

from app.safety.roles import Role
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    app_settings_fixture,
    fast_reconnect_fixture,
    link_fixture,
    project_dialogs_fixture,
    translator_fixture,
    window_fixture,
)
from ui.main_window import TAB_PLANNER, TAB_POINTS, MainWindow
from ui.window_tabs import LazyTab

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


# --- Points and Planner: built on first show, gated from the moment they exist ------------------

PASSWORD = "cell-42"
CHEAP_SCRYPT = 2**4  # tests only


def _passwords(window: MainWindow) -> Any:
    store = window.safety_menu.safety.session.store
    store.scrypt_n = CHEAP_SCRYPT
    store.set_password(Role.ENGINEER, PASSWORD, by=Role.ADMINISTRATOR)
    return window.safety_menu.safety


def test_points_and_planner_are_built_when_their_tab_is_shown(qtbot: Any, window: MainWindow) -> None:
    tabs = window.work_tabs
    assert not window.points_tab.built and not window.planner_tab.built
    assert [tabs.tabText(i) for i in range(3)] == ["Monitor", "Points", "Planner"]  # titled before
    window.show_tab("planner")
    assert window.planner_tab.built and not window.points_tab.built
    assert tabs.currentIndex() == TAB_PLANNER and tabs.currentWidget() is window.planner_panel
    assert tabs.tabText(TAB_PLANNER) == "Planner"
    tabs.setCurrentIndex(TAB_POINTS)  # a click on the tab does the same
    assert window.points_tab.built and tabs.currentWidget() is window.points_panel
    assert tabs.indexOf(window.points_panel) == TAB_POINTS and tabs.count() == 4


def test_a_tab_built_while_the_operator_is_in_force_is_gated(qtbot: Any, window: MainWindow) -> None:
    safety = _passwords(window)
    assert safety.role is Role.OPERATOR and not window.points_tab.built
    window.show_tab("points")  # built now, with the operator in force
    points = window.points_panel
    assert not points.action_add.isEnabled() and "engineer" in points.action_add.toolTip()
    assert not points.table.editTriggers()
    planner = window.planner_panel  # built on access, also gated at once
    assert not planner.planner_actions["add_plan"].isEnabled()
    safety.login(Role.ENGINEER, PASSWORD)  # and both follow the role afterwards
    assert points.action_add.isEnabled() and points.table.editTriggers()
    assert planner.planner_actions["add_plan"].isEnabled()
    safety.logout()
    assert not points.action_add.isEnabled() and not planner.planner_actions["add_plan"].isEnabled()


def test_a_tab_built_for_an_engineer_is_editable_and_checked(qtbot: Any, window: MainWindow) -> None:
    safety = _passwords(window)
    safety.login(Role.ENGINEER, PASSWORD)
    points = window.points_panel
    assert points.action_add.isEnabled() and points.move_check is not None  # the envelope's check
    assert window.planner_panel.planner_actions["add_plan"].isEnabled()


def test_a_lazily_built_panel_gets_what_the_window_gave_before(qtbot: Any, window: MainWindow) -> None:
    def confirm(_title: str, _question: str) -> bool:
        return False

    window.confirm = confirm  # before the panels exist
    assert not window.points_tab.built
    assert window.points_panel._confirm is confirm and window.planner_panel._confirm is confirm


# --- LazyTab itself -----------------------------------------------------------------------------


def test_lazy_tab_builds_once_in_place_and_runs_its_callbacks_before_the_swap(qtbot: Any) -> None:
    tabs = QTabWidget()
    qtbot.addWidget(tabs)
    tabs.addTab(QLabel("first"), "first")
    built: list[QLabel] = []

    def build() -> QLabel:
        built.append(QLabel("lazy"))
        return built[-1]

    tab: LazyTab[QLabel] = LazyTab(tabs, build, "Lazy")
    tabs.setTabText(1, "lazy")
    tabs.addTab(QLabel("last"), "last")
    seen: list[tuple[QLabel, int]] = []
    tab.on_built(lambda panel: seen.append((panel, tabs.indexOf(panel))))
    assert not built and tab.widget.objectName() == "LazyPlaceholder"
    panel = tab.panel
    assert built == [panel] and tab.panel is panel  # once
    assert seen == [(panel, -1)]  # the callback ran before the panel was in the tab
    assert tabs.indexOf(panel) == 1 and tabs.tabText(1) == "lazy" and tabs.count() == 3
    assert tabs.currentIndex() == 0  # asking for it does not bring it to the front
    late: list[QLabel] = []
    tab.on_built(late.append)  # after the build: called at once
    assert late == [panel]


def test_lazy_tab_refuses_to_be_asked_for_while_it_is_built(qtbot: Any) -> None:
    tabs = QTabWidget()
    qtbot.addWidget(tabs)
    holder: list[LazyTab[QLabel]] = []

    def build() -> QLabel:
        return holder[0].panel  # a bug: the panel asks for itself

    holder.append(LazyTab(tabs, build, "Loop"))
    with pytest.raises(RuntimeError, match="while it was being built"):
        holder[0].panel  # noqa: B018 - builds it
