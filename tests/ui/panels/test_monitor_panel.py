"""MonitorPanel: readouts, ring-buffered plots painted by a visibility-bound timer, X–Y trace."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest
from PySide6.QtCore import QCoreApplication, QTranslator
from PySide6.QtWidgets import QWidget

from app.models import Pose
from ui.panels import monitor_panel
from ui.panels.monitor_figures import MAX_PLOT_POINTS, PAINT_MARGIN
from ui.panels.monitor_panel import PAINT_INTERVAL_MS, MonitorPanel

# The offscreen platform warns on every top-level show; it says nothing about the panel.
pytestmark = pytest.mark.qt_log_ignore("This plugin does not support propagateSizeHints")


def pose(x: float = 0.0, y: float = 0.0, z: float = 0.0, *, joints: tuple[float, ...] | None = None) -> Pose:
    return Pose(x, y, z, 10.0, -20.0, 30.0, ext=(1.0, 2.0, 3.0, 4.0, -5.5), joints=joints)


@pytest.fixture
def panel(qtbot: Any) -> Iterator[MonitorPanel]:
    widget = MonitorPanel()
    qtbot.addWidget(widget)
    yield widget


@pytest.fixture
def shown(qtbot: Any, panel: MonitorPanel) -> MonitorPanel:
    panel.resize(1280, 700)
    panel.show()
    qtbot.waitExposed(panel)
    return panel


def _count_set_data(panel: MonitorPanel, monkeypatch: pytest.MonkeyPatch) -> list[str]:
    calls: list[str] = []
    for name, curve in panel.curves.items():
        original = curve.setData

        def spy(*args: Any, _name: str = name, _original: Any = original, **kwargs: Any) -> None:
            calls.append(_name)
            _original(*args, **kwargs)

        monkeypatch.setattr(curve, "setData", spy)
    return calls


def test_paint_rate_is_at_most_30_hz() -> None:
    assert PAINT_INTERVAL_MS >= 1000 / 30


def test_readouts_show_fixed_decimals_and_units(panel: MonitorPanel) -> None:
    panel.on_pose(Pose(123.4567, -0.0001, 1500.0, 179.9999, -0.5, 90.0, ext=(1.0, 2.25, 0.0, 0.0, -7.0)))
    panel.refresh()
    r = panel.readouts
    assert r["X"].text() == "123.457"
    assert r["Y"].text() == "0.000"  # no "-0.000"
    assert r["Z"].text() == "1500.000"
    assert r["A"].text() == "180.000"
    assert r["B"].text() == "-0.500"
    assert r["J8"].text() == "2.250"
    assert r["J11"].text() == "-7.000"
    assert (r["X"].unit(), r["A"].unit(), r["J7"].unit()) == ("mm", "°", "")
    assert panel._axes_box.title().endswith("(°)")  # the small readouts' unit is in the title
    assert r["X"].caption() == "X"


def test_readout_digits_are_monospace_and_large(panel: MonitorPanel) -> None:
    number = panel.readouts["X"]._number
    metrics = number.fontMetrics()
    widths = {metrics.horizontalAdvance(ch * 4) for ch in "0123456789-. "}
    assert len(widths) == 1  # every digit, sign and point equally wide: values don't jitter
    assert number.font().pointSizeF() >= 20


def test_joints_appear_with_the_first_pose_that_has_them(panel: MonitorPanel) -> None:
    panel.on_pose(pose(1, 2, 3))
    panel.refresh()
    assert not panel.joints_shown
    panel.on_pose(pose(1, 2, 3, joints=(1.5, 2, 3, 4, 5, -6)))
    panel.refresh()
    assert panel.joints_shown
    assert panel.readouts["J1"].text() == "1.500"
    assert panel.readouts["J6"].text() == "-6.000"


def test_curves_get_data_after_the_paint_timer_fires(qtbot: Any, shown: MonitorPanel) -> None:
    assert not shown.paint_timer_active  # nothing to show: no frames
    for i in range(50):
        shown.on_pose(pose(i, 2 * i, 3 * i), t=100.0 + i * 0.02)
    assert shown.paint_timer_active
    curve = shown.curves["Y"]
    qtbot.waitUntil(lambda: curve.xData is not None and len(curve.xData) == 50, timeout=2000)
    assert curve.yData[-1] == 98.0
    # seconds before the newest sample: 0 at the right edge, the first one 49 x 20 ms earlier
    assert curve.xData[-1] == 0.0
    assert curve.xData[0] == pytest.approx(-0.98)
    # The curve holds a view of the ring buffer, not a copy.
    assert np.shares_memory(curve.yData, shown._history._buf)
    qtbot.waitUntil(
        lambda: (
            shown.trace_count == 50
            and shown.trace_curve.xData is not None
            and len(shown.trace_curve.xData) == 50
        ),
        timeout=2000,
    )
    qtbot.waitUntil(lambda: shown.readouts["Z"].text() == "147.000", timeout=2000)


def test_nothing_new_means_no_set_data(panel: MonitorPanel, monkeypatch: pytest.MonkeyPatch) -> None:
    calls = _count_set_data(panel, monkeypatch)
    panel.on_pose(pose(1, 1, 1), t=0.0)
    panel.refresh()
    assert len(calls) == 6
    panel.refresh()
    panel.refresh()
    assert len(calls) == 6
    panel.on_pose(pose(2, 2, 2), t=0.1)
    panel.refresh()
    assert len(calls) == 12


def test_pause_freezes_the_plots_but_keeps_recording(
    panel: MonitorPanel, monkeypatch: pytest.MonkeyPatch
) -> None:
    panel.on_pose(pose(1), t=0.0)
    panel.refresh()
    calls = _count_set_data(panel, monkeypatch)
    panel.pause_button.click()
    assert panel.is_paused()
    for i in range(10):
        panel.on_pose(pose(i), t=0.1 * (i + 1))
    panel.refresh()
    assert calls == []
    assert panel.sample_count == 11
    assert panel.readouts["X"].text() == "9.000"  # readouts stay live
    panel.set_paused(False)
    assert not panel.pause_button.isChecked()
    panel.refresh()
    assert len(panel.curves["X"].xData) == 11


def test_window_limits_the_plotted_time_span(panel: MonitorPanel) -> None:
    for i in range(1000):  # 100 s at 10 Hz
        panel.on_pose(pose(i), t=i * 0.1)
    panel.set_window(10)
    assert panel.window_combo.currentData() == 10
    panel.refresh()
    xs = panel.curves["X"].xData
    assert xs[-1] == 0.0  # the newest sample, at "now"
    assert xs[0] >= -10 - 1e-9
    assert len(xs) == 101
    assert panel.xyz_plot.getViewBox().viewRange()[0] == pytest.approx([-10.0, 0.0])
    panel.window_combo.setCurrentIndex(panel.window_combo.findData(60))
    assert panel.window_seconds() == 60
    panel.refresh()
    assert len(panel.curves["X"].xData) == 601


def test_long_windows_are_decimated_but_end_at_the_newest_sample(panel: MonitorPanel) -> None:
    n = 12_000  # 60 s at 200 Hz
    for i in range(n):
        panel.on_pose(pose(float(i)), t=i * 0.005)
    panel.set_window(60)
    panel.refresh()
    curve = panel.curves["X"]
    assert len(curve.xData) <= MAX_PLOT_POINTS
    assert curve.yData[-1] == float(n - 1)
    assert np.shares_memory(curve.yData, panel._history._buf)


def test_curves_never_get_the_whole_ring(qtbot: Any) -> None:
    panel = MonitorPanel(history_capacity=PAINT_MARGIN + 100, trace_capacity=PAINT_MARGIN + 50)
    qtbot.addWidget(panel)
    for i in range(2000):
        panel.on_pose(pose(float(i), float(i)), t=i * 0.01)
    panel.refresh()
    assert len(panel.curves["X"].xData) == 100
    assert panel.curves["X"].yData[-1] == 1999.0
    assert len(panel.trace_curve.xData) == 50


def test_trace_skips_tiny_moves_and_clears(panel: MonitorPanel) -> None:
    panel.on_pose(pose(0, 0), t=0)
    panel.on_pose(pose(0.01, 0.01), t=0.01)  # below TRACE_MIN_STEP_MM
    panel.on_pose(pose(1, 0), t=0.02)
    panel.on_pose(pose(1, 1), t=0.03)
    assert panel.trace_count == 3
    panel.refresh()
    assert panel.trace_curve.xData.tolist() == [0.0, 1.0, 1.0]
    assert panel.trace_curve.yData.tolist() == [0.0, 0.0, 1.0]
    assert panel.trace_plot.getViewBox().state["aspectLocked"]
    panel.clear_trace_button.click()
    assert panel.trace_count == 0
    assert panel.sample_count == 4  # the time plots keep their data
    panel.refresh()
    assert len(panel.trace_curve.xData) == 0


def test_clear_forgets_everything(panel: MonitorPanel) -> None:
    panel.on_pose(pose(5), t=1.0)
    panel.refresh()
    panel.clear()
    panel.refresh()
    assert panel.sample_count == 0
    assert len(panel.curves["X"].xData) == 0
    assert panel.readouts["X"].text() == "—"


def test_paint_timer_runs_only_while_visible(qtbot: Any, shown: MonitorPanel) -> None:
    shown.on_pose(pose(1))  # live samples: the time axis keeps time, a frame after each frame
    assert shown.paint_timer_active
    qtbot.waitUntil(lambda: shown.readouts["X"].text() == "1.000", timeout=2000)
    assert shown.paint_timer_active
    shown.hide()
    assert not shown.paint_timer_active
    shown.show()
    qtbot.waitExposed(shown)
    assert shown.paint_timer_active
    shown.close()
    assert not shown.paint_timer_active


def test_hidden_panel_does_not_paint(qtbot: Any, panel: MonitorPanel) -> None:
    panel.on_pose(pose(1), t=0.0)
    assert not panel.paint_timer_active
    assert len(panel.curves["X"].xData) == 0
    panel.show()  # showing paints at once, then keeps painting
    qtbot.waitExposed(panel)
    assert len(panel.curves["X"].xData) == 1


def test_readouts_grow_on_wide_screens(qtbot: Any, panel: MonitorPanel) -> None:
    panel.resize(640, 700)  # the monitor tab of a 1280 px window
    panel.show()
    qtbot.waitExposed(panel)
    small = panel.readouts["X"].point_size()
    panel.resize(1300, 1000)  # ... of a 1920 px window
    qtbot.waitUntil(lambda: panel.readouts["X"].point_size() > small, timeout=2000)
    assert panel.readouts["X"].point_size() <= monitor_panel._BIG_POINTS_MAX


class _Prefix(QTranslator):
    def translate(self, context: str, source: str, disambiguation: str | None = None, n: int = -1) -> str:
        return f"中 {source}"

    def isEmpty(self) -> bool:
        return False


def test_language_change_retranslates(qtbot: Any, panel: MonitorPanel) -> None:
    translator = _Prefix()
    app = QCoreApplication.instance()
    assert app is not None
    app.installTranslator(translator)
    try:
        qtbot.waitUntil(lambda: panel.pause_button.text() == "中 Pause plots", timeout=2000)
        assert panel.window_combo.itemText(0) == "中 10 s"
        assert panel.readouts["X"].unit() == "中 mm"
    finally:
        app.removeTranslator(translator)
    qtbot.waitUntil(lambda: panel.readouts["X"].unit() == "mm", timeout=2000)


def test_non_finite_samples_stay_out_of_the_plots(panel: MonitorPanel) -> None:
    panel.on_pose(pose(1.0), t=0.0)
    panel.on_pose(Pose(float("nan"), 0, 0, 0, 0, 0), t=0.1)
    panel.refresh()
    assert panel.sample_count == 1
    assert panel.readouts["X"].text() == "—"
    assert panel.readouts["Y"].text() == "0.000"


def test_the_first_fit_waits_for_the_loop_and_is_made_once_at_the_last_width(
    qtbot: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Qt lays a window out twice in its first show(): the readouts are fitted once, at the width
    the panel has when the loop is back (before the first paint), then at every resize at once."""
    host = QWidget()
    qtbot.addWidget(host)
    host.resize(1400, 600)
    panel = MonitorPanel(host)
    boxes = panel._readout_boxes
    fitted: list[int] = []
    fit = boxes.fit_width

    def noted_fit(width: int) -> None:
        fitted.append(width)
        fit(width)

    monkeypatch.setattr(boxes, "fit_width", noted_fit)
    panel.resize(739, 500)
    host.show()  # the pending resize is delivered here
    panel.resize(590, 500)  # a child: its resize event at once
    assert fitted == []
    qtbot.waitUntil(lambda: fitted == [590], timeout=2000)
    big = panel.readouts["X"].point_size()
    panel.resize(1230, 500)
    assert fitted == [590, 1230]  # from then on, at once
    assert panel.readouts["X"].point_size() > big
