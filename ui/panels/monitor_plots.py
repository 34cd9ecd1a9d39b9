"""The monitor's plots: XYZ and ABC over time, the X–Y top view, and their helpers.

:class:`MonitorPlots` builds the pyqtgraph widgets (pyqtgraph is imported only then, after the
window's first paint) and draws from the monitor's ring buffers: contiguous views, no copies,
a stride when a window holds more samples than the plot has pixels to show them.

What a plot frame costs is mostly what changes in it (``python -m benchmarks.streaming``), so
the frame keeps the rest still:

* The time axis is "seconds ago" (``-window .. 0``): it is set once per window, and its tick
  labels and grid do not move; only the curves do. A scrolling axis regenerated its labels,
  re-laid out both plots and recomputed every curve's bounds in every frame.
* The vertical ranges are set by the plots, not by pyqtgraph's auto-range (which scanned every
  curve in every frame): from the window's extremes, padded and snapped to round values, and
  only set again when a value leaves the range or the values use less than a third of it.
* The curves are told their bounds (:class:`~ui.panels.monitor_curve.BoundedCurve`: the range
  their plot shows) instead of scanning their data for them many times a frame.
* The top view's marker is one ellipse moved with ``setPos`` (a scatter item rebuilt its spot
  table for one point in every frame), and the top view is redrawn in a frame only when the
  marker moved a pixel or more since it was drawn (:meth:`MonitorPlots.trace_moved`): a slow
  arm's trace grows by less than a pixel per frame.
* The axes (their tick labels and the grid they draw across the plot) and the legends are
  cached as pixmaps (``DeviceCoordinateCache``): the curves move under them in every frame and
  the scene repaints whatever they cover, but an axis is drawn again only when its ticks
  change. Replaying their drawings was about a quarter of a plot frame.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from PySide6.QtCore import Qt
from PySide6.QtGui import QBrush, QColor, QFont, QPen
from PySide6.QtWidgets import QGraphicsEllipseItem, QGraphicsItem, QSizePolicy, QSplitter, QWidget

from ui.models.ring_buffer import RingBuffer
from ui.panels.monitor_figures import (
    CARTESIAN,
    MAX_PLOT_POINTS,
    PAINT_MARGIN,
    TRACE_MIN_SPAN_MM,
)

if TYPE_CHECKING:
    import numpy as np
else:  # numpy is imported by its first use, not with this module (app/lazy_numpy.py)
    from app.lazy_numpy import np

if TYPE_CHECKING:  # imported when the first plot is built (the window's first paint goes first)
    import pyqtgraph as pg

    from ui.panels.monitor_curve import BoundedCurve

__all__ = [
    "AXIS_TICK_POINTS",
    "GRID_COLOR",
    "LEFT_AXIS_WIDTH",
    "MIN_PLOT_POINTS",
    "MonitorPlots",
    "add_legend",
    "cache_legend",
    "fit_range",
    "style_plot",
    "unwrap_degrees",
]

AXIS_TICK_POINTS = 9.0
LEFT_AXIS_WIDTH = 52  # px: room for "-8888" labels, so the plots do not shift as values change
GRID_COLOR = "#dde3e6"
# px: two stacked plots + the tiles above them set the Monitor tab's height, the tallest tab; with
# the alarm banner up at 1280x800 (Chinese fonts are taller) 2 x 90 px did not fit; 80 left no
# room once the external axes read J7..J11 (their narrower captions take a half point larger font)
PLOT_MIN_HEIGHT = 76
# Points per curve: two per pixel of the plot's width, within MIN_PLOT_POINTS..MAX_PLOT_POINTS
# (ui/panels/monitor_figures.py, with CARTESIAN, PAINT_MARGIN, TRACE_MIN_SPAN_MM and
# PLOT_INTERVAL_MS: the panel needs them before the plots exist).
MIN_PLOT_POINTS = 1000
POINTS_PER_PIXEL = 2
CURVE_WIDTH = 1  # px, the time curves and the top view's trace (see MonitorPlots)
TRACE_PADDING = 0.08  # fraction of the span around the trace
# Vertical ranges (see fit_range): padding around the values, the smallest span shown (a still
# arm's flat line, not its noise magnified), and how little of the range the values may use
# before it is narrowed again.
RANGE_PADDING = 0.1
RANGE_MIN_SPAN = 2.0  # mm on the position plot, degrees on the orientation plot
RANGE_MIN_USE = 1.0 / 3.0
MARKER_SIZE = 11  # px, the top view's "now" marker
_CACHED = QGraphicsItem.CacheMode.DeviceCoordinateCache  # the axes' and legends' cache

# History channels: time, then X Y Z and the unwrapped A B C.
T, X = 0, 1
_PLOT_COLORS = {
    "X": "#d62728",
    "Y": "#2ca02c",
    "Z": "#1f77b4",
    "A": "#d62728",
    "B": "#2ca02c",
    "C": "#1f77b4",
}
_TRACE_COLOR = "#6a1b9a"
_PLOT_NAMES = {"xyz": CARTESIAN[:3], "abc": CARTESIAN[3:]}


def unwrap_degrees(previous_raw: float, previous_unwrapped: float, raw: float) -> float:
    """Continue an unwrapped angle: the step from ``previous_raw`` to ``raw`` taken the short way
    round (so -179 -> +179 is a 2 degree step, not 358), added to ``previous_unwrapped``."""
    step = (raw - previous_raw + 180.0) % 360.0 - 180.0
    return previous_unwrapped + step


def _nice_step(raw: float) -> float:
    """The round step (1, 2 or 5 times a power of ten) at or above ``raw`` (> 0)."""
    power = 10.0 ** math.floor(math.log10(raw))
    for factor in (1.0, 2.0, 5.0, 10.0):
        if raw <= factor * power:
            return factor * power
    return 10.0 * power


def fit_range(
    current: tuple[float, float] | None, lo: float, hi: float, min_span: float = RANGE_MIN_SPAN
) -> tuple[float, float]:
    """The vertical range to show values between ``lo`` and ``hi``: ``current`` while they stay
    inside it and use at least ``RANGE_MIN_USE`` of it (the axis keeps still), else a new one,
    padded by ``RANGE_PADDING`` and snapped outwards to round values."""
    if current is not None:
        c_lo, c_hi = current
        if c_lo <= lo and hi <= c_hi and max(hi - lo, min_span) >= RANGE_MIN_USE * (c_hi - c_lo):
            return current
    middle, span = (lo + hi) / 2.0, max(hi - lo, min_span)
    lo, hi = middle - span / 2.0, middle + span / 2.0
    pad = span * RANGE_PADDING
    step = _nice_step((span + 2 * pad) / 8.0)
    return math.floor((lo - pad) / step) * step, math.ceil((hi + pad) / step) * step


def add_legend(plot: pg.PlotWidget) -> None:
    """A compact one-row legend in the top-right corner, translucent so the curves show through."""
    import pyqtgraph as pg

    plot.addLegend(
        offset=(-4, 2),  # negative x: anchored to the right edge
        colCount=3,
        labelTextColor="#263238",
        brush=pg.mkBrush(255, 255, 255, 150),
        pen=pg.mkPen(176, 190, 197, 160),
        verSpacing=-6,
        horSpacing=8,
    )


def cache_legend(plot: pg.PlotWidget) -> None:
    """Cache the legend and each of its parts (samples, labels, their text items) as pixmaps, once
    its rows are in: a cached item does not cache its children, and the legend sits on the
    curves, so without that each label's text was laid out and drawn again in every frame."""
    pending: list[QGraphicsItem] = [plot.getPlotItem().legend]
    while pending:
        item = pending.pop()
        item.setCacheMode(_CACHED)
        pending.extend(item.childItems())


