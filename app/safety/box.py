"""Box: an axis-aligned box in the base frame (mm), the shape of the envelope's keep-in space
and keep-out zones, with the geometry its checks need.

Containment of a point or of many, the nearest face, the clearance, and chords against the box
by the slab test (exact, so a thin box between two path samples is not missed). Used by
:mod:`app.safety.envelope` (its checks and clearance serve the jog guard)
and the 3-D views (``edges``).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from app.errors import InvalidInput
from app.lazy_numpy import FloatArray

if TYPE_CHECKING:
    import numpy as np
    from numpy.typing import NDArray
else:  # numpy is imported by its first use, not with this module (app/lazy_numpy.py)
    from app.lazy_numpy import np

__all__ = ["Box"]


def _finite3(values: Sequence[float], what: str) -> tuple[float, float, float]:
    if len(values) != 3 or not all(isinstance(v, int | float) and math.isfinite(v) for v in values):
        raise InvalidInput(f"{what} needs three finite numbers (x, y, z)")
    return (float(values[0]), float(values[1]), float(values[2]))


@dataclass(frozen=True)
class Box:
    """An axis-aligned box in the base frame (mm): ``lo`` <= p <= ``hi`` on each axis."""

    name: str
    lo: tuple[float, float, float]
    hi: tuple[float, float, float]

    def __post_init__(self) -> None:
        lo = _finite3(self.lo, f"box '{self.name}' lower corner")
        hi = _finite3(self.hi, f"box '{self.name}' upper corner")
        if any(a >= b for a, b in zip(lo, hi, strict=True)):
            raise InvalidInput(f"box '{self.name}': each lower bound must be below its upper bound")
        object.__setattr__(self, "lo", lo)
        object.__setattr__(self, "hi", hi)

    @functools.cached_property
    def lo_array(self) -> FloatArray:
        return np.asarray(self.lo, dtype=np.float64)

    @functools.cached_property
    def hi_array(self) -> FloatArray:
        return np.asarray(self.hi, dtype=np.float64)

    def edges(self) -> FloatArray:
        """(24, 3): the 12 edges as point pairs, for drawing (pyqtgraph ``connect="pairs"``)."""
        lo, hi = self.lo, self.hi
        corners = np.array([[(lo, hi)[(k >> i) & 1][i] for i in range(3)] for k in range(8)])
        pairs = [(k, k | 1 << i) for k in range(8) for i in range(3) if not k >> i & 1]
        return np.asarray(corners[np.array(pairs).reshape(-1)], dtype=np.float64)

    def contains(self, p: FloatArray) -> bool:
        return bool(np.all(p >= self.lo_array) and np.all(p <= self.hi_array))

    def inside_mask(self, pts: FloatArray) -> NDArray[np.bool_]:
        """Per row of (n, 3) ``pts``: inside (or on) the box."""
        return np.asarray(np.all((pts >= self.lo_array) & (pts <= self.hi_array), axis=1))

    def depth(self, p: FloatArray) -> tuple[int, float, float]:
        """(axis, value, face) of the nearest face: how ``p`` would leave (or entered) the box."""
        lo, hi = self.lo_array, self.hi_array
        d_lo, d_hi = p - lo, hi - p
        i_lo, i_hi = int(np.argmin(d_lo)), int(np.argmin(d_hi))
        if d_lo[i_lo] <= d_hi[i_hi]:
            return i_lo, float(p[i_lo]), float(lo[i_lo])
        return i_hi, float(p[i_hi]), float(hi[i_hi])

    def clearance_inside(self, p: FloatArray) -> float:
        """Distance to the nearest face while inside (> 0); minus the distance to the box outside."""
        # plain floats: called on every jog poll, where numpy's per-call cost dominates
        out2 = 0.0
        inside = math.inf
        for v, lo, hi in zip((float(p[0]), float(p[1]), float(p[2])), self.lo, self.hi, strict=True):
            excess = max(lo - v, v - hi, 0.0)
            out2 += excess * excess
            inside = min(inside, v - lo, hi - v)
        return -math.sqrt(out2) if out2 > 0 else inside

    def chord_hits(self, a: FloatArray, b: FloatArray) -> bool:
        """Whether the chord a -> b touches the box (slab test, plain floats)."""
        t0, t1 = 0.0, 1.0
        for i in range(3):
            ai, di = float(a[i]), float(b[i]) - float(a[i])
            lo, hi = self.lo[i], self.hi[i]
            if di == 0.0:
                if ai < lo or ai > hi:
                    return False
                continue
            ta, tb = (lo - ai) / di, (hi - ai) / di
            if ta > tb:
                ta, tb = tb, ta
            t0, t1 = max(t0, ta), min(t1, tb)
            if t0 > t1:
                return False
        return True

    def segments_hit(self, a: FloatArray, b: FloatArray) -> int | None:
        """Index of the first chord ``a[k] -> b[k]`` that touches the box (slab test), or None."""
        if a.shape[0] <= 4:
            return next((k for k in range(a.shape[0]) if self.chord_hits(a[k], b[k])), None)
        lo, hi = self.lo_array, self.hi_array
        d = b - a
        with np.errstate(divide="ignore", invalid="ignore"):
            inv = 1.0 / d
            t1 = (lo - a) * inv
            t2 = (hi - a) * inv
        tmin = np.where(d == 0, np.where((a >= lo) & (a <= hi), -np.inf, np.inf), np.minimum(t1, t2))
        tmax = np.where(d == 0, np.where((a >= lo) & (a <= hi), np.inf, -np.inf), np.maximum(t1, t2))
        enter = np.max(tmin, axis=1)
        leave = np.min(tmax, axis=1)
        hit = (enter <= leave) & (leave >= 0.0) & (enter <= 1.0)
        idx = np.flatnonzero(hit)
        return int(idx[0]) if idx.size else None

    def entry_point(self, a: FloatArray, b: FloatArray) -> FloatArray:
        """Where the chord a -> b first touches the box (``a`` if it starts inside)."""
        lo, hi = self.lo_array, self.hi_array
        d = b - a
        t_enter = 0.0
        for i in range(3):
            if d[i] != 0:
                t1, t2 = (lo[i] - a[i]) / d[i], (hi[i] - a[i]) / d[i]
                t_enter = max(t_enter, min(t1, t2))
        return np.asarray(a + min(t_enter, 1.0) * d, dtype=np.float64)
