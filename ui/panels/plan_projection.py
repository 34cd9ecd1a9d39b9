"""One projection of the plan preview (:mod:`ui.panels.plan_preview`): its plot styled for a
preview (fixed axes, locked aspect) and the items drawn on it: the path, the selected segment,
the points and their labels, the start, the live TCP and its trail, the safety envelope's boxes.
pyqtgraph is imported when a projection is built (the planner is a hidden tab at start).

The point labels are plain Qt items (``QGraphicsSimpleTextItem``, no Python ``paint``), made once
per projection and label slot and reused (new text, position, shown / hidden), never pyqtgraph
``TextItem``s removed and re-created at each plan change: with PySide6 6.11.2/6.11.3 a Python
exception pending while Qt paints a *new* item with a Python ``paint`` (an exception from another
item's ``paint``) makes shiboken release a reference it does not own to the class's ``paint``
function — re-created labels drained ``TextItem.paint`` until it was freed (a segfault). See
``tests/ui/panels/test_plan_labels_crash.py``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray
from PySide6.QtCore import QMarginsF, QPointF, QRectF, Qt
from PySide6.QtGui import QBrush, QColor, QTransform
from PySide6.QtWidgets import QGraphicsItem, QGraphicsSimpleTextItem

from ui.palette import (
    COLOR_AXIS,
    COLOR_HIGHLIGHT,
    COLOR_INK,
    COLOR_INK_SOFT,
    COLOR_PATH,
    COLOR_START,
    COLOR_TCP,
    COLOR_TRAIL,
)
from ui.palette import COLOR_ERROR as COLOR_KEEP_OUT
from ui.palette import COLOR_OK as COLOR_KEEP_IN

if TYPE_CHECKING:
    import pyqtgraph as pg

MAX_LABELS = 40  # point labels drawn (more would clutter and cost)
PLOT_MIN_SIDE = 200  # px: each projection the planner shows is at least this wide and high
MIN_LABEL_SPACING_PX = 44  # between two labelled ticks of the X axis: "-1200" and a gap
LABEL_MARGIN_PX = 4  # round a label's text: off its point's dot, apart from its neighbours

#: Where a point's label goes (the label's corner at the point, as fractions of its width and
#: height from its top left), first free one first: above right, above left, below right, below left.
LABEL_ANCHORS: tuple[tuple[float, float], ...] = ((0.0, 1.0), (1.0, 1.0), (0.0, 0.0), (1.0, 0.0))

FloatArray = NDArray[np.float64]


def point_tip(x: float, y: float, data: object) -> str:
    """The tooltip of a point under the mouse: its label (hidden where labels would pile up)."""
    return f"{data}  ({x:.1f}, {y:.1f} mm)" if data else f"({x:.1f}, {y:.1f} mm)"


def wider_interval(interval: float) -> float:
    """The next round tick interval after ``interval`` (…, 1, 2, 5, 10, 20, …)."""
    power = 10.0 ** math.floor(math.log10(interval))
    leading = round(interval / power)
    if leading < 2:
        return 2.0 * power
    if leading < 5:
        return 5.0 * power
    return 10.0 * power


def spaced_levels(
    levels: list[tuple[float, float]], span: float, size_px: float, min_px: float = MIN_LABEL_SPACING_PX
) -> list[tuple[float, float]]:
    """pyqtgraph's tick levels with the labelled (first) level at least ``min_px`` apart.

    pyqtgraph always labels its first level, however narrow the axis: at 1280×800 a projection is
    ~65 px wide and its labels ran into each other ("400600"). Finer levels stay as unlabelled ticks
    (pyqtgraph labels them only where there is room).
    """
    if not levels or span <= 0 or size_px <= 0:
        return levels
    major = levels[0][0]
    if major <= 0 or not math.isfinite(major):
        return levels
    while major * size_px / span < min_px and major < span:
        major = wider_interval(major)
    return [(major, 0.0)] + [level for level in levels[1:] if level[0] < major]


_axis_class: type[pg.AxisItem] | None = None


def spaced_axis(orientation: str) -> pg.AxisItem:
    """An axis whose labels never touch (see :func:`spaced_levels`)."""
    global _axis_class
    if _axis_class is None:
        import pyqtgraph as pg  # deferred: see the module docstring

        class SpacedAxis(pg.AxisItem):  # type: ignore[misc]
            def tickSpacing(self, minVal: float, maxVal: float, size: float) -> list[tuple[float, float]]:  # noqa: N803
                levels = super().tickSpacing(minVal, maxVal, size)
                if self._tickSpacing is not None:
                    return list(levels)
                return spaced_levels(list(levels), abs(maxVal - minVal), size)

        _axis_class = SpacedAxis
    return _axis_class(orientation=orientation)


def style_plot(plot: pg.PlotWidget) -> None:
    import pyqtgraph as pg  # deferred: see the module docstring

    plot.setBackground("w")
    item = plot.getPlotItem()
    item.setAxisItems({"bottom": spaced_axis("bottom")})
    item.showGrid(x=True, y=True, alpha=0.25)
    for name in ("left", "bottom"):
        axis = item.getAxis(name)
        axis.enableAutoSIPrefix(False)
        axis.setPen(pg.mkPen(COLOR_AXIS))
        axis.setTextPen(pg.mkPen(COLOR_INK))
    # a fixed left axis: an auto-sized one changes the view's width with its tick labels, and an
    # aspect-locked view then changes its range, hence its labels: an endless relayout when narrow
    item.getAxis("left").setWidth(44)
    plot.setMenuEnabled(False)
    plot.setAspectLocked(True)
    plot.getViewBox().setDefaultPadding(0.12)  # room for the point labels at the edges
    plot.setMinimumSize(PLOT_MIN_SIDE, PLOT_MIN_SIDE)


class Projection:
    """The items of one projection."""

    def __init__(self, plot: pg.PlotWidget, h: int, v: int) -> None:
        import pyqtgraph as pg  # deferred: see the module docstring

        self.plot = plot
        self.h = h
        self.v = v
        self.path = pg.PlotCurveItem(pen=pg.mkPen(COLOR_PATH, width=2), connect="finite", antialias=True)
        self.selected = pg.PlotCurveItem(
            pen=pg.mkPen(COLOR_HIGHLIGHT, width=5), connect="finite", antialias=True
        )
        self.points = pg.ScatterPlotItem(
            size=7, brush=pg.mkBrush(COLOR_AXIS), pen=pg.mkPen("w"), hoverable=True, tip=point_tip
        )
        self.start = pg.ScatterPlotItem(
            size=11, symbol="t1", brush=pg.mkBrush(COLOR_START), pen=pg.mkPen("w")
        )
        self.trail = pg.PlotCurveItem(pen=pg.mkPen(COLOR_TRAIL, width=2))
        self.tcp = pg.ScatterPlotItem(
            size=13, symbol="o", brush=pg.mkBrush(COLOR_TCP), pen=pg.mkPen(COLOR_INK)
        )
        # the safety envelope (added at the first envelope): each box's 12 edges projected, dashed
        self.keep_in: pg.PlotCurveItem | None = None
        self.keep_out: pg.PlotCurveItem | None = None
        # label slots, made as needed (at most MAX_LABELS) and kept: the first len(_label_at) are used
        self._slots: list[QGraphicsSimpleTextItem] = []
        self._label_at: list[tuple[float, float]] = []  # each used label's point (view coordinates)
        plot.getViewBox().sigTransformChanged.connect(self.place_labels)
        for z, item in enumerate((self.path, self.selected, self.points, self.start, self.trail, self.tcp)):
            item.setZValue(z)
            plot.addItem(item)

    def set_boxes(self, keep_in: FloatArray, keep_out: FloatArray) -> None:
        """Outline rectangles of the envelope's boxes (point pairs of :meth:`Box.edges`)."""
        if self.keep_in is None or self.keep_out is None:
            if not len(keep_in) and not len(keep_out):
                return
            import pyqtgraph as pg  # deferred: see the module docstring

            dash = Qt.PenStyle.DashLine
            pairs = "pairs"
            self.keep_in = pg.PlotCurveItem(pen=pg.mkPen(COLOR_KEEP_IN, width=1, style=dash), connect=pairs)
            self.keep_out = pg.PlotCurveItem(pen=pg.mkPen(COLOR_KEEP_OUT, width=2, style=dash), connect=pairs)
            for item in (self.keep_in, self.keep_out):
                item.setZValue(-1)
                # drawn, but the view fits the plan: a keep-in box is often the arm's whole reach
                self.plot.addItem(item, ignoreBounds=True)
        self.keep_in.setData(keep_in[:, self.h], keep_in[:, self.v])
        self.keep_out.setData(keep_out[:, self.h], keep_out[:, self.v])

    def set_labels(self, xyz: FloatArray, texts: Sequence[str]) -> None:
        """Label the first :data:`MAX_LABELS` points; the label items are reused (see the module
        docstring), the ones not needed are hidden."""
        self._label_at = []
        for i, (row, text) in enumerate(zip(xyz[:MAX_LABELS], texts[:MAX_LABELS], strict=False)):
            label = self._label(i)
            at = (float(row[self.h]), float(row[self.v]))
            label.setText(text)
            label.setPos(*at)
            self._label_at.append(at)
        for label in self._slots[len(self._label_at) :]:
            label.setVisible(False)
        self.place_labels()

    def _label(self, i: int) -> QGraphicsSimpleTextItem:
        """Label slot ``i``, made (once) on first use."""
        while len(self._slots) <= i:
            label = QGraphicsSimpleTextItem()
            label.setBrush(QBrush(QColor(COLOR_INK_SOFT)))
            # its size in pixels whatever the zoom, its position a point of the plot
            label.setFlag(QGraphicsItem.GraphicsItemFlag.ItemIgnoresTransformations)
            label.setZValue(10)
            label.setVisible(False)
            self.plot.getViewBox().addItem(label, ignoreBounds=True)
            self._slots.append(label)
        return self._slots[i]

    @property
    def labels(self) -> list[QGraphicsSimpleTextItem]:
        """The labels of the points (shown, or hidden where they would cover another)."""
        return self._slots[: len(self._label_at)]

    def place_labels(self) -> None:
        """Give each label the first corner of its point where it covers no label placed before
        it, on screen; a label with no free corner is hidden (its point names it on hover).

        Labels keep their screen size whatever the zoom, so this is done again whenever the view
        changes (a zoom, a pan, a resize): points that lie close ("P2P3P4") are named one by one
        as the operator zooms in."""
        view = self.plot.getViewBox()
        taken: list[QRectF] = []
        for i, (x, y) in enumerate(self._label_at):
            label = self._slots[i]
            text = label.boundingRect().size()
            size = text.grownBy(QMarginsF(*(LABEL_MARGIN_PX,) * 4))
            at = view.mapViewToScene(QPointF(x, y))
            free = None
            for ax, ay in LABEL_ANCHORS:
                box = QRectF(
                    at.x() - size.width() * ax, at.y() - size.height() * ay, size.width(), size.height()
                )
                if not any(box.intersects(other) for other in taken):
                    free = (ax, ay)
                    taken.append(box)
                    break
            if free is not None:
                # in the label's own (pixel) coordinates: its corner ``free`` at its position
                shift = QTransform.fromTranslate(
                    LABEL_MARGIN_PX - size.width() * free[0], LABEL_MARGIN_PX - size.height() * free[1]
                )
                if label.transform() != shift:
                    label.setTransform(shift)
            label.setVisible(free is not None)
