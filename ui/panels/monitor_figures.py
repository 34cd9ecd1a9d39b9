"""The monitor's figures that the panel needs before its plots exist.

The panel, its readouts and :mod:`ui.panels.monitor_plots` (the pyqtgraph plots, built after
the window's first paint) import them from here, so the window's first paint does not import the
plots' module.
"""

from __future__ import annotations

__all__ = ["CARTESIAN", "MAX_PLOT_POINTS", "PAINT_MARGIN", "PLOT_INTERVAL_MS", "TRACE_MIN_SPAN_MM"]

CARTESIAN = ("X", "Y", "Z", "A", "B", "C")
# Points per curve: two per pixel of the plot's width, at most this many (see monitor_plots);
# longer windows are drawn with a stride (still a view). Drawing 2 px wide lines costs in
# proportion to the points.
MAX_PLOT_POINTS = 2500
# Curves keep a view of the ring buffer until the scene repaints; never hand them the whole
# buffer, so samples arriving before that repaint cannot overwrite what they show.
PAINT_MARGIN = 512
TRACE_MIN_SPAN_MM = 50.0  # the top view never zooms in closer than this (readable labels)
# The plots' frame period: every other display frame (10 Hz). The readouts above them show the
# newest pose at the display rate; a curve that moves 10 times a second still reads as live, and
# the plots were most of the monitor's painting (benchmarks/streaming.py).
PLOT_INTERVAL_MS = 100
