"""What the live views do (and do not do) per frame while the robot streams: the monitor's plots
take every other display frame, their time axis and vertical ranges keep still, the curves'
bounds hold their points, and live labels never re-lay out the window (issue 10)."""

from __future__ import annotations

import datetime as dt
import math
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest
from PySide6.QtCore import QEvent, QObject, Qt
from PySide6.QtWidgets import QApplication, QDockWidget, QMainWindow, QVBoxLayout, QWidget

from app.models import ControllerStatus, Pose
from app.protocol.datetime_regs import decode_clock, encode_clock
from app.protocol.enums import Alarm, ControllerMode, ProgramState
from benchmarks.traffic import Feed
from tests.ui.fake_link import FakeLink
from ui.display_clock import DISPLAY_INTERVAL_MS
from ui.panels.monitor_figures import PLOT_INTERVAL_MS
from ui.panels.monitor_panel import MonitorPanel
from ui.panels.monitor_plots import RANGE_MIN_SPAN, fit_range
from ui.panels.status_panel import StatusPanel
from ui.panels.traffic_panel import TrafficPanel
from ui.widgets.live_label import LiveLabel
from ui.window_status import WindowStatusBar

pytestmark = pytest.mark.qt_log_ignore("This plugin does not support propagateSizeHints")


class _Count(QObject):
    """Counts the events of one type that reach the object it watches."""

    def __init__(self, watched: QObject, kind: QEvent.Type) -> None:
        super().__init__()
        self.kind = kind
        self.count = 0
        watched.installEventFilter(self)

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        if event.type() == self.kind:
            self.count += 1
        return False


def _square(i: int) -> Pose:
    """The arm going round a 100 mm square at 200 mm/s, polled at 100 Hz, its C swinging a little."""
    d = (2.0 * i) % 400.0
    side, f = divmod(d, 100.0)
    x, y = ((f, 0.0), (100.0, f), (100.0 - f, 100.0), (0.0, 100.0 - f))[int(side)]
    return Pose(400.0 + x, y, 300.0, 180.0, 0.0, 90.0 + 5.0 * math.sin(i / 50.0))


class _Stream:
    """Feeds a monitor on a clock of its own: 100 Hz poses between display frames."""

    def __init__(self, panel: MonitorPanel) -> None:
        self.panel = panel
        self.now = panel._now()  # the clock the panel has used so far
        self.i = 0
        panel._now = lambda: self.now

    def frame(self) -> None:
        """The poses of one display frame, then the frame."""
        for _ in range(round(DISPLAY_INTERVAL_MS / 10)):
            self.i += 1
            self.now += 0.01
            self.panel.on_pose(_square(self.i))
        self.panel._tick()


@pytest.fixture
def monitor(qtbot: Any) -> Iterator[MonitorPanel]:
    panel = MonitorPanel()
    qtbot.addWidget(panel)
    panel.resize(1100, 640)
    panel.show()
    qtbot.waitExposed(panel)
    panel.refresh()  # the plots are built
    yield panel
    panel.close()


# --- vertical ranges ----------------------------------------------------------------------
def test_a_range_is_kept_while_the_values_stay_inside_and_use_a_third_of_it() -> None:
    first = fit_range(None, 400.0, 500.0)
    assert first[0] < 400.0 and first[1] > 500.0  # padded
    assert all(float(v).is_integer() for v in first)  # snapped to round values: still labels
    assert fit_range(first, 410.0, 495.0) == first  # inside: the same range, the axis keeps still
    assert fit_range(first, 420.0, 470.0) == first  # a third or more of it in use: kept
    moved = fit_range(first, 400.0, 530.0)  # a value left the range: a new one holds it
    assert moved != first and moved[0] <= 400.0 and moved[1] >= 530.0
    narrow = fit_range(first, 449.0, 451.0)  # the values use little of it: zoom in
    assert narrow[1] - narrow[0] < (first[1] - first[0]) / 3


def test_a_standing_arm_gets_the_minimum_span_not_its_noise_magnified() -> None:
    lo, hi = fit_range(None, 300.0, 300.0)
    assert lo < 300.0 < hi and hi - lo >= RANGE_MIN_SPAN
    assert fit_range((lo, hi), 300.001, 300.002) == (lo, hi)


# --- the monitor's frames -----------------------------------------------------------------
def test_the_plots_take_every_other_display_frame_and_the_readouts_every_frame(
    monitor: MonitorPanel, monkeypatch: pytest.MonkeyPatch
) -> None:
    assert PLOT_INTERVAL_MS == 2 * DISPLAY_INTERVAL_MS
    stream = _Stream(monitor)
    stream.frame()
    set_data: list[float] = []
    curve = monitor.curves["X"]
    original = curve.setData

    def spy(*args: Any, **kwargs: Any) -> None:
        set_data.append(stream.now)
        original(*args, **kwargs)

    monkeypatch.setattr(curve, "setData", spy)
    for _ in range(10):
        stream.frame()
        # the newest pose is on the readouts after every frame
        assert monitor.readouts["X"].text() == f"{_square(stream.i).x:.3f}"
    assert len(set_data) == 5  # 10 frames, 5 of them with the plots
    assert curve.xData[-1] == pytest.approx(0.0)  # the newest sample at "now"


