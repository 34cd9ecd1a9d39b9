"""Drawing primitives of the 3D view: pens, round marker sprites, and reusable native arrays
for ``drawLines`` / ``drawPixmapFragments`` filled from numpy (pyqtgraph's ``PrimitiveArray``:
no Python object per line or marker)."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from pyqtgraph.Qt.internals import PrimitiveArray
from PySide6.QtCore import QLineF, QPointF, QRectF, Qt
from PySide6.QtGui import QColor, QPainter, QPen, QPixmap

from ui.palette import COLOR_WHITE

FloatArray = NDArray[np.float64]


def pen(color: str, width: float, *, round_cap: bool = False) -> QPen:
    """Flat caps unless asked: round caps on thousands of antialiased lines cost seconds."""
    result = QPen(QColor(color), width)
    result.setCapStyle(Qt.PenCapStyle.RoundCap if round_cap else Qt.PenCapStyle.FlatCap)
    return result


def _sprite(color: str, size: int, ring: bool = False) -> QPixmap:
    """A round marker, drawn once and stamped many times (drawPixmapFragments)."""
    pix = QPixmap(size + 2, size + 2)
    pix.fill(Qt.GlobalColor.transparent)
    p = QPainter(pix)
    p.setRenderHint(QPainter.RenderHint.Antialiasing)
    if ring:
        p.setPen(pen(color, 2.0))
        p.setBrush(Qt.BrushStyle.NoBrush)
        p.drawEllipse(QRectF(2, 2, size - 2, size - 2))
    else:
        p.setPen(pen(COLOR_WHITE, 1.0))
        p.setBrush(QColor(color))
        p.drawEllipse(QRectF(1, 1, size, size))
    p.end()
    return pix


class Buffers:
    """Reusable native arrays for drawPoints / drawLines."""

    def __init__(self) -> None:
        self.points = PrimitiveArray(QPointF, 2)
        self.lines = PrimitiveArray(QLineF, 4)
        self.fragments = PrimitiveArray(QPainter.PixmapFragment, 10)
        self.sprites: dict[tuple[str, int, bool], QPixmap] = {}

    def draw_sprites(self, painter: QPainter, xy: FloatArray, color: str, size: int,
                     ring: bool = False) -> None:
        """One marker per row of ``xy`` (non-finite rows skipped), in one call."""
        xy = xy[np.isfinite(xy).all(axis=1)]
        if not len(xy):
            return
        key = (color, size, ring)
        sprite = self.sprites.get(key)
        if sprite is None:
            sprite = self.sprites[key] = _sprite(color, size, ring)
        self.fragments.resize(len(xy))
        frag = self.fragments.ndarray()
        frag[:, 0:2] = xy
        frag[:, 2:4] = 0.0
        frag[:, 4] = sprite.width()
        frag[:, 5] = sprite.height()
        frag[:, 6:8] = 1.0
        frag[:, 8] = 0.0
        frag[:, 9] = 1.0
        fragments, count = self.fragments.drawargs()  # (the array's pointer, its length)
        painter.drawPixmapFragments(fragments, count, sprite)

    def draw_points(self, painter: QPainter, xy: FloatArray) -> None:
        xy = xy[np.isfinite(xy).all(axis=1)]
        if len(xy):
            self.points.resize(len(xy))
            self.points.ndarray()[:] = xy
            painter.drawPoints(*self.points.drawargs())

    def draw_lines(self, painter: QPainter, segs: FloatArray) -> None:
        """``segs`` (k, 4): x1 y1 x2 y2 per line; rows with NaN are skipped."""
        segs = segs[np.isfinite(segs).all(axis=1)]
        if len(segs):
            self.lines.resize(len(segs))
            self.lines.ndarray()[:] = segs
            painter.drawLines(*self.lines.drawargs())


def polyline_pairs(xy: FloatArray) -> FloatArray:
    """(k, 4) lines between consecutive rows (NaN rows break the line)."""
    if len(xy) < 2:
        return np.zeros((0, 4))
    return np.concatenate([xy[:-1], xy[1:]], axis=1)
