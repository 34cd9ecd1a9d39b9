"""Where the 3D view writes its point names, so that no two overlap (widget-free).

Labels are placed greedily in priority order: each tries four places around its marker (above
right, above left, below right, below left) and takes the first that stays inside the viewport
and touches no label placed before it; a label with no such place is left out. The first
``must`` labels of the order (the hovered and the selected points) are always written: when
none of their places is free they take the first one anyway (they can then only overlap each
other, never a lower-priority label, which comes later and must find a free place).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Final

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]

LABEL_OFFSET_PX: Final = 6.0  # from the marker's centre to the label's nearest corner
LABEL_GAP_PX: Final = 1.0  # labels closer than this count as touching

Rect = tuple[float, float, float, float]  # x, y, width, height (screen pixels, y down)


def _places(x: float, y: float, w: float, h: float) -> list[Rect]:
    d = LABEL_OFFSET_PX
    return [
        (x + d, y - d - h, w, h),  # above right (the usual place)
        (x - d - w, y - d - h, w, h),  # above left
        (x + d, y + d, w, h),  # below right
        (x - d - w, y + d, w, h),  # below left
    ]


def _inside(r: Rect, width: float, height: float) -> bool:
    return r[0] >= 0 and r[1] >= 0 and r[0] + r[2] <= width and r[1] + r[3] <= height


def _free(r: Rect, placed: list[Rect]) -> bool:
    g = LABEL_GAP_PX
    for p in placed:
        if (
            r[0] < p[0] + p[2] + g
            and p[0] < r[0] + r[2] + g
            and r[1] < p[1] + p[3] + g
            and p[1] < r[1] + r[3] + g
        ):
            return False
    return True


def place_labels(
    anchors: FloatArray,
    sizes: FloatArray,
    order: Sequence[int],
    viewport: tuple[float, float],
    must: int = 0,
    blocked: Sequence[Rect] = (),
) -> list[tuple[int, Rect]]:
    """(row, rectangle) of every label written, in ``order`` (rows of ``anchors``: the markers'
    screen positions, ``sizes``: each label's width and height), clear of the ``blocked``
    rectangles (the view's badges and scale) like of each other. See the module docstring."""
    width, height = viewport
    placed: list[Rect] = list(blocked)
    out: list[tuple[int, Rect]] = []
    for i, row in enumerate(order):
        x, y = float(anchors[row, 0]), float(anchors[row, 1])
        if not (np.isfinite(x) and np.isfinite(y)):
            continue
        places = _places(x, y, float(sizes[row, 0]), float(sizes[row, 1]))
        chosen = next((r for r in places if _inside(r, width, height) and _free(r, placed)), None)
        if chosen is None and i < must:
            chosen = next((r for r in places if _free(r, placed)), places[0])
        if chosen is not None:
            placed.append(chosen)
            out.append((int(row), chosen))
    return out
