"""A refused motion is said in the motion area itself, under the motion buttons -- where the
operator's eyes are when a press does nothing -- not only in the status bar and *Last command*
(issue 21). Against the simulator with a keep-in box: a refused step (the Step tab's own button)
reads in the line in both languages (re-worded on a language change) and the simulator never sees
a write; the jog guard's stop reads there; the link's refusal of go to zero in reduced-speed mode
reads there; the next accepted motion clears the line, and so does time."""

from __future__ import annotations

from typing import Any

import pytest
from PySide6.QtCore import Qt

from app.link.ops import GoZero
from app.link.types import StepFrame
from app.protocol import registers
from app.safety.box import Box
from app.safety.envelope import Envelope
from tests.ui.controllers.test_gui_motion import _envelope
from tests.ui.controllers.test_gui_roles import SAMPLE, menu_fixture  # noqa: F401 - fixture
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    SIGNAL_TIMEOUT_MS,
    app_settings_fixture,
    connect,
    fast_reconnect_fixture,
    jogging,
    link_fixture,
    project_dialogs_fixture,
    translator_fixture,
    window_fixture,
)
from tests.ui.test_messages import assert_chinese
from ui.controllers.safety_menu import SafetyMenu
from ui.panels import jog_refusal

pytestmark = [pytest.mark.timeout(60), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]

MARGIN_MM = 5.0  # the keep-in box's face this far beyond the arm along +Y


def _face_ahead(menu: SafetyMenu, y_limit: float) -> None:
    _envelope(menu, Envelope(keep_in=Box("cell", (-5000.0, -5000.0, -5000.0), (5000.0, y_limit, 5000.0))))


def _connected_at_rest(qtbot: Any, window: Any, sim: Any) -> float:
    connect(qtbot, window.link, sim, poll_timeout=1.0)
    qtbot.waitUntil(lambda: window.link.state.pose is not None, timeout=SIGNAL_TIMEOUT_MS)
    return float(window.link.state.pose.y)


def _step_tab(qtbot: Any, window: Any) -> Any:
    column = window.control_column
    column.tabs.setCurrentIndex(1)
    panel = window.step_panel
    panel.set_frame(StepFrame.BASE)
    panel.set_preset(10.0)
    qtbot.waitUntil(lambda: panel.plus_buttons[1].isEnabled(), timeout=SIGNAL_TIMEOUT_MS)
    return panel


def _under_the_buttons(window: Any) -> None:
    column = window.control_column
    line = column.refusal_line
    assert line.isVisible() and line.text()
    assert line.geometry().top() >= column.tabs.geometry().bottom()  # under the motion buttons


def test_a_refused_step_reads_under_the_buttons_in_both_languages(
    qtbot: Any, sim: Any, menu: SafetyMenu, window: Any
) -> None:
    y0 = _connected_at_rest(qtbot, window, sim)
    _face_ahead(menu, y0 + MARGIN_MM)
    panel = _step_tab(qtbot, window)
    line = window.control_column.refusal_line
    assert not line.isVisible()
    writes = len(sim.writes)
    with qtbot.waitSignal(menu.safety.motionRefused, timeout=SIGNAL_TIMEOUT_MS):
        qtbot.mouseClick(panel.plus_buttons[1], Qt.MouseButton.LeftButton)  # Y + 10 mm: through the face
    _under_the_buttons(window)
    assert "Y = " in line.text() and "is outside the allowed work space" in line.text(), line.text()
    window.set_language("zh_CN")  # the same refusal, worded again where it is shown
    assert_chinese(line.text())
    line.clear_refusal()
    with qtbot.waitSignal(menu.safety.motionRefused, timeout=SIGNAL_TIMEOUT_MS):
        qtbot.mouseClick(panel.plus_buttons[1], Qt.MouseButton.LeftButton)
    _under_the_buttons(window)
    assert_chinese(line.text())
    assert len(sim.writes) == writes  # at the simulator: the refused steps never went out
    # the next accepted motion clears it: a step away from the face goes out
    with qtbot.waitSignal(menu.safety.motionAccepted, timeout=SIGNAL_TIMEOUT_MS):
        qtbot.mouseClick(panel.minus_buttons[1], Qt.MouseButton.LeftButton)
    assert not line.isVisible() and not line.text()
    qtbot.waitUntil(lambda: len(sim.writes) > writes, timeout=SIGNAL_TIMEOUT_MS)


