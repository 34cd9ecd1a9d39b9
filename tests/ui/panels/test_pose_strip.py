"""The screen an operator can trust, with the typed fake link: the pose strip, staleness in the
control bar / status panel / monitor, fixed widths in both languages, plots that keep time, the
alarm banner and list, and the alarm hold of the motion controller."""

from __future__ import annotations

import datetime as dt
import time
from collections.abc import Iterator
from typing import Any

import pytest
from PySide6.QtCore import QEvent, QObject
from PySide6.QtGui import QUndoStack
from PySide6.QtWidgets import QApplication, QMainWindow, QWidget

from app.link.ops import GoZero, JogPress, Stop
from app.models import ControllerStatus, Pose
from app.points.project_model import Project
from app.protocol.enums import Alarm, ControllerMode, ProgramState, TeachFrame
from tests.ui.fake_link import FakeLink
from tests.ui.pendant_support import translator_fixture  # noqa: F401 - fixture
from ui.controllers.motion import MotionController
from ui.controllers.plan_run_controller import PlanRunController
from ui.models.points_model import PointsModel
from ui.panels.alarm_banner import AlarmBanner
from ui.panels.alarm_list import COL_ADVICE, COL_CLEARED, COL_MEANING, COL_RAISED, AlarmListPanel
from ui.panels.control_bar import ControlBar
from ui.panels.jog_panel import JogPanel
from ui.panels.monitor_panel import MonitorPanel
from ui.panels.pose_strip import PoseStrip
from ui.panels.program_panel import ProgramPanel
from ui.panels.status_panel import StatusPanel
from ui.panels.step_panel import StepPanel
from ui.widgets_common import LEVEL_OFF

POSE = Pose(512.25, -3.5, 400.0, 180.0, 0.0, -90.0)


def status(
    mode: int = ControllerMode.AUTO, program: int = ProgramState.STOPPED, alarms: int = 0
) -> ControllerStatus:
    return ControllerStatus(mode, program, Alarm(alarms), 0xFF)


def poll(link: FakeLink, pose: Pose = POSE, st: ControllerStatus | None = None) -> None:
    """One good poll, the way RobotLink feeds its state."""
    link.state.set_pose(pose)
    link.state.set_status(st or status())
    link.state.note_good_poll(time.monotonic())


@pytest.fixture
def link(qtbot: Any) -> Iterator[FakeLink]:
    fake = FakeLink(connected=True)
    yield fake
    fake.set_connected(False)  # stops the state's freshness timer


@pytest.fixture
def strip(qtbot: Any, link: FakeLink) -> PoseStrip:
    widget = PoseStrip()
    qtbot.addWidget(widget)
    widget.bind(link.state)
    widget.show()
    return widget


# --- the pose strip ---------------------------------------------------------------------
def test_the_strip_shows_pose_mode_and_program_live(strip: PoseStrip, link: FakeLink) -> None:
    assert strip.freshness_text() == "stale" and strip.value_text("X") == "—"
    poll(link, st=status(ControllerMode.MANUAL, ProgramState.RUNNING))
    assert strip.is_live() and strip.freshness_text() == "live"
    shown = [strip.value_text(a) for a in "XYZABC"]
    assert shown == ["512.25", "-3.50", "400.00", "180.00", "0.00", "-90.00"]
    assert strip.mode_chip.text() == "manual" and strip.program_chip.text() == "running"
    assert strip.values["X"].property("stale") is False


def test_the_strip_goes_stale_after_silence_and_live_again(
    qtbot: Any, strip: PoseStrip, link: FakeLink
) -> None:
    link.state.set_freshness_limit(0.05)
    poll(link)
    assert strip.is_live()
    # no poll: the state's own timer turns the values stale; they keep their last value, greyed
    qtbot.waitUntil(lambda: strip.freshness_text().startswith("stale "), timeout=2000)
    assert strip.value_text("X") == "512.25" and strip.values["X"].property("stale") is True
    assert strip.mode_chip.text() == "unknown" and strip.program_chip.text() == "unknown"
    assert strip._age_timer.isActive()  # the age counts up while stale and shown
    poll(link)
    assert strip.freshness_text() == "live" and strip.mode_chip.text() == "auto"
    assert not strip._age_timer.isActive()