def style_plot(plot: pg.PlotWidget) -> None:
    import pyqtgraph as pg

    plot.setBackground("w")
    item = plot.getPlotItem()
    item.showGrid(x=True, y=True)
    for name in ("left", "bottom"):
        axis = item.getAxis(name)
        # an opaque light grid: a translucent one (alpha < 1) is blended on every repaint and
        # cost ~3x the paint time of the three plots at 30 Hz (benchmarks/gui.py)
        axis.setTickPen(pg.mkPen(GRID_COLOR))
        axis.setStyle(tickAlpha=255, maxTickLevel=1)  # major and minor lines only
        axis.setZValue(-100)  # grid behind the curves
        axis.enableAutoSIPrefix(False)  # "1500 mm", never "1.5 kmm"
        axis.setPen(pg.mkPen("#455a64"))
        axis.setTextPen(pg.mkPen("#263238"))
        font = QFont()
        font.setPointSizeF(AXIS_TICK_POINTS)
        axis.setStyle(tickFont=font)
        # a pixmap, drawn again only when its ticks change (AxisItem.update): the curves below
        # it repaint in every frame, and with them the part of the grid they cover
        axis.setCacheMode(_CACHED)
    for name in ("top", "right"):  # hidden, but linked to the view: no label update per new range
        item.getAxis(name).enableAutoSIPrefix(False)
    item.getAxis("left").setWidth(LEFT_AXIS_WIDTH)
    plot.setMenuEnabled(False)
    plot.setMinimumHeight(PLOT_MIN_HEIGHT)
    plot.setMinimumWidth(120)


