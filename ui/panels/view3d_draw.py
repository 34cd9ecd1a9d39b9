"""Drawing primitives of the 3D view: pens, marker sprites, and reusable native arrays for
``drawLines`` / ``drawPixmapFragments`` filled from numpy (pyqtgraph's ``PrimitiveArray``:
no Python object per line or marker)."""

from __future__ import annotations

import functools

import numpy as np
from numpy.typing import NDArray
from pyqtgraph.Qt.internals import PrimitiveArray
from PySide6.QtCore import QLineF, QPointF, QRectF, Qt
from PySide6.QtGui import QColor, QPainter, QPen, QPixmap

from ui.palette import COLOR_WHITE

FloatArray = NDArray[np.float64]


@functools.lru_cache(maxsize=64)
def pen(color: str, width: float, *, round_cap: bool = False) -> QPen:
    """Flat caps unless asked: round caps on thousands of antialiased lines cost seconds.
    Made once per style (a QColor from its name costs more than the lines of a small layer);
    callers must not change the pen they get."""
    result = QPen(QColor(color), width)
    result.setCapStyle(Qt.PenCapStyle.RoundCap if round_cap else Qt.PenCapStyle.FlatCap)
    return result


def _sprite(color: str, size: int, ring: bool = False, square: bool = False) -> QPixmap:
    """A round (or square) marker, drawn once and stamped many times (drawPixmapFragments)."""
    pix = QPixmap(size + 2, size + 2)
    pix.fill(Qt.GlobalColor.transparent)
    p = QPainter(pix)
    p.setRenderHint(QPainter.RenderHint.Antialiasing)
    if square:  # an arc's middle point: white with a coloured edge
        p.setPen(pen(color, 1.0))
        p.setBrush(QColor(COLOR_WHITE))
        p.drawRect(QRectF(1.5, 1.5, size - 1, size - 1))
    elif ring:
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
        self.sprites: dict[tuple[str, int, bool, bool], QPixmap] = {}

    def draw_sprites(
        self,
        painter: QPainter,
        xy: FloatArray,
        color: str,
        size: int,
        ring: bool = False,
        square: bool = False,
    ) -> None:
        """One marker per row of ``xy`` (non-finite rows skipped), in one call."""
        finite = np.isfinite(xy).all(axis=1)
        if not finite.all():
            xy = xy[finite]
        if not len(xy):
            return
        key = (color, size, ring, square)
        sprite = self.sprites.get(key)
        if sprite is None:
            sprite = self.sprites[key] = _sprite(color, size, ring, square)
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
        finite = np.isfinite(segs).all(axis=1)
        if not finite.all():
            segs = segs[finite]
        if len(segs):
            self.lines.resize(len(segs))
            self.lines.ndarray()[:] = segs
            painter.drawLines(*self.lines.drawargs())

    def draw_polyline(self, painter: QPainter, xy: FloatArray) -> None:
        """Lines between consecutive rows of ``xy`` (NaN rows break the line), written straight
        into the native array (no (k, 4) copy in between)."""
        if len(xy) < 2:
            return
        if not np.isfinite(xy).all():
            self.draw_lines(painter, polyline_pairs(xy))
            return
        self.lines.resize(len(xy) - 1)
        out = self.lines.ndarray()
        out[:, 0:2] = xy[:-1]
        out[:, 2:4] = xy[1:]
        painter.drawLines(*self.lines.drawargs())


def polyline_pairs(xy: FloatArray) -> FloatArray:
    """(k, 4) lines between consecutive rows (NaN rows break the line)."""
    if len(xy) < 2:
        return np.zeros((0, 4))
    return np.concatenate([xy[:-1], xy[1:]], axis=1)
