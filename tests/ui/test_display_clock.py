"""The display clock: views repaint together, at most once per frame, and idle views cost nothing.

Also the streaming behaviour it carries: the newest pose is shown within one frame, and panels
that are hidden do no formatting work while poses and traffic stream in."""

from __future__ import annotations

import itertools
import time
from collections.abc import Iterator
from typing import Any

import pytest

from app.models import ControllerStatus, Pose
from app.protocol.enums import Alarm
from tests.ui.fake_link import FakeLink
from ui.display_clock import DISPLAY_INTERVAL_MS, DisplayClock
from ui.panels.monitor_panel import MonitorPanel
from ui.panels.pose_strip import PoseStrip
from ui.panels.traffic_panel import TrafficPanel
from ui.widgets_common import NumericReadout

pytestmark = pytest.mark.qt_log_ignore("This plugin does not support propagateSizeHints")


class Views:
    """Two fake views that count their frames."""

    def __init__(self) -> None:
        self.calls: list[str] = []

    def a(self) -> None:
        self.calls.append("a")

    def b(self) -> None:
        self.calls.append("b")


@pytest.fixture
def clock(qtbot: Any) -> Iterator[DisplayClock]:
    made = DisplayClock(interval_ms=20)
    yield made
    made.cancel(Views().a)  # nothing pending is left behind (the leak check looks at its timer)


def test_requests_run_together_once_per_frame(qtbot: Any, clock: DisplayClock) -> None:
    views = Views()
    for _ in range(5):  # a burst of data for two views
        clock.request(views.a)
        clock.request(views.b)
    assert clock.active and views.calls == []
    qtbot.waitUntil(lambda: clock.frames == 1, timeout=2000)
    assert views.calls == ["a", "b"]  # one frame, both views, each once
    assert not clock.active  # nothing asked for: idle, no timer running


def test_frames_are_at_least_one_interval_apart(qtbot: Any, clock: DisplayClock) -> None:
    stamps: list[float] = []

    def view() -> None:
        stamps.append(time.monotonic())
        if len(stamps) < 4:
            clock.request(view)  # an animating view asks for the next frame from its frame

    clock.request(view)
    qtbot.waitUntil(lambda: len(stamps) == 4, timeout=3000)
    gaps = [b - a for a, b in itertools.pairwise(stamps)]
    assert min(gaps) >= 0.95 * clock.interval_ms / 1000.0  # a coarse timer may be 5 % early


def test_run_or_request_shows_the_first_value_at_once_then_waits(qtbot: Any) -> None:
    clock = DisplayClock(interval_ms=500)  # "within the interval" must hold on a loaded machine too
    views = Views()
    clock.run_or_request(views.a)
    assert views.calls == ["a"]  # idle clock: at once
    clock.run_or_request(views.a)
    clock.run_or_request(views.a)
    assert views.calls == ["a"]  # within the interval: the next frame, once
    qtbot.waitUntil(lambda: views.calls == ["a", "a"], timeout=5000)
    assert not clock.active


def test_cancel_stops_the_timer(clock: DisplayClock) -> None:
    views = Views()
    clock.request(views.a)
    clock.cancel(views.a)
    assert not clock.active and not clock.is_requested(views.a)


def test_a_deleted_view_is_skipped(qtbot: Any, clock: DisplayClock) -> None:
    import shiboken6

    panel = MonitorPanel(clock=clock)
    clock.request(panel._tick)
    shiboken6.delete(panel)
    qtbot.waitUntil(lambda: clock.frames == 1, timeout=2000)  # no "already deleted" error


def test_the_interval_is_a_display_rate() -> None:
    assert 1000 / 30 <= DISPLAY_INTERVAL_MS <= 1000 / 20
    with pytest.raises(ValueError):
        DisplayClock(interval_ms=0)