def test_the_strip_names_the_link_state(strip: PoseStrip, link: FakeLink) -> None:
    poll(link)
    link.set_connected(False)
    assert strip.freshness_text() == "link down" and strip.mode_chip.text() == "unknown"
    assert strip.value_text("Z") == "400.00" and strip.values["Z"].property("stale") is True


class _Paints(QObject):
    """Counts the paint events a widget gets."""

    def __init__(self, widget: QWidget) -> None:
        super().__init__()
        self.count = 0
        widget.installEventFilter(self)

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        if event.type() == QEvent.Type.Paint:
            self.count += 1
        return False


def test_a_new_value_repaints_its_number_not_the_strip(qtbot: Any, strip: PoseStrip, link: FakeLink) -> None:
    """The numbers are opaque (live: the strip's own colour; stale: the stale colour), so a new
    value repaints the number alone: a see-through label repainted the strip under it too."""
    poll(link)
    qtbot.waitExposed(strip)
    QApplication.processEvents()
    under, number = _Paints(strip), _Paints(strip.values["X"])
    for i in range(3):
        poll(link, Pose(100.0 + i, -3.5, 400.0, 180.0, 0.0, -90.0))
        strip._show_pose()  # the display frame
        qtbot.waitUntil(lambda i=i: number.count > i, timeout=2000)
    assert strip.value_text("X") == "102.00"
    assert under.count == 0
    for label in strip.values.values():
        assert label.autoFillBackground()
        assert label.palette().window().color().alpha() == 255
    link.state.set_freshness_limit(0.01)
    qtbot.waitUntil(lambda: not strip.is_live(), timeout=2000)
    stale = strip.values["X"].palette().window().color()
    assert stale.alpha() == 255 and stale != strip.palette().window().color()  # still looks stale


def _geometry(strip: PoseStrip, bar: ControlBar) -> list[Any]:
    QApplication.processEvents()  # let any relayout a text change asked for happen first
    parts = [
        strip.mode_chip,
        strip.program_chip,
        strip.freshness,
        *strip.values.values(),
        bar.stop_button,
        bar.mode_label,
    ]
    return [(w.x(), w.width(), w.height()) for w in parts]


def test_nothing_moves_when_the_texts_change(qtbot: Any, link: FakeLink, translator: Any) -> None:
    host = QWidget()
    qtbot.addWidget(host)
    strip, bar = PoseStrip(host), ControlBar(host)
    bar.move(0, 60)
    strip.bind(link.state)
    bar.bind(link.state)
    strip.resize(1300, strip.sizeHint().height())  # its full width: units and captions shown
    bar.resize(420, bar.sizeHint().height())
    host.resize(1400, 200)
    host.show()
    qtbot.waitExposed(host)
    poll(link, st=status(ControllerMode.MANUAL))
    seen: list[list[Any]] = []
    for language in ("en", "zh_CN"):
        assert translator.set_language(language)
        first = _geometry(strip, bar)
        seen.append(first)
        for mode in (ControllerMode.MODBUS_TEACH, ControllerMode.AUTO, 7, ControllerMode.MANUAL):
            poll(link, Pose(-1234.56, 0, 0, 0, 0, 0), status(mode, ProgramState.PAUSED))
            assert _geometry(strip, bar) == first, (language, mode)
        link.state.set_freshness_limit(0.01)
        qtbot.waitUntil(lambda: not strip.is_live(), timeout=2000)
        assert _geometry(strip, bar) == first
        if language == "zh_CN":  # no English fragment in the Chinese strip
            assert strip.mode_chip.text() == "未知" and strip.freshness_text().startswith("过期")
            assert "Mode" not in bar.mode_label.text()
        link.state.set_freshness_limit(10.0)
    assert seen[0] == seen[1]  # sized for both languages: a language switch moves nothing either
    assert not strip.compact, (strip.width(), strip._full_width)
    strip.resize(strip.sizeHint())  # a narrow window: no units, no captions, the same chips
    QApplication.processEvents()
    assert strip.compact and not strip.units["X"].isVisible()
    assert strip.freshness.width() == seen[0][2][1]


