"""A curve whose bounds are given, not computed from its data: the monitor's time curves and trace.

pyqtgraph's ``PlotCurveItem.boundingRect`` scans the data (``nanmin``/``nanmax`` on both axes)
and measures the pen in pixels each time the data or the view changes; the scene asks for it
dozens of times per frame. While streaming, that was about a tenth of the GUI thread's time
(``python -m benchmarks.streaming``, profiled with py-spy). The monitor knows where its curves
are -- inside the window it shows, whose range it sets itself -- so it tells the curve.

Imported when the plots are built (pyqtgraph is not loaded before the window's first paint).
"""

from __future__ import annotations

from typing import Any

import pyqtgraph as pg
from PySide6.QtCore import QRectF

__all__ = ["BoundedCurve"]


class BoundedCurve(pg.PlotCurveItem):  # type: ignore[misc]  # pyqtgraph is not typed
    """A ``PlotCurveItem`` bounded by :meth:`set_bounds` (an empty rect until then).

    Every point must lie inside the bounds: the scene repaints only there. The monitor gives
    each curve the range its plot shows, which holds every point the curve has.
    """

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self._bounds = QRectF()

    def set_bounds(self, x0: float, x1: float, y0: float, y1: float) -> None:
        rect = QRectF(x0, y0, x1 - x0, y1 - y0)
        if rect != self._bounds:
            self.prepareGeometryChange()
            self._bounds = rect

    def boundingRect(self) -> QRectF:
        return self._bounds