# --- the panels on one clock ------------------------------------------------------------
def _poll(link: FakeLink, x: float) -> None:
    link.state.set_pose(Pose(x, 2.0, 3.0, 10.0, 20.0, 30.0, joints=(1.0, 2.0, 3.0, 4.0, 5.0, 6.0)))
    link.state.set_status(ControllerStatus(2, 1, Alarm(0), 0xFF))
    link.state.note_good_poll(time.monotonic())


@pytest.fixture
def link(qtbot: Any) -> Iterator[FakeLink]:
    fake = FakeLink(connected=True)
    yield fake
    fake.set_connected(False)


def test_shown_panels_end_on_the_newest_pose_within_a_frame(qtbot: Any, link: FakeLink) -> None:
    clock = DisplayClock()
    monitor, strip = MonitorPanel(clock=clock), PoseStrip(clock=clock)
    for widget in (monitor, strip):
        qtbot.addWidget(widget)
        widget.bind(link.state)
        widget.show()
    qtbot.waitExposed(monitor)
    frames = clock.frames
    for i in range(1, 101):  # a second of polls at 100 Hz, faster than any frame
        _poll(link, float(i))
    qtbot.waitUntil(
        lambda: monitor.readouts["X"].text() == "100.000" and strip.value_text("X") == "100.00", timeout=2000
    )
    assert clock.frames - frames <= 3  # a burst is drawn in a frame or two, not 100 times
    monitor.close()
    strip.close()


def test_a_hidden_monitor_formats_and_plots_nothing(
    qtbot: Any, link: FakeLink, monkeypatch: pytest.MonkeyPatch
) -> None:
    formatted: list[float | None] = []
    original = NumericReadout.set_value

    def counting(self: NumericReadout, value: float | None) -> None:
        formatted.append(value)
        original(self, value)

    monkeypatch.setattr(NumericReadout, "set_value", counting)
    clock = DisplayClock(interval_ms=5)
    monitor = MonitorPanel(clock=clock)
    qtbot.addWidget(monitor)
    monitor.bind(link.state)
    monitor.show()
    qtbot.waitExposed(monitor)
    monitor.refresh()  # the plots are built
    set_data: list[str] = []
    for name, curve in monitor.curves.items():
        monkeypatch.setattr(curve, "setData", lambda *a, _n=name, **k: set_data.append(_n))
    monitor.hide()
    formatted.clear()
    for i in range(200):  # streaming while the Monitor tab is not in front
        _poll(link, float(i))
    qtbot.wait(3 * clock.interval_ms)  # frames would have come by now
    assert formatted == [] and set_data == [] and not monitor.paint_timer_active
    assert monitor.sample_count == 200  # recorded all the same: the plots are whole when shown


def test_a_hidden_traffic_panel_decodes_and_formats_nothing(
    qtbot: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    from app.protocol.frames import decode_frame as original
    from benchmarks.traffic import Feed

    decoded: list[bytes] = []

    def counting(data: bytes, **kwargs: Any) -> Any:
        decoded.append(bytes(data))
        return original(data, **kwargs)

    monkeypatch.setattr("ui.models.traffic_row.decode_frame", counting)
    panel = TrafficPanel(clock=DisplayClock(interval_ms=5))
    qtbot.addWidget(panel)
    label = panel.count_label.text()
    feed = Feed()
    for _ in range(100):  # a second of polls, the panel hidden (capture on)
        panel.on_traffic(feed.batch())
    qtbot.wait(20)
    assert decoded == [] and panel.count_label.text() == label  # no decoding, no count text
    assert panel.model.rowCount() == 400
    panel.resize(1400, 400)  # the meaning column on screen
    panel.show()  # shown: the count and the newest rows at once
    qtbot.waitExposed(panel)
    assert panel.count_label.text() == "400 frames"
    qtbot.waitUntil(lambda: len(decoded) > 0, timeout=2000)  # the visible rows' meaning
    assert len(decoded) < 100  # only what is on screen
