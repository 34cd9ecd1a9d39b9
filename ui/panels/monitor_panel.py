"""Live position monitor: big XYZABC / external-axis / joint readouts, rolling plots, X–Y trace.

Poll rate and paint rate are separate clocks: ``on_pose`` (called at the poll rate, 50–200 Hz)
only stores the sample in preallocated ring buffers; the frames of the application's
:class:`~ui.display_clock.DisplayClock` (≤ 20 Hz, shared with the pose strip and the traffic
table so that they repaint together), taken only while the panel is visible, update the
readouts, and every ``PLOT_INTERVAL_MS`` (every other frame) hand contiguous buffer views to
the curves (:mod:`ui.panels.monitor_plots`).

Plots keep time: the pose only changes (and ``poseChanged`` only fires) while the arm moves, so
each frame also appends the last pose at the current time while the values are fresh,
and the time axis ends at "now" (it counts seconds before now): the curves move left at a
steady rate when the arm is still, and a silent link leaves a visible gap at the right instead
of a flat line that looks live. Hidden, the panel takes
no frames: nothing is appended, formatted or painted. Stale values (``RobotState.fresh`` False)
grey the readouts.
The top view fits its trace (at least ``TRACE_MIN_SPAN_MM`` wide, so a standing arm's single
point still gets readable axis labels).
"""

from __future__ import annotations

import math
import time
from typing import Any

from PySide6.QtCore import QEvent, QSignalBlocker, QSize, QTimer, Slot
from PySide6.QtGui import QCloseEvent, QHideEvent, QPaintEvent, QResizeEvent, QShowEvent
from PySide6.QtWidgets import (
    QComboBox,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QSizePolicy,
    QVBoxLayout,
    QWidget,
)

from app.link.state import RobotState
from app.models import Pose
from app.safety.stopping import StopKind, StopMeasurement
from ui.display_clock import DISPLAY_INTERVAL_MS, DisplayClock
from ui.models.ring_buffer import RingBuffer
from ui.panels.monitor_figures import CARTESIAN as _CARTESIAN
from ui.panels.monitor_figures import PLOT_INTERVAL_MS
from ui.panels.monitor_readouts import BIG_POINTS_MAX, MIN_WIDTH, PANEL_MARGIN, ReadoutBoxes, readout_scale
from ui.widgets_common import NumericReadout, neutral_text

__all__ = [
    "PAINT_INTERVAL_MS",
    "MonitorPanel",
]

#: Attributes that exist once the plots are built (asking for one builds them).
_PLOT_ATTRIBUTES = frozenset({"xyz_plot", "abc_plot", "trace_plot", "curves", "trace_curve", "trace_marker"})

PAINT_INTERVAL_MS = DISPLAY_INTERVAL_MS  # the display clock's frame period (<= 20 Hz): the readouts
# A plot frame is due this long after the last one: PLOT_INTERVAL_MS, less half a display frame
# (frames come a millisecond early or late; every other one must do).
_PLOT_DUE_S = (PLOT_INTERVAL_MS - DISPLAY_INTERVAL_MS / 2) / 1000.0
WINDOW_CHOICES_S: tuple[int, ...] = (10, 30, 60)
DEFAULT_WINDOW_S = 30
HISTORY_CAPACITY = 16384  # samples: the longest window at up to ~270 Hz
TRACE_CAPACITY = 20000  # X–Y path points
TRACE_MIN_STEP_MM = 0.05  # a standing robot does not fill the trace with one point
_BIG_POINTS_MAX = BIG_POINTS_MAX


