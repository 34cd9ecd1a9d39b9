"""What the monitor skips to keep the GUI thread's streaming cost down, and what it never skips:
the top view waits for its marker to move a pixel, the cached axes still follow their ranges,
the per-poll recording (inlined angle unwrapping, finiteness) records what it did before."""

from __future__ import annotations

import math
from typing import Any

import pytest
from PySide6.QtGui import QImage

from app.models import Pose
from ui.panels.monitor_panel import MonitorPanel

pytestmark = pytest.mark.qt_log_ignore("This plugin does not support propagateSizeHints")


def pose(x: float = 0.0, y: float = 0.0, c: float = 30.0) -> Pose:
    return Pose(x, y, 100.0, 10.0, -20.0, c)


@pytest.fixture
def shown(qtbot: Any) -> MonitorPanel:
    panel = MonitorPanel()
    qtbot.addWidget(panel)
    panel.resize(1280, 700)
    panel.show()
    qtbot.waitExposed(panel)
    return panel


def _trace_draws(panel: MonitorPanel, monkeypatch: pytest.MonkeyPatch) -> list[int]:
    calls: list[int] = []
    original = panel.trace_curve.setData

    def spy(*args: Any, **kwargs: Any) -> None:
        calls.append(len(args[0]))
        original(*args, **kwargs)

    monkeypatch.setattr(panel.trace_curve, "setData", spy)
    return calls


def _frame(panel: MonitorPanel, clock: list[float]) -> None:
    """One display frame a plot frame after the last (the panel's clock moved on 0.2 s)."""
    clock[0] += 0.2
    panel._tick()


def test_the_top_view_waits_for_the_marker_to_move_a_pixel(
    shown: MonitorPanel, monkeypatch: pytest.MonkeyPatch
) -> None:
    clock = [1000.0]
    monkeypatch.setattr(shown, "_now", lambda: clock[0])
    shown.on_pose(pose(0.0, 0.0))
    shown.refresh()
    draws = _trace_draws(shown, monkeypatch)
    pixel_x, pixel_y = shown._plots._trace_pixel
    step = 0.06  # recorded (>= TRACE_MIN_STEP_MM) ...
    assert step < min(pixel_x, pixel_y) / 2  # ... but under half a pixel of the top view
    shown.on_pose(pose(step, 0.0))
    _frame(shown, clock)
    assert shown.trace_count == 2
    assert draws == []  # nothing on the top view would change: not redrawn
    shown.on_pose(pose(2 * step, 0.0))
    _frame(shown, clock)
    assert draws == []  # still under a pixel from where the marker was drawn
    shown.on_pose(pose(2 * step + pixel_x, 0.0))  # a pixel away now
    _frame(shown, clock)
    assert draws == [4]  # redrawn in that frame, with every point recorded meanwhile
    assert shown.trace_marker.pos().x() == pytest.approx(2 * step + pixel_x)


def test_refresh_draws_the_top_view_for_any_move(
    shown: MonitorPanel, monkeypatch: pytest.MonkeyPatch
) -> None:
    shown.on_pose(pose(0.0, 0.0), t=0.0)
    shown.refresh()
    draws = _trace_draws(shown, monkeypatch)
    shown.on_pose(pose(0.06, 0.0), t=0.01)
    shown.refresh()
    assert draws == [2]


def test_a_moving_arm_redraws_the_top_view_in_every_plot_frame(
    shown: MonitorPanel, monkeypatch: pytest.MonkeyPatch
) -> None:
    clock = [1000.0]
    monkeypatch.setattr(shown, "_now", lambda: clock[0])
    shown.on_pose(pose(0.0, 0.0))
    shown.refresh()
    draws = _trace_draws(shown, monkeypatch)
    for i in range(1, 4):
        shown.on_pose(pose(5.0 * i, 0.0))
        _frame(shown, clock)
    assert draws == [2, 3, 4]


def _image(panel: MonitorPanel) -> QImage:
    image: QImage = panel.xyz_plot.grab().toImage()
    return image


def test_a_cached_axis_follows_its_range(qtbot: Any, shown: MonitorPanel) -> None:
    """The axes are drawn from a pixmap cache: a new range still draws new tick labels."""
    shown.on_pose(pose(0.0), t=0.0)
    shown.on_pose(pose(1.0), t=0.1)
    shown.refresh()
    before = _image(shown)
    assert _image(shown) == before  # nothing changed: the same picture
    low = shown._plots.y_range("xyz")
    shown.on_pose(pose(5000.0), t=0.2)  # far outside: a new vertical range
    shown.refresh()
    assert shown._plots.y_range("xyz") != low
    qtbot.waitUntil(lambda: _image(shown) != before, timeout=2000)
    axis = shown.xyz_plot.getPlotItem().getAxis("left")
    shown_range = shown._plots.y_range("xyz")
    assert shown_range is not None
    values = [v for _spacing, ticks in axis.tickValues(*shown_range, 200) for v in ticks]
    assert max(values) >= 1000.0  # the ticks are the new range's


def test_angles_are_plotted_unwrapped_and_shown_raw(qtbot: Any) -> None:
    panel = MonitorPanel()
    qtbot.addWidget(panel)
    for i, c in enumerate((170.0, 179.0, -179.0, -170.0, 175.0)):
        panel.on_pose(pose(c=c), t=0.1 * i)
    panel.refresh()
    assert panel.curves["C"].yData.tolist() == pytest.approx([170.0, 179.0, 181.0, 190.0, 175.0])
    assert panel.readouts["C"].text() == "175.000"


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_a_non_finite_value_in_any_field_stays_out_of_the_plots(qtbot: Any, bad: float) -> None:
    panel = MonitorPanel()
    qtbot.addWidget(panel)
    panel.on_pose(pose(1.0), t=0.0)
    for field in range(6):
        x, y, z, a, b, c = (bad if i == field else float(i + 1) for i in range(6))
        panel.on_pose(Pose(x, y, z, a, b, c), t=0.1 + field)
    assert panel.sample_count == 1
    assert panel.trace_count == 1


def test_a_cleared_trace_is_redrawn_in_the_next_frame_however_little_moved(
    shown: MonitorPanel, monkeypatch: pytest.MonkeyPatch
) -> None:
    clock = [1000.0]
    monkeypatch.setattr(shown, "_now", lambda: clock[0])
    for i in range(3):
        shown.on_pose(pose(10.0 * i, 0.0))
    shown.refresh()
    assert len(shown.trace_curve.xData) == 3
    shown.set_paused(True)
    shown.clear_trace_button.click()
    shown.on_pose(pose(20.06, 0.0))  # the marker's place, give or take a fraction of a pixel
    shown.set_paused(False)
    _frame(shown, clock)
    assert shown.trace_curve.xData.tolist() == [pytest.approx(20.06)]  # not the old trace
