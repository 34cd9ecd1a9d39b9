"""Double-clicking a cell the role may not edit says why (issue 21: nothing happened), in both
languages; the cell does not open and nothing changes."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from PySide6.QtCore import Qt
from PySide6.QtTest import QTest
from PySide6.QtWidgets import QAbstractItemView, QTableView

from app.safety.roles import Role
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    app_settings_fixture,
    fast_reconnect_fixture,
    link_fixture,
    project_dialogs_fixture,
    translator_fixture,
    window_fixture,
)
from ui.controllers.safety_menu import SafetyMenu
from ui.models.point_columns import COL_NAME

pytestmark = [pytest.mark.timeout(60), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]

SAMPLE = Path(__file__).resolve().parents[3] / "resources" / "samples" / "demo.teachpad.json"
PASSWORD = "cell-42"


@pytest.fixture(name="menu")
def menu_fixture(window: Any) -> SafetyMenu:
    menu: SafetyMenu = window.safety_menu
    store = menu.safety.session.store
    store.scrypt_n = 2**4
    for role in (Role.ADMINISTRATOR, Role.ENGINEER):
        store.set_password(role, PASSWORD, by=Role.ADMINISTRATOR)
    return menu


def double_click(qtbot: Any, view: QTableView, row: int, column: int) -> None:
    view.show()
    qtbot.waitExposed(view)
    view.scrollTo(view.model().index(row, column))
    center = view.visualRect(view.model().index(row, column)).center()
    QTest.mouseClick(view.viewport(), Qt.MouseButton.LeftButton, pos=center)  # as a hand does
    QTest.mouseDClick(view.viewport(), Qt.MouseButton.LeftButton, pos=center)


def test_the_points_table_says_why_a_cell_does_not_open(qtbot: Any, menu: SafetyMenu, window: Any) -> None:
    assert window.project.open_file(SAMPLE)
    window.show()
    window.show_tab("points")
    panel = window.points_panel
    name = window.project.points_model.ledger[0].name
    double_click(qtbot, panel.table, 0, COL_NAME)
    assert panel.table.state() is not QAbstractItemView.State.EditingState
    text = panel.status.text()
    assert text.startswith("This cell cannot be edited: Needs the engineer role"), text
    assert window.project.points_model.ledger[0].name == name
    menu.safety.login(Role.ENGINEER, PASSWORD)
    panel.show_message("")
    double_click(qtbot, panel.table, 0, COL_NAME)
    assert panel.table.state() is QAbstractItemView.State.EditingState  # the engineer edits
    assert panel.status.text() == ""


def test_the_planner_says_why_in_chinese(qtbot: Any, menu: SafetyMenu, window: Any, translator: Any) -> None:
    assert window.project.open_file(SAMPLE)
    assert translator.set_language("zh_CN")
    window.show()
    window.show_tab("planner")
    planner = window.planner_panel
    double_click(qtbot, planner.plan_view, 0, 0)
    text = planner.status.text()
    assert text.startswith("无法编辑此单元格：") and "工程师" in text, text
    assert not any("a" <= c.lower() <= "z" for c in text), text