def test_a_long_mode_text_wraps_or_elides_and_the_tooltip_has_it(qtbot: Any, link: FakeLink) -> None:
    bar = ControlBar()
    qtbot.addWidget(bar)
    bar.bind(link.state)
    poll(link, st=status(ControllerMode.MODBUS_TEACH))
    lines = bar.mode_label.text().split("\n")
    metrics = bar.mode_label.fontMetrics()
    assert all(metrics.horizontalAdvance(line) <= bar.mode_label.width() for line in lines)
    assert "Modbus teach" in bar.mode_label.toolTip()


# --- staleness elsewhere ----------------------------------------------------------------
def test_the_status_panel_and_the_control_bar_do_not_look_live_when_stale(qtbot: Any, link: FakeLink) -> None:
    panel, bar = StatusPanel(), ControlBar()
    qtbot.addWidget(panel)
    qtbot.addWidget(bar)
    panel.bind(link.state)
    bar.bind(link.state)
    poll(link, st=status(ControllerMode.AUTO, ProgramState.RUNNING, alarms=int(Alarm.BRAKE)))
    assert panel.mode_label.text() == "auto" and bar.mode_text() == "auto"
    link.state.set_freshness_limit(0.02)
    qtbot.waitUntil(lambda: not panel.fresh, timeout=2000)
    assert panel.mode_label.text() == "unknown" and panel.mode_label.level() == LEVEL_OFF
    assert panel.program_label.text() == "unknown" and panel.program_label.level() == LEVEL_OFF
    assert panel.alarm_lamp_for(Alarm.BRAKE).is_active()  # an alarm is never hidden by silence
    assert "unknown" in bar.mode_label.text()


def test_the_monitor_greys_its_readouts_when_stale(qtbot: Any, link: FakeLink) -> None:
    panel = MonitorPanel()
    qtbot.addWidget(panel)
    panel.bind(link.state)
    poll(link)
    assert panel.readouts["X"].isEnabled()
    link.set_connected(False)
    assert not panel.readouts["X"].isEnabled() and not panel.fresh


# --- plots that keep time ---------------------------------------------------------------
def test_the_time_axis_advances_while_the_pose_is_constant(qtbot: Any, link: FakeLink) -> None:
    link.state.set_freshness_limit(30.0)
    panel = MonitorPanel()
    qtbot.addWidget(panel)
    panel.bind(link.state)
    panel.set_window(3.0)
    panel.show()
    qtbot.waitExposed(panel)
    poll(link)  # one pose, then the arm stands still: no more poseChanged
    samples = panel.sample_count
    curve = panel.curves["X"]
    # the axis counts seconds before now: the first sample moves left, the held value stays at 0
    qtbot.waitUntil(lambda: curve.xData is not None and len(curve.xData) > 1 and curve.xData[0] < -0.3)
    assert panel.sample_count > samples  # the last value held at the display rate
    assert curve.xData[-1] == pytest.approx(0.0, abs=0.05)
    assert panel.xyz_plot.getViewBox().viewRange()[0] == pytest.approx([-3.0, 0.0])  # the axis stays still
    # stale: nothing is appended any more (a gap, not a flat line that looks live) ...
    link.set_connected(False)
    held = panel.sample_count
    # ... but the axis keeps time: the newest sample moves away from "now"
    qtbot.waitUntil(lambda: curve.xData[-1] < -0.2, timeout=3000)
    assert panel.sample_count == held
    panel.hide()
    assert not panel.paint_timer_active  # hidden: idle


def test_the_top_view_fits_its_trace(qtbot: Any) -> None:
    panel = MonitorPanel()
    qtbot.addWidget(panel)
    panel.on_pose(POSE, t=0.0)
    panel.refresh()
    (x0, x1), (y0, y1) = panel.trace_view_range()
    assert x0 < POSE.x < x1 and y0 < POSE.y < y1 and x1 - x0 >= 50.0  # one point: readable labels
    panel.on_pose(Pose(900.0, 300.0, 0, 0, 0, 0), t=1.0)
    panel.refresh()
    (x0, x1), (y0, y1) = panel.trace_view_range()
    assert x0 <= POSE.x and x1 >= 900.0 and y0 <= POSE.y and y1 >= 300.0