def test_the_time_axis_and_the_ranges_keep_still_while_the_arm_goes_round(
    qtbot: Any, monitor: MonitorPanel, monkeypatch: pytest.MonkeyPatch
) -> None:
    import pyqtgraph as pg

    stream = _Stream(monitor)
    for _ in range(70):  # 1.75 times round: every range has seen the whole square and swing
        stream.frame()
    QApplication.processEvents()
    generated: list[str] = []
    original = pg.AxisItem.generateDrawSpecs

    def counting(self: Any, painter: Any) -> Any:
        generated.append(self.orientation)
        return original(self, painter)

    monkeypatch.setattr(pg.AxisItem, "generateDrawSpecs", counting)
    ranges = (monitor._plots.y_range("xyz"), monitor._plots.y_range("abc"))
    x_range = monitor.xyz_plot.getViewBox().viewRange()[0]
    painted = _Count(monitor.xyz_plot.viewport(), QEvent.Type.Paint)
    for _ in range(20):
        stream.frame()
        QApplication.processEvents()
    assert painted.count >= 5  # the plots were repainted, with new curves ...
    assert generated == []  # ... and no axis laid its labels out again
    assert (monitor._plots.y_range("xyz"), monitor._plots.y_range("abc")) == ranges
    assert monitor.xyz_plot.getViewBox().viewRange()[0] == x_range == pytest.approx([-30.0, 0.0])


def test_every_point_of_a_curve_is_inside_its_bounds(monitor: MonitorPanel) -> None:
    stream = _Stream(monitor)
    for _ in range(30):
        stream.frame()
    monitor.refresh()
    for curve in [*monitor.curves.values(), monitor.trace_curve]:
        rect = curve.boundingRect()
        xs, ys = np.asarray(curve.xData), np.asarray(curve.yData)
        assert len(xs) > 10
        assert rect.left() <= xs.min() and xs.max() <= rect.right()
        assert rect.top() <= ys.min() and ys.max() <= rect.bottom()


# --- live labels ----------------------------------------------------------------------------
def test_a_live_label_repaints_itself_without_a_relayout_and_only_grows(qtbot: Any) -> None:
    window = QWidget()
    qtbot.addWidget(window)
    layout = QVBoxLayout(window)
    label = LiveLabel(parent=window, samples=["RTT 9999.9 ms"])
    layout.addWidget(label)
    window.show()
    qtbot.waitExposed(window)
    QApplication.processEvents()
    relayouts = _Count(window, QEvent.Type.LayoutRequest)
    width = label.width()
    for ms in (0.3, 12.5, 150.25, 1.0, 9999.9, 7.0):  # narrower and wider texts, within the samples
        label.setText(f"RTT {ms} ms")
        QApplication.processEvents()
    assert relayouts.count == 0 and label.width() == width
    label.setText("RTT 99999999.9 ms, and more")  # wider than ever: grows once
    QApplication.processEvents()
    assert relayouts.count == 1 and label.width() > width
    wide = label.width()
    label.setText("1 ms")  # never shrinks: nothing beside it moves back
    QApplication.processEvents()
    assert label.width() == wide and relayouts.count == 1


def test_a_live_label_keeps_room_for_its_samples_in_a_new_style(qtbot: Any) -> None:
    """The samples are measured again in the font a style brings (the status panel's stale clock
    is italic, which may fall back to another font): a sample-shaped text then needs no re-layout."""
    window = QWidget()
    qtbot.addWidget(window)
    layout = QVBoxLayout(window)
    label = LiveLabel("1", parent=window, samples=["12:34 s"])
    layout.addWidget(label)
    window.show()
    qtbot.waitExposed(window)
    label.set_style("font-size: 40px; font-style: italic;")
    QApplication.processEvents()
    relayouts = _Count(window, QEvent.Type.LayoutRequest)
    width = label.width()
    for text in ("00:00 s", "88:88 s", "47:59 s", "12:34 s"):  # any digits, the sample's shape
        label.setText(text)
        QApplication.processEvents()
    assert relayouts.count == 0 and label.width() == width


def test_streaming_status_and_traffic_do_not_relayout_the_main_window(qtbot: Any) -> None:
    link = FakeLink(connected=True)
    window = QMainWindow()
    qtbot.addWidget(window)
    window.setCentralWidget(QWidget())
    status_panel, traffic_panel = StatusPanel(), TrafficPanel()
    for panel, area in ((status_panel, Qt.DockWidgetArea.RightDockWidgetArea),
                        (traffic_panel, Qt.DockWidgetArea.BottomDockWidgetArea)):  # fmt: skip
        dock = QDockWidget(window)
        dock.setWidget(panel)
        window.addDockWidget(area, dock)
    bar = WindowStatusBar(window.statusBar())
    status_panel.bind(link.state)
    bar.bind(link.state)
    window.resize(1200, 800)
    window.show()
    qtbot.waitExposed(window)
    feed = Feed()
    start = dt.datetime(2026, 1, 2, 3, 4, 5)

    def stream(second: int) -> None:
        clock = decode_clock(encode_clock(start + dt.timedelta(seconds=second)))
        status = ControllerStatus(ControllerMode.AUTO, ProgramState.RUNNING, Alarm(0), 0xFF, clock)
        link.state.set_status(status)  # a new clock reading every second
        link.state.set_rtt(0.5 + second % 7 * 11.3)  # RTT texts of different widths
        for _ in range(50):
            traffic_panel.on_traffic(feed.batch())
        traffic_panel.flush()  # the count label: "... frames", wider as it grows
        QApplication.processEvents()

    stream(0)  # the first texts
    qtbot.wait(100)  # a re-layout climbs one level per turn of the event loop: let it settle
    relayouts = _Count(window, QEvent.Type.LayoutRequest)
    for second in range(1, 25):
        stream(second)
    assert relayouts.count == 0
    assert traffic_panel.model.rowCount() == 25 * 50 * 4
    link.set_connected(False)