class MonitorPlots:
    """The three plots in their splitters (``widget``), drawn from the monitor's ring buffers."""

    def __init__(self, parent: QWidget) -> None:
        import pyqtgraph as pg

        from ui.panels.monitor_curve import BoundedCurve

        self.xyz_plot = pg.PlotWidget(parent)
        self.abc_plot = pg.PlotWidget(parent)
        self.trace_plot = pg.PlotWidget(parent)
        for plot in (self.xyz_plot, self.abc_plot, self.trace_plot):
            style_plot(plot)
        self.abc_plot.setXLink(self.xyz_plot)
        self.xyz_plot.getPlotItem().hideAxis("bottom")
        for plot in (self.xyz_plot, self.abc_plot):
            # the plots set their ranges (paint_history): no pan or zoom to fight them
            plot.setMouseEnabled(x=False, y=False)
        self.curves: dict[str, BoundedCurve] = {}
        for name in CARTESIAN:
            plot = self.xyz_plot if name in "XYZ" else self.abc_plot
            if name in ("X", "A"):
                add_legend(plot)
            # 1 px: the raster engine's fast path; a 2 px pen is stroked as polygons and cost
            # about half of the monitor's frame time (benchmarks/streaming.py, plots at 25 Hz)
            curve = BoundedCurve(pen=pg.mkPen(_PLOT_COLORS[name], width=CURVE_WIDTH), name=name)
            plot.addItem(curve)
            self.curves[name] = curve
        for plot in (self.xyz_plot, self.abc_plot):
            cache_legend(plot)

        self.trace_plot.setAspectLocked(True)
        # room on the right for the last bottom tick label (else clipped at the plot's edge)
        self.trace_plot.getPlotItem().layout.setContentsMargins(2, 2, 16, 2)
        # 1 px too: a 2 px trace was drawn as line segments, and a trace of a program running for
        # a minute (thousands of points) cost more than both time plots together
        self.trace_curve = BoundedCurve(pen=pg.mkPen(_TRACE_COLOR, width=CURVE_WIDTH))
        self.trace_plot.addItem(self.trace_curve)
        # "now" on the top view: a fixed-size dot moved with setPos (no data, no bounds of its own)
        half = MARKER_SIZE / 2.0
        self.trace_marker = QGraphicsEllipseItem(-half, -half, MARKER_SIZE, MARKER_SIZE)
        self.trace_marker.setBrush(QBrush(QColor("#ff6f00")))
        self.trace_marker.setPen(QPen(QColor("#263238")))
        self.trace_marker.setFlag(QGraphicsItem.GraphicsItemFlag.ItemIgnoresTransformations)
        self.trace_marker.setZValue(10)
        self.trace_marker.setVisible(False)
        self.trace_plot.getPlotItem().getViewBox().addItem(self.trace_marker, ignoreBounds=True)
        self._trace_range: tuple[float, float, float] | None = None  # centre x, y and half span set last
        self._marker_at: tuple[float, float] | None = None  # the marker's position drawn last
        self._trace_pixel = (0.0, 0.0)  # the top view's pixel in mm (x, y), at its last draw
        self._window_s: float | None = None  # the time axis' span set last
        self._y_ranges: dict[str, tuple[float, float]] = {}  # "xyz" / "abc" -> range set last

        time_plots = QSplitter(Qt.Orientation.Vertical, parent)
        time_plots.addWidget(self.xyz_plot)
        time_plots.addWidget(self.abc_plot)
        time_plots.setChildrenCollapsible(False)
        plots = QSplitter(Qt.Orientation.Horizontal, parent)
        plots.addWidget(time_plots)
        plots.addWidget(self.trace_plot)
        plots.setStretchFactor(0, 2)
        plots.setStretchFactor(1, 1)
        plots.setChildrenCollapsible(False)
        plots.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Expanding)
        self.widget = plots

    def max_points(self) -> int:
        """Points per curve worth drawing: two per pixel of the time plots' width, bounded."""
        width = int(self.xyz_plot.width())
        return min(MAX_PLOT_POINTS, max(MIN_PLOT_POINTS, POINTS_PER_PIXEL * width))

    def paint_history(self, history: RingBuffer, window_s: float, now: float | None) -> None:
        """The time plots: the last ``window_s`` seconds before ``now`` (relative time) or the
        newest sample, whichever is later, on a time axis of seconds before that end."""
        self._set_window(window_s)
        n = min(len(history), history.capacity - PAINT_MARGIN)
        if n <= 0:
            for curve in self.curves.values():
                curve.setData([], [])
            return
        t = history.view(T, n)
        t_end = float(t[-1]) if now is None else max(float(t[-1]), now)
        start = int(np.searchsorted(t, t_end - window_s, side="left"))
        count = n - start
        if count <= 0:  # nothing within the window (a long silence): empty plots, ranges kept
            for curve in self.curves.values():
                curve.setData([], [])
            return
        step = max(1, -(-count // self.max_points()))
        first = start + (count - 1) % step  # keep the newest sample on the stride
        t_view = t[first::step] - t_end  # seconds ago: <= 0, the newest at the right edge
        for channel, name in enumerate(CARTESIAN, start=X):
            self.curves[name].setData(t_view, history.view(channel, n)[first::step], skipFiniteCheck=True)
        block = history.views(n)[:, first::step]
        ranges = (("xyz", self.xyz_plot, block[X : X + 3]), ("abc", self.abc_plot, block[X + 3 :]))
        for key, plot, rows in ranges:
            shown = self._y_ranges.get(key)
            wanted = fit_range(shown, float(rows.min()), float(rows.max()))
            if wanted != shown:
                self._y_ranges[key] = wanted
                plot.setYRange(*wanted, padding=0)
            for name in _PLOT_NAMES[key]:  # every point of the curve is in the range its plot shows
                self.curves[name].set_bounds(-window_s, 0.0, *wanted)

    def _set_window(self, window_s: float) -> None:
        if window_s != self._window_s:
            self._window_s = window_s
            self.xyz_plot.setXRange(-window_s, 0.0, padding=0)  # the ABC plot is linked to it

    def trace_moved(self, trace: RingBuffer) -> bool:
        """Whether the trace's newest point is a pixel or more (in x or y) from where the marker
        was drawn last, or the trace is new or empty: else redrawing the top view would show
        nothing new (what the trace gained since is shorter than a pixel)."""
        marker = self._marker_at
        if marker is None or not len(trace):
            return True
        px, py = self._trace_pixel
        return abs(trace.latest(0) - marker[0]) >= px or abs(trace.latest(1) - marker[1]) >= py

    def paint_trace(self, trace: RingBuffer) -> None:
        n = min(len(trace), trace.capacity - PAINT_MARGIN)
        if n <= 0:
            self.trace_curve.setData([], [])
            self.trace_marker.setVisible(False)
            self._marker_at = None
            return
        xs, ys = trace.view(0, n), trace.view(1, n)
        x0, x1, y0, y1 = float(xs.min()), float(xs.max()), float(ys.min()), float(ys.max())
        self.trace_curve.setData(xs, ys, skipFiniteCheck=True)
        # the view shows TRACE_PADDING of its span beyond the trace: half of that is a margin
        # for the pen that stays inside the view
        margin = max(x1 - x0, y1 - y0, TRACE_MIN_SPAN_MM) * TRACE_PADDING / 2.0
        self.trace_curve.set_bounds(x0 - margin, x1 + margin, y0 - margin, y1 + margin)
        marker = (float(xs[-1]), float(ys[-1]))
        self.trace_marker.setPos(*marker)
        self.trace_marker.setVisible(True)
        self._fit_trace(x0, x1, y0, y1)
        self._marker_at = marker
        self._measure_trace_pixel()  # each time: a resized view has other pixels

    def _fit_trace(self, x0: float, x1: float, y0: float, y1: float) -> None:
        """Show the whole trace, at least TRACE_MIN_SPAN_MM wide and tall, centred; the view is
        only touched when that range changes (a new range re-lays out both axes)."""
        half = max(x1 - x0, y1 - y0, TRACE_MIN_SPAN_MM) / 2.0
        wanted = ((x0 + x1) / 2.0, (y0 + y1) / 2.0, half)
        if wanted == self._trace_range:
            return
        self._trace_range = wanted
        cx, cy, _ = wanted
        view = self.trace_plot.getPlotItem().getViewBox()
        view.setRange(xRange=(cx - half, cx + half), yRange=(cy - half, cy + half), padding=TRACE_PADDING)

    def _measure_trace_pixel(self) -> None:
        """The top view's pixel in mm now, for :meth:`trace_moved`."""
        (x0, x1), (y0, y1) = self.trace_plot.getPlotItem().getViewBox().viewRange()
        rect = self.trace_plot.getPlotItem().getViewBox().boundingRect()
        width, height = max(1.0, rect.width()), max(1.0, rect.height())
        self._trace_pixel = ((x1 - x0) / width, (y1 - y0) / height)

    def forget_ranges(self) -> None:
        """Set the view ranges again at the next paint (after the plots were cleared or resized)."""
        self._trace_range = None
        self._marker_at = None
        self._window_s = None
        self._y_ranges.clear()

    def y_range(self, which: str) -> tuple[float, float] | None:
        """The vertical range set last on the ``"xyz"`` or ``"abc"`` plot (None: none yet)."""
        return self._y_ranges.get(which)

    def trace_view_range(self) -> tuple[tuple[float, float], tuple[float, float]]:
        (x0, x1), (y0, y1) = self.trace_plot.getPlotItem().getViewBox().viewRange()
        return (x0, x1), (y0, y1)