class MonitorPanel(QWidget):
    """Big live readouts and plots of the robot position. Feed it with ``on_pose``."""

    def __init__(
        self,
        parent: QWidget | None = None,
        *,
        history_capacity: int = HISTORY_CAPACITY,
        trace_capacity: int = TRACE_CAPACITY,
        clock: DisplayClock | None = None,
    ) -> None:
        super().__init__(parent)
        self.setObjectName("MonitorPanel")
        # Samples: time + XYZABC; the X–Y trace has its own (longer, decimated) buffer.
        self._history = RingBuffer(history_capacity, 7)
        self._trace = RingBuffer(trace_capacity, 2)
        self._t0: float | None = None
        self._latest: Pose | None = None
        self._latest_row: tuple[float, ...] | None = None  # the last history row appended
        self._held_time = False  # the last sample came with an explicit time: no hold samples
        self._fresh = True  # unbound: every pose is taken as live
        self._now = time.monotonic  # the display clock (tests may replace it)
        self._readouts_dirty = False
        self._painted_history = -1  # RingBuffer.total at the last paint (-1: force)
        self._painted_trace = -1
        self._plots_painted_at = -math.inf  # self._now() of the last plot frame
        self._window_s = float(DEFAULT_WINDOW_S)
        self._paused = False
        # A B C are plotted unwrapped (a turn through +-180 draws on continuously); the readouts
        # show the controller's values. Last raw value and its unwrapped counterpart per angle.
        self._angle_raw: tuple[float, float, float] | None = None
        self._angle_unwrapped = (0.0, 0.0, 0.0)
        self._trace_last: tuple[float, float] | None = None  # the trace's newest point

        self._clock = clock if clock is not None else DisplayClock.shared()
        self._shown = False  # between showEvent and hideEvent: frames are taken
        self._fitted = False  # the readouts fitted to the panel's width once (resizeEvent)
        self._fit_scheduled = False
        self._build_ui()

    # --- UI ---------------------------------------------------------------------------
    def _build_ui(self) -> None:
        boxes = ReadoutBoxes(self)
        self.readouts: dict[str, NumericReadout] = boxes.readouts
        self._readout_boxes = boxes
        self._cart_box, self._axes_box = boxes.cart_box, boxes.axes_box
        self._joint_readouts = boxes.joint_readouts

        # Plot controls.
        self.window_combo = QComboBox(self)
        for seconds in WINDOW_CHOICES_S:
            self.window_combo.addItem("", seconds)
        self.window_combo.setCurrentIndex(WINDOW_CHOICES_S.index(DEFAULT_WINDOW_S))
        self.window_combo.currentIndexChanged.connect(self._on_window_index)
        self.pause_button = QPushButton(self)
        self.pause_button.setCheckable(True)
        self.pause_button.toggled.connect(self.set_paused)
        self.clear_trace_button = QPushButton(self)
        self.clear_trace_button.clicked.connect(self.clear_trace)

        controls = QHBoxLayout()
        controls.setContentsMargins(0, 0, 0, 0)
        self._window_label = QLabel(self)
        self._window_label.setBuddy(self.window_combo)
        controls.addWidget(self._window_label)
        controls.addWidget(self.window_combo)
        controls.addWidget(self.pause_button)
        controls.addStretch(1)
        # measured stopping (ui/controllers/stop_timing.py): "Last stop: 180 ms, 4.2 mm", in the
        # controls' free width (beside the plots' status line it cut that line under wider fonts)
        self.last_stop_label = QLabel(self)
        self.last_stop_label.setObjectName("LastStopLabel")
        controls.addWidget(self.last_stop_label)
        controls.addSpacing(12)
        controls.addWidget(self.clear_trace_button)

        # Plots: built after the window's first paint (_build_plots); a placeholder keeps their place.
        self._plots_built = False
        self._plots_scheduled = False
        plots = QWidget(self)
        plots.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Expanding)
        self._plots_slot = plots

        self._status = QLabel(self)
        neutral_text(self._status)
        self._last_stop: StopMeasurement | None = None
        self._stops_measured = 0

        layout = QVBoxLayout(self)
        layout.setContentsMargins(PANEL_MARGIN, PANEL_MARGIN, PANEL_MARGIN, PANEL_MARGIN)
        layout.setSpacing(6)
        layout.addWidget(boxes.cart_box)
        layout.addWidget(boxes.axes_box)
        layout.addLayout(controls)
        layout.addWidget(plots, 1)
        layout.addWidget(self._status)
        self._layout = layout
        self.retranslate()

    # --- the plots, built on first need ------------------------------------------------
    def __getattr__(self, name: str) -> Any:
        """The plot attributes (``xyz_plot``, ``curves``, ...) build the plots when asked for first."""
        if name in _PLOT_ATTRIBUTES and not self.__dict__.get("_plots_built", True):
            self._build_plots()
            return getattr(self, name)
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    @property
    def plots_built(self) -> bool:
        return self._plots_built

    @Slot()
    def _build_plots(self) -> None:
        """The pyqtgraph plots, and pyqtgraph's import (~0.3 s): after the window's first paint."""
        if self._plots_built:
            return
        self._plots_built = True
        from ui.panels.monitor_plots import MonitorPlots  # not needed for the first paint

        plots = MonitorPlots(self)
        self._plots = plots
        self.xyz_plot, self.abc_plot, self.trace_plot = plots.xyz_plot, plots.abc_plot, plots.trace_plot
        self.curves = plots.curves
        self.trace_curve, self.trace_marker = plots.trace_curve, plots.trace_marker
        self._layout.replaceWidget(self._plots_slot, plots.widget)
        self._plots_slot.deleteLater()
        plots.widget.show()  # made after the panel was shown: hidden until shown
        self._retranslate_plots()
        self._painted_history = self._painted_trace = -1  # paint what was recorded meanwhile

    def retranslate(self) -> None:
        """(Re)set every user-visible text: at construction and on a language change."""
        mm, deg = self.tr("mm"), self.tr("°")
        self._cart_box.setTitle(self.tr("TCP position (base frame)"))
        # the small readouts carry no unit of their own (no room at 1280 px): it is in the title
        self._axes_box.setTitle(self.tr("Joints and external axes (°)"))
        for i, name in enumerate(_CARTESIAN):
            self.readouts[name].set_unit(mm if i < 3 else deg)
        for index, seconds in enumerate(WINDOW_CHOICES_S):
            self.window_combo.setItemText(index, self.tr("{n} s").format(n=seconds))
        self.window_combo.setToolTip(self.tr("Time span of the position plots"))
        self._window_label.setText(self.tr("Window:"))
        self.pause_button.setText(self.tr("Pause plots"))
        self.pause_button.setToolTip(self.tr("Freeze the plots; samples keep being recorded"))
        self.clear_trace_button.setText(self.tr("Clear trace"))
        self.clear_trace_button.setToolTip(self.tr("Erase the X–Y path trace"))
        self._update_status_text()
        self._show_last_stop()
        if self._plots_built:
            self._retranslate_plots()

    def _retranslate_plots(self) -> None:
        mm, deg = self.tr("mm"), self.tr("°")
        self.xyz_plot.setLabel("left", self.tr("position"), units=mm)
        self.abc_plot.setLabel("left", self.tr("orientation"), units=deg)
        self.abc_plot.setLabel("bottom", self.tr("time"), units=self.tr("s"))
        self.trace_plot.setTitle(self.tr("Top view (X–Y)"), color="#263238", size="10pt")
        self.trace_plot.setLabel("bottom", "X", units=mm)
        self.trace_plot.setLabel("left", "Y", units=mm)

    def changeEvent(self, event: QEvent) -> None:
        if event.type() == QEvent.Type.LanguageChange:
            self.retranslate()
        super().changeEvent(event)

    # --- slots ------------------------------------------------------------------------
    def bind(self, state: RobotState) -> None:
        """Record ``state``'s poses from now on; grey the readouts while they are stale."""
        state.poseChanged.connect(self.on_pose)
        state.freshnessChanged.connect(self.on_freshness)
        self.on_freshness(state.fresh)

    @Slot(bool)
    def on_freshness(self, fresh: bool) -> None:
        self._fresh = bool(fresh)
        tip = "" if fresh else self.tr("Stale: not confirmed by the controller within the freshness limit")
        for box in (self._cart_box, self._axes_box):  # the readouts follow their box
            box.setEnabled(self._fresh)
            box.setToolTip(tip)
        self._update_status_text()

    @property
    def fresh(self) -> bool:
        return self._fresh

    @Slot(object)
    def on_pose(self, pose: Pose, t: float | None = None) -> None:
        """Record one sample (``t``: monotonic seconds, default now). Cheap: no painting here
        (it runs at the poll rate: plain float arithmetic, no per-sample lists)."""
        self._latest = pose
        self._readouts_dirty = True
        if self._shown:
            self._clock.request(self._tick)
        x, y, z, a, b, c = pose.x, pose.y, pose.z, pose.a, pose.b, pose.c
        # a NaN or an infinity in any of them (the sum of finite poses, < 1e39, is finite)
        if not math.isfinite(x + y + z + a + b + c):
            return  # shown as "—"; kept out of the plots (skipFiniteCheck trusts the data)
        self._held_time = t is not None
        if t is None:
            t = self._now()
        if self._t0 is None:
            self._t0 = t
        raw = self._angle_raw
        if raw is None:
            ua, ub, uc = a, b, c
        else:  # each angle's step taken the short way round (unwrap_degrees, inlined)
            ua, ub, uc = self._angle_unwrapped
            ua += (a - raw[0] + 180.0) % 360.0 - 180.0
            ub += (b - raw[1] + 180.0) % 360.0 - 180.0
            uc += (c - raw[2] + 180.0) % 360.0 - 180.0
        self._angle_raw, self._angle_unwrapped = (a, b, c), (ua, ub, uc)
        row = (t - self._t0, x, y, z, ua, ub, uc)
        self._history.append(row)
        self._latest_row = row
        last = self._trace_last
        if last is None or math.hypot(x - last[0], y - last[1]) >= TRACE_MIN_STEP_MM:
            self._trace.append((x, y))
            self._trace_last = (x, y)

    @Slot()
    def clear_trace(self) -> None:
        self._trace.clear()
        self._trace_last = None
        self._painted_trace = -1

    @Slot()
    def clear(self) -> None:
        """Forget every sample (e.g. after connecting to another controller)."""
        self._history.clear()
        self._trace.clear()
        self._trace_last = None
        self._angle_raw = None
        self._t0 = None
        self._latest = None
        self._latest_row = None
        self._readouts_dirty = True
        self._painted_history = -1
        self._painted_trace = -1
        if self._plots_built:
            self._plots.forget_ranges()  # the next samples may be anywhere

    @Slot(bool)
    def set_paused(self, paused: bool) -> None:
        """Freeze the plots (readouts and recording go on)."""
        paused = bool(paused)
        if paused == self._paused:
            return
        self._paused = paused
        with QSignalBlocker(self.pause_button):
            self.pause_button.setChecked(paused)
        if not paused:
            self._painted_history = self._painted_trace = -1
        self._update_status_text()

    def is_paused(self) -> bool:
        return self._paused

    def set_window(self, seconds: float) -> None:
        """Time span of the rolling plots; a value from ``WINDOW_CHOICES_S`` selects its entry."""
        if seconds <= 0:
            raise ValueError("the plot window must be positive")
        self._window_s = float(seconds)
        index = self.window_combo.findData(int(seconds)) if float(seconds).is_integer() else -1
        if index >= 0:
            with QSignalBlocker(self.window_combo):
                self.window_combo.setCurrentIndex(index)
        self._painted_history = -1
        self._update_status_text()

    def window_seconds(self) -> float:
        return self._window_s

    @property
    def paint_timer_active(self) -> bool:
        """The panel waits for a display frame (only while shown)."""
        return self._clock.is_requested(self._tick)

    @property
    def sample_count(self) -> int:
        return len(self._history)

    @property
    def trace_count(self) -> int:
        return len(self._trace)

    # --- painting ---------------------------------------------------------------------
    @Slot()
    def _tick(self) -> None:
        """A display frame: hold the last fresh pose at "now", draw the readouts that changed and,
        every ``PLOT_INTERVAL_MS``, the plots; ask for the next frame while the time axis has to
        keep time."""
        row, now = self._latest_row, self._relative_now()
        if row is not None and now is not None and self._fresh and now > row[0]:
            self._history.append((now, *row[1:]))
            self._latest_row = (now, *row[1:])
        if self._shown and now is not None:
            self._clock.request(self._tick)
        if not self._plots_built and not self._plots_scheduled:  # before the first paint
            if self._readouts_dirty:
                self._readouts_dirty = False
                self._paint_readouts()
            return
        self._draw(plots=self._now() - self._plots_painted_at >= _PLOT_DUE_S, frame=True)

    @Slot()
    def refresh(self) -> None:
        """Draw now: readouts, then the plots if new samples arrived (or the time axis moved)."""
        self._draw(plots=True)

    def _draw(self, *, plots: bool, frame: bool = False) -> None:
        if not self._plots_built:
            self._build_plots()
        if plots and not self._paused:
            self._draw_plots(every_trace_change=not frame)
        if self._readouts_dirty:
            self._readouts_dirty = False
            self._paint_readouts()

    def _draw_plots(self, *, every_trace_change: bool = True) -> None:
        """``every_trace_change`` False (the display frames): the top view only once its marker
        moved a pixel (the time plots move with the clock in every plot frame)."""
        now = self._relative_now()
        painted = False
        if self._history.total != self._painted_history or now is not None:
            self._painted_history = self._history.total
            self._plots.paint_history(self._history, self._window_s, now)
            painted = True
        if self._trace.total != self._painted_trace and (
            every_trace_change or self._painted_trace < 0 or self._plots.trace_moved(self._trace)
        ):  # (-1: cleared, resumed or built since: drawn whatever moved)
            self._painted_trace = self._trace.total
            self._plots.paint_trace(self._trace)
            painted = True
        if painted:
            self._plots_painted_at = self._now()

    def _relative_now(self) -> float | None:
        """The display clock's "now" on the plots' time axis; None when the axis does not keep
        time (no sample yet, or the samples came with their own times)."""
        if self._t0 is None or self._held_time:
            return None
        return self._now() - self._t0

    def _paint_readouts(self) -> None:
        pose = self._latest
        readouts = self.readouts
        if pose is None:
            for readout in readouts.values():
                readout.set_value(None)
            return
        for name, value in zip(_CARTESIAN, pose.xyzabc, strict=True):
            readouts[name].set_value(value)
        for i, value in enumerate(pose.ext[:5], start=7):  # the external axes, J7..J11
            readouts[f"J{i}"].set_value(value)
        joints = pose.joints
        if joints and not self.joints_shown:
            for readout in self._joint_readouts:
                readout.setVisible(True)
        for i, readout in enumerate(self._joint_readouts):
            readout.set_value(joints[i] if joints and i < len(joints) else None)

    @property
    def joints_shown(self) -> bool:
        """Whether the joint readouts are shown (after the first pose with joint angles)."""
        return self._joint_readouts[0].isVisibleTo(self)

    def trace_view_range(self) -> tuple[tuple[float, float], tuple[float, float]]:
        return self._plots.trace_view_range()

    def _update_status_text(self) -> None:
        text = self.tr("Plots: last {n} s").format(n=f"{self._window_s:g}")
        if self._paused:
            text += " — " + self.tr("paused")
        if not self._fresh:
            text += " — " + self.tr("values stale (grey): no fresh data from the controller")
        self._status.setText(text)

    @Slot(object)
    def show_last_stop(self, measurement: StopMeasurement) -> None:
        """A Stop or jog release was measured (``StopTiming.measured``): say how long and how far."""
        self._last_stop = measurement
        self._stops_measured += 1
        self._show_last_stop()

    def _show_last_stop(self) -> None:
        m = self._last_stop
        if m is None:
            self.last_stop_label.setText(self.tr("Last stop: not measured yet"))
        else:
            head = self.tr("Last stop:") if m.kind is StopKind.STOP else self.tr("Last jog release:")
            body = (
                self.tr("{ms} ms, {mm} mm").format(ms=m.ms, mm=f"{m.distance_mm:.1f}")
                if m.still
                else self.tr("not seen still within {s} s ({mm} mm)").format(
                    s=f"{m.timeout:g}", mm=f"{m.distance_mm:.1f}"
                )
            )
            self.last_stop_label.setText(f"{head} {body}")
        self.last_stop_label.setToolTip(
            self.tr(
                "Measured stopping: from the click on Stop (or a jog's release) to the arm seen still "
                "(two polls alike), and the distance it travelled meanwhile. {n} measured in this session."
            ).format(n=self._stops_measured)
        )

    @Slot(int)
    def _on_window_index(self, index: int) -> None:
        seconds = self.window_combo.itemData(index)
        if seconds:
            self.set_window(float(seconds))

    def minimumSizeHint(self) -> QSize:
        # The readouts' fonts follow the width (resizeEvent), so the fonts in use now do not
        # set the minimum: a narrow window gets smaller numbers, never a clipped panel.
        hint = super().minimumSizeHint()
        return QSize(min(hint.width(), MIN_WIDTH), hint.height())

    def readout_scale(self, width: int) -> float:
        """Readout size factor for a panel ``width`` px wide (1.0 at its reference width)."""
        return readout_scale(width)

    def resizeEvent(self, event: QResizeEvent) -> None:
        if self._fitted:
            self._fit_readouts()
        elif not self._fit_scheduled:
            # Qt lays a window out twice in its first show() (this panel ~740 px wide, then as wide
            # as the docks leave it): the first fit waits for the loop, which comes back before the
            # first paint, and is made once, at the width of then (~10 ms less before the paint)
            self._fit_scheduled = True
            QTimer.singleShot(0, self, self._fit_readouts)
        super().resizeEvent(event)

    @Slot()
    def _fit_readouts(self) -> None:
        self._fitted = True
        self._readout_boxes.fit_width(self.width())  # numbers as big as the panel allows

    # --- frames follow visibility --------------------------------------------------------
    def showEvent(self, event: QShowEvent) -> None:
        super().showEvent(event)
        self._shown = True
        if self._plots_built:
            self._readouts_dirty = True
            self.refresh()
        else:  # the first show: readouts now, the plots after the first paint (paintEvent)
            self._readouts_dirty = False
            self._paint_readouts()
        if self._relative_now() is not None:
            self._clock.request(self._tick)  # the time axis keeps time

    def paintEvent(self, event: QPaintEvent) -> None:
        super().paintEvent(event)
        if not self._plots_built and not self._plots_scheduled:
            self._plots_scheduled = True  # the window's first paint is under way: plots right after it
            QTimer.singleShot(0, self, self.refresh)

    def hideEvent(self, event: QHideEvent) -> None:
        self._shown = False
        self._clock.cancel(self._tick)
        super().hideEvent(event)

    def closeEvent(self, event: QCloseEvent) -> None:
        self._shown = False
        self._clock.cancel(self._tick)
        super().closeEvent(event)
