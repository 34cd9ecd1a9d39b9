"""Main window: languages, remembered settings, display panels fed by the link, `teachpad` itself."""

from __future__ import annotations

from typing import Any

import pytest
from PySide6.QtCore import QSettings
from PySide6.QtGui import QImage

from app.connection import ConnectionSettings
from app.link.ops import JogPress, JogRelease, SetMode
from app.link.types import JogRequest, LinkState
from app.protocol.codec import WordOrder
from app.protocol.enums import Alarm, TeachFrame, WorkMode
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    SIGNAL_TIMEOUT_MS,
    app_settings_fixture,
    connect,
    connection_settings,
    fast_reconnect_fixture,
    is_state,
    link_fixture,
    project_dialogs_fixture,
    translator_fixture,
    window_fixture,
)
from tests.waits import loop_deadline
from ui.dialogs.connection_dialog import ConnectionDialog
from ui.i18n import qm_path
from ui.main import main
from ui.main_window import MainWindow
from ui.settings import AppSettings

pytestmark = [pytest.mark.timeout(60), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]


def _english(window: MainWindow) -> dict[str, str]:
    return {
        "tab": window.tabs.tabText(0),
        "stop": window.control_bar.stop_button.text(),
        "menu": window.menus.motion_menu.title(),
        "frame": window.jog_panel.frame_combo.itemText(0),
        "step": window.step_panel.axes_box.title(),
        "program": window.program_panel.run_button.text(),
    }


def test_builds_and_switches_language_at_runtime(
    qtbot: Any, sim: Any, window: MainWindow, app_settings: AppSettings
) -> None:
    assert qm_path("zh_CN").is_file()
    assert _english(window) == {
        "tab": "Jog",
        "stop": "STOP",
        "menu": "&Motion",
        "frame": "Base frame",
        "step": "Incremental move",
        "program": "Run program",
    }
    connect(qtbot, window.link, sim)
    qtbot.waitUntil(lambda: window.control_bar.mode_text() == "auto", timeout=SIGNAL_TIMEOUT_MS)
    window.menus.language_actions["zh_CN"].trigger()
    assert _english(window) == {
        "tab": "点动",
        "stop": "停止",
        "menu": "运动(&M)",
        "frame": "基坐标系",
        "step": "增量运动",
        "program": "运行程序",
    }
    assert window.control_bar.mode_text() == "自动"  # protocol texts too
    assert window.program_panel.mode_combo.itemText(2) == "循环"
    assert app_settings.language == "zh_CN"
    window.set_language("en")
    assert _english(window)["stop"] == "STOP" and window.control_bar.mode_text() == "auto"
    assert app_settings.language == "en"


def test_builds_in_chinese_from_the_start(
    qtbot: Any, link: Any, app_settings: AppSettings, translator: Any
) -> None:
    assert translator.set_language("zh_CN")
    window = MainWindow(link, app_settings, translator)
    qtbot.addWidget(window)
    assert window.tabs.tabText(1) == "增量运动"
    assert window.step_panel.speed_unit() == "转/分"
    assert window.menus.language_actions["zh_CN"].isChecked()
    assert "未连接" in window.motion_banner.text()


def test_alarms_show_in_the_status_panel_with_their_words(qtbot: Any, sim: Any, window: MainWindow) -> None:
    connect(qtbot, window.link, sim)
    lamp = window.status_panel.alarm_lamp_for(Alarm.ESTOP)
    assert lamp.text() == "emergency stop" and not lamp.is_active()
    sim.set_alarm(Alarm.ESTOP, True)
    qtbot.waitUntil(lambda: lamp.is_active(), timeout=SIGNAL_TIMEOUT_MS)
    events = [e.text for e in window.event_log.model.events()]
    assert any("emergency stop" in text for text in events)
    window.set_language("zh_CN")
    assert window.status_panel.alarm_lamp_for(Alarm.ESTOP).text() in ("急停", "emergency stop")
    sim.set_alarm(Alarm.ESTOP, False)
    qtbot.waitUntil(lambda: not lamp.is_active(), timeout=SIGNAL_TIMEOUT_MS)


def test_live_pose_reaches_the_monitor(qtbot: Any, sim: Any, window: MainWindow) -> None:
    connect(qtbot, window.link, sim)
    x = sim.state().pose[0]
    readout = window.monitor_panel.readouts["X"]
    qtbot.waitUntil(
        lambda: readout.value is not None and abs(readout.value - x) < 1e-3, timeout=SIGNAL_TIMEOUT_MS
    )
    window.link.submit(JogPress(JogRequest(TeachFrame.BASE, 0, 1, 100.0)))
    qtbot.waitUntil(lambda: readout.value is not None and readout.value > x + 5.0, timeout=SIGNAL_TIMEOUT_MS)
    window.link.submit(JogRelease())