@pytest.mark.parametrize("language", ["en", "zh_CN"])
def test_the_jog_guards_stop_reads_under_the_jog_buttons(
    qtbot: Any, sim_factory: Any, menu: SafetyMenu, window: Any, language: str
) -> None:
    sim = sim_factory(watchdog=2.0)  # a stalled test process must not stop the jog first
    window.resize(1280, 800)
    y0 = _connected_at_rest(qtbot, window, sim)
    window.set_language(language)
    _face_ahead(menu, y0 + 30.0)
    panel = window.jog_panel
    qtbot.waitUntil(lambda: panel.axes_box.isEnabled(), timeout=SIGNAL_TIMEOUT_MS)
    button = panel.button(1, 1)  # Y+ toward the face
    with qtbot.waitSignal(window.link.jogGuardStopped, timeout=SIGNAL_TIMEOUT_MS):
        qtbot.mousePress(button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: not jogging(sim), timeout=SIGNAL_TIMEOUT_MS)
    assert y0 < sim.state().pose[1] < y0 + 30.0  # at the simulator: short of the face
    qtbot.mouseRelease(button, Qt.MouseButton.LeftButton)
    line = window.control_column.refusal_line
    _under_the_buttons(window)
    if language == "en":
        assert line.text().startswith("Jog stopped before the limit: Y = "), line.text()
    else:
        assert_chinese(line.text())
    # the six jog rows still fit at 1280×800: the hints under them gave the line their height
    qtbot.waitUntil(lambda: panel.axes_scroll.viewport().height() >= panel.axes_rows.sizeHint().height())
    assert not panel.keys_label.isVisible()


def test_go_to_zero_refused_in_reduced_speed_reads_in_the_motion_area(
    qtbot: Any, sim: Any, menu: SafetyMenu, window: Any, translator: Any
) -> None:
    _connected_at_rest(qtbot, window, sim)
    window.set_language("zh_CN")
    menu.reduced_action.setChecked(True)
    assert menu.safety.session.reduced
    writes = len(sim.writes)
    line = window.control_column.refusal_line
    with qtbot.waitSignal(window.link.errorOccurred, timeout=SIGNAL_TIMEOUT_MS):
        window.link.submit(GoZero(None))
    qtbot.waitUntil(line.isVisible, timeout=SIGNAL_TIMEOUT_MS)
    assert_chinese(line.text())
    assert not [w for w in sim.writes[writes:] if w.address == registers.REG_GO_ZERO]  # never written


def test_a_refusal_goes_stale(
    qtbot: Any, sim: Any, menu: SafetyMenu, window: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(jog_refusal, "REFUSAL_SHOWN_MS", 300)
    y0 = _connected_at_rest(qtbot, window, sim)
    _face_ahead(menu, y0 + MARGIN_MM)
    panel = _step_tab(qtbot, window)
    line = window.control_column.refusal_line
    with qtbot.waitSignal(menu.safety.motionRefused, timeout=SIGNAL_TIMEOUT_MS):
        qtbot.mouseClick(panel.plus_buttons[1], Qt.MouseButton.LeftButton)
    assert line.isVisible()
    qtbot.waitUntil(lambda: not line.isVisible(), timeout=SIGNAL_TIMEOUT_MS)
    assert not line.shown


def test_a_move_to_a_point_refused_reads_in_the_motion_area(
    qtbot: Any, sim: Any, menu: SafetyMenu, window: Any, translator: Any
) -> None:
    assert window.project.open_file(SAMPLE)
    _connected_at_rest(qtbot, window, sim)
    ledger = window.project.points_model.ledger
    target = max(ledger, key=lambda p: p.xyz[1])  # the point furthest along +Y
    _face_ahead(menu, target.xyz[1] - 10.0)
    window.set_language("zh_CN")
    panel = window.points_panel
    panel.select_rows([window.project.points_model.row_of(target.id)])
    writes = len(sim.writes)
    with qtbot.waitSignal(menu.safety.motionRefused, timeout=SIGNAL_TIMEOUT_MS):
        panel.move_to_selected()
    _under_the_buttons(window)
    assert_chinese(window.control_column.refusal_line.text())
    assert len(sim.writes) == writes  # at the simulator: nothing went out
