"""The monitor's plot helpers: angle unwrapping, plot styling and the compact legend."""

from __future__ import annotations

from typing import TYPE_CHECKING

from PySide6.QtGui import QFont

if TYPE_CHECKING:  # imported when the first plot is built (the window's first paint goes first)
    import pyqtgraph as pg

__all__ = ["AXIS_TICK_POINTS", "GRID_COLOR", "LEFT_AXIS_WIDTH", "add_legend", "style_plot", "unwrap_degrees"]

AXIS_TICK_POINTS = 9.0
LEFT_AXIS_WIDTH = 52  # px: room for "-8888" labels, so the plots do not shift as values change
GRID_COLOR = "#dde3e6"
# px: two stacked plots + the tiles above them set the Monitor tab's height, the tallest tab; with
# the alarm banner up at 1280x800 (Chinese fonts are taller) 2 x 90 px did not fit
PLOT_MIN_HEIGHT = 80


def unwrap_degrees(previous_raw: float, previous_unwrapped: float, raw: float) -> float:
    """Continue an unwrapped angle: the step from ``previous_raw`` to ``raw`` taken the short way
    round (so -179 -> +179 is a 2 degree step, not 358), added to ``previous_unwrapped``."""
    step = (raw - previous_raw + 180.0) % 360.0 - 180.0
    return previous_unwrapped + step


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
    item.getAxis("left").setWidth(LEFT_AXIS_WIDTH)
    plot.setMenuEnabled(False)
    plot.setMinimumHeight(PLOT_MIN_HEIGHT)
    plot.setMinimumWidth(120)