def test_connect_disconnect_from_the_window(
    qtbot: Any, sim: Any, window: MainWindow, app_settings: AppSettings
) -> None:
    # poll_timeout None: the window remembers what the connection dialog offers, not a test knob
    settings = connection_settings(sim, unit=1, word_order=WordOrder.LOW_FIRST, poll_timeout=None)
    with qtbot.waitSignal(
        window.link.connectionChanged,
        check_params_cb=is_state(LinkState.CONNECTED),
        timeout=SIGNAL_TIMEOUT_MS,
    ):
        window.connect_with(settings)
    assert window.status_link.text() == "connected"
    assert str(sim.port) in window.windowTitle()
    assert app_settings.connection() == settings  # remembered
    with qtbot.waitSignal(
        window.link.connectionChanged,
        check_params_cb=is_state(LinkState.DISCONNECTED),
        timeout=SIGNAL_TIMEOUT_MS,
    ):
        window.menus.disconnect_action.trigger()
    assert not window.motion_enabled


def test_errors_reach_the_event_log(qtbot: Any, window: MainWindow) -> None:
    with qtbot.waitSignal(window.link.errorOccurred, timeout=SIGNAL_TIMEOUT_MS):
        window.menus.stop_action.trigger()  # not connected
    last = list(window.event_log.model.events())[-1]
    assert (last.level, last.source, last.text) == (
        "error",
        "stop",
        "Not connected to a controller: nothing was sent.",
    )


def test_window_state_is_remembered(
    qtbot: Any, link: Any, app_settings: AppSettings, translator: Any
) -> None:
    first = MainWindow(link, app_settings, translator, shutdown_link_on_close=False)
    qtbot.addWidget(first)
    first.show()
    first.resize(1700, 1050)
    first.traffic_dock.hide()
    first.close()
    assert app_settings.window_geometry() is not None and app_settings.window_state() is not None
    second = MainWindow(link, app_settings, translator, shutdown_link_on_close=False)
    qtbot.addWidget(second)
    assert second.traffic_dock.isHidden() and not second.event_dock.isHidden()


def test_connection_dialog_round_trip(qtbot: Any) -> None:
    settings = ConnectionSettings(
        host="10.0.0.7", port=1502, unit=3, word_order=WordOrder.HIGH_FIRST, timeout=0.5, monitor_only=True
    )
    dialog = ConnectionDialog(settings)
    qtbot.addWidget(dialog)
    assert dialog.settings() == settings
    dialog.transport_combo.setCurrentIndex(1)
    dialog.serial_edit.setText("/dev/ttyUSB0")
    rtu = dialog.settings()
    assert rtu.serial_port == "/dev/ttyUSB0" and rtu.transport == "rtu"


def test_settings_use_the_given_file(tmp_path: Any, qapp: Any) -> None:
    path = tmp_path / "t.ini"
    settings = AppSettings.from_file(path)
    settings.language = "zh_CN"
    settings.sync()
    assert QSettings(str(path), QSettings.Format.IniFormat).value("ui/language") == "zh_CN"
    assert AppSettings.from_file(path).language == "zh_CN"
    assert AppSettings.from_file(tmp_path / "none.ini").connection() == ConnectionSettings()


def test_teachpad_sim_screenshot(qtbot: Any, tmp_path: Any) -> None:
    png = tmp_path / "shot.png"
    args = ["--sim", "--screenshot", str(png), "--size", "1700x1000"]
    with loop_deadline("teachpad --sim --screenshot"):  # main()'s app.exec() runs in this process
        code = main([*args, "--settings", str(tmp_path / "teachpad.ini"), "--lang", "en"])
    assert code == 0
    image = QImage(str(png))
    assert not image.isNull() and image.width() >= 1600


def test_traffic_inspector_shows_decoded_frames_from_the_simulator(
    qtbot: Any, sim: Any, window: MainWindow
) -> None:
    """Raise the inspector, connect, send a command: its frames arrive decoded, as in the seed."""
    from ui.models.traffic_model import COL_BYTES, COL_MEANING

    window.show()
    window.traffic_dock.show()
    window.traffic_dock.raise_()
    connect(qtbot, window.link, sim)
    panel = window.traffic_panel
    model = panel.model

    def texts(column: int) -> list[str]:
        panel.flush()
        return [str(model.data(model.index(r, column))) for r in range(model.rowCount())]

    qtbot.waitUntil(lambda: any("read pose" in t for t in texts(COL_MEANING)), timeout=SIGNAL_TIMEOUT_MS)
    window.link.submit(SetMode(WorkMode.MANUAL))  # 444 <- 0, a 0x06 write
    qtbot.waitUntil(
        lambda: any("work mode manual (444 ← 0)" in t for t in texts(COL_MEANING)), timeout=SIGNAL_TIMEOUT_MS
    )
    # the hex column shows the bytes as the seed prints them: MBAP, then 01 06 01 BC 00 00
    assert any(t.endswith("01 06 01 BC 00 00") for t in texts(COL_BYTES))
    # hidden behind the event log, nothing is captured any more
    window.event_dock.raise_()
    qtbot.waitUntil(lambda: not window.docks.traffic_capture, timeout=SIGNAL_TIMEOUT_MS)