# --- alarms -------------------------------------------------------------------------------
def test_the_banner_shows_while_an_alarm_is_set(qtbot: Any, link: FakeLink) -> None:
    window = QMainWindow()
    qtbot.addWidget(window)
    banner = AlarmBanner(window)  # laid over the window, no tool bar
    banner.bind(link.state)
    window.show()
    assert not banner.isVisible()
    poll(link, st=status(alarms=int(Alarm.ESTOP | Alarm.ENCODER)))
    assert banner.isVisible()
    text = banner.text()
    assert "ALARM: emergency stop, encoder angle alarm" in text
    assert "release the emergency stop button" in text and "held" in text
    poll(link, st=status(alarms=int(Alarm.ENCODER)))
    assert banner.isVisible() and "held" not in banner.text()  # the encoder alarm alone holds nothing
    poll(link, st=status(alarms=0))
    assert not banner.isVisible()


def test_the_banner_speaks_chinese(qtbot: Any, link: FakeLink, translator: Any) -> None:
    assert translator.set_language("zh_CN")
    banner = AlarmBanner()
    qtbot.addWidget(banner)
    banner.bind(link.state)
    poll(link, st=status(alarms=int(Alarm.SERVO) | (1 << 9)))
    text = banner.text()
    assert "伺服报警" in text and "报警位 9" in text
    assert not any(ch.isascii() and ch.isalpha() for ch in text.replace("STOP", ""))  # no English


def test_the_alarm_list_has_meaning_advice_and_times(qtbot: Any) -> None:
    panel = AlarmListPanel()
    qtbot.addWidget(panel)
    t = dt.datetime(2026, 11, 24, 9, 30, 5)
    panel.on_alarms(int(Alarm.ESTOP), t)
    bit = int(Alarm.ESTOP)
    assert "emergency stop circuit" in panel.cell(bit, COL_MEANING)
    assert "release the emergency stop" in panel.cell(bit, COL_ADVICE)
    assert panel.cell(bit, COL_RAISED) == "09:30:05" and panel.cell(bit, COL_CLEARED) == "active"
    panel.on_alarms(0, t + dt.timedelta(seconds=42))
    assert panel.cell(bit, COL_CLEARED) == "09:30:47"
    assert panel.cell(int(Alarm.SERVO), COL_RAISED) == "—"
    panel.on_alarms(1 << 12, t)
    assert panel.table.rowCount() == 6 and panel.cell(1 << 12, COL_RAISED) == "09:30:05"


def test_an_estop_holds_motion_but_not_stop(qtbot: Any, link: FakeLink) -> None:
    host = QWidget()
    qtbot.addWidget(host)
    bar, jog, step, program = ControlBar(host), JogPanel(host), StepPanel(host), ProgramPanel(host)
    motion = MotionController(
        link, bar, jog, step, program, PlanRunController(link, points=PointsModel(Project(), QUndoStack()))
    )
    holds: list[bool] = []
    motion.alarmHoldChanged.connect(holds.append)
    assert jog.axes_box.isEnabled()
    poll(link, st=status(alarms=int(Alarm.ESTOP)))
    assert motion.alarm_hold and holds == [True]
    assert not jog.axes_box.isEnabled() and not step.move_button.isEnabled()
    assert not program.run_button.isEnabled() and not bar.resume_button.isEnabled()
    assert bar.stop_button.isEnabled() and bar.pause_button.isEnabled()
    jog.jogPressed.emit(jog_request())  # an intent already on its way is dropped
    program.goZeroRequested.emit(None)
    assert link.named(JogPress) == [] and link.named(GoZero) == []
    bar.stopRequested.emit()
    assert link.kinds() == [Stop]
    poll(link, st=status(alarms=int(Alarm.BRAKE)))  # a brake alarm alone does not hold
    assert not motion.alarm_hold and jog.axes_box.isEnabled() and bar.resume_button.isEnabled()


def jog_request() -> Any:
    from app.link.types import JogRequest

    return JogRequest(TeachFrame.BASE, 0, 1, 20.0)


def test_the_strip_redraws_at_the_paint_rate_and_ends_on_the_latest_pose(
    qtbot: Any, strip: PoseStrip, link: FakeLink
) -> None:
    poll(link, Pose(1.0, 0, 0, 0, 0, 0))
    assert strip.value_text("X") == "1.00"  # the first pose at once
    for i in range(2, 50):  # a burst at the poll rate: coalesced
        poll(link, Pose(float(i), 0, 0, 0, 0, 0))
    assert strip.value_text("X") == "1.00"
    qtbot.waitUntil(lambda: strip.value_text("X") == "49.00", timeout=2000)
