"""Where a plan goes: arc geometry (the circle through S, M, E), sampling for drawing, lengths.

A LINE is straight; an ARC is the true circle through its start S, middle M and end E (centre
= circumcentre, in the plane of the three points), travelled S -> M -> E. Vectorised over
segments with numpy; NaN rows stand for what is unknown (a missing point, no start pose).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from app.errors import InvalidInput
from app.lazy_numpy import FloatArray
from app.models import Pose
from app.plan.segments import Plan, Segment
from app.points.ledger import PointLedger
from app.points.point import TempPoint

if TYPE_CHECKING:
    import numpy as np
    from numpy.typing import NDArray
else:  # numpy is imported by its first use, not with this module (app/lazy_numpy.py)
    from app.lazy_numpy import np

DEFAULT_SAMPLES = 32  # samples per segment for drawing

PointLike = Pose | TempPoint | Sequence[float] | FloatArray


def xyz_of(obj: PointLike) -> FloatArray:
    """XYZ (mm) of a pose, a point, or a sequence / array whose first three values are XYZ."""
    if isinstance(obj, Pose | TempPoint):
        return np.array((obj.x, obj.y, obj.z), dtype=np.float64)
    arr = np.asarray(obj, dtype=np.float64).reshape(-1)
    if arr.size < 3:
        raise InvalidInput(f"a start pose needs at least x y z, got {arr.size} values")
    return arr[:3].copy()


@dataclass(frozen=True)
class ArcGeometry:
    """Circles through (S, M, E) triples, one row per arc; NaN rows where degenerate.

    A point of the circle at angle t is ``centre + radius * (cos t * u + sin t * v)``; S is at
    t = 0, M at ``via_angle``, E at ``sweep`` (0 < via_angle < sweep < 2 pi).
    """

    centre: FloatArray  # (n, 3)
    radius: FloatArray  # (n,)
    normal: FloatArray  # (n, 3) unit, S -> M -> E counter-clockwise about it
    u: FloatArray  # (n, 3) unit, centre -> S
    v: FloatArray  # (n, 3) unit, normal x u
    via_angle: FloatArray  # (n,) rad
    sweep: FloatArray  # (n,) rad

    @property
    def length(self) -> FloatArray:
        return np.asarray(self.radius * self.sweep, dtype=np.float64)

    def rows(self, mask: NDArray[np.bool_]) -> ArcGeometry:
        """The arcs selected by a boolean mask."""
        return ArcGeometry(
            self.centre[mask],
            self.radius[mask],
            self.normal[mask],
            self.u[mask],
            self.v[mask],
            self.via_angle[mask],
            self.sweep[mask],
        )

    def masked(self, keep: NDArray[np.bool_]) -> ArcGeometry:
        """Same rows, NaN where ``keep`` is False."""
        k1, k2 = keep, keep[:, None]
        return ArcGeometry(
            np.where(k2, self.centre, np.nan),
            np.where(k1, self.radius, np.nan),
            np.where(k2, self.normal, np.nan),
            np.where(k2, self.u, np.nan),
            np.where(k2, self.v, np.nan),
            np.where(k1, self.via_angle, np.nan),
            np.where(k1, self.sweep, np.nan),
        )


def _rows_dot(p: FloatArray, q: FloatArray) -> FloatArray:
    return np.asarray(np.einsum("ij,ij->i", p, q), dtype=np.float64)


def arc_geometry(s: FloatArray, m: FloatArray, e: FloatArray, eps: float = 1e-9) -> ArcGeometry:
    """Circumcircles of the triangles (S, M, E), vectorised over rows of (n, 3) arrays.

    Rows whose points are (nearly) collinear or coincide — triangle area below ``eps`` times
    the squared size — are NaN.
    """
    s, m, e = (np.atleast_2d(np.asarray(x, dtype=np.float64)) for x in (s, m, e))
    b = m - s
    c = e - s
    w = np.cross(b, c)
    ww = _rows_dot(w, w)
    scale = np.maximum(_rows_dot(b, b), _rows_dot(c, c))
    ok = ww > (eps * scale) ** 2  # |w| (twice the triangle's area) against size^2
    ww_safe = np.where(ok, ww, 1.0)
    # circumcentre relative to S: (|b|^2 (c x w) + |c|^2 (w x b)) / (2 |w|^2)
    rel = (_rows_dot(b, b)[:, None] * np.cross(c, w) + _rows_dot(c, c)[:, None] * np.cross(w, b)) / (
        2.0 * ww_safe[:, None]
    )
    centre = s + rel
    radius = np.linalg.norm(rel, axis=1)
    normal = w / np.sqrt(ww_safe)[:, None]
    u = -rel / np.where(radius > 0, radius, 1.0)[:, None]
    v = np.cross(normal, u)
    two_pi = 2.0 * math.pi

    def angle(p: FloatArray) -> FloatArray:
        d = p - centre
        return np.asarray(np.mod(np.arctan2(_rows_dot(d, v), _rows_dot(d, u)), two_pi), dtype=np.float64)

    via_angle = angle(m)
    sweep = angle(e)
    return ArcGeometry(centre, radius, normal, u, v, via_angle, sweep).masked(ok)


def _sample_arcs(s: FloatArray, m: FloatArray, e: FloatArray, geo: ArcGeometry, samples: int) -> FloatArray:
    """(n, samples, 3) points along each arc, with S, M and E themselves among them.

    The angle is piecewise linear in the sample number so that sample ``j`` is exactly M;
    degenerate rows (NaN geometry) become the polyline S -> M -> E."""
    n = s.shape[0]
    k = samples
    t = np.linspace(0.0, 1.0, k)
    frac = np.where(np.isfinite(geo.sweep), geo.via_angle / np.where(geo.sweep > 0, geo.sweep, 1.0), 0.5)
    j = np.clip(np.rint(frac * (k - 1)), 1, k - 2).astype(np.intp)
    t_m = (j / (k - 1))[:, None]
    first = t[None, :] <= t_m
    # fraction along each half (0..1)
    h1 = np.where(first, t[None, :] / t_m, 0.0)
    h2 = np.where(first, 0.0, (t[None, :] - t_m) / (1.0 - t_m))
    theta = np.where(
        first, geo.via_angle[:, None] * h1, geo.via_angle[:, None] + (geo.sweep - geo.via_angle)[:, None] * h2
    )
    pts = geo.centre[:, None, :] + geo.radius[:, None, None] * (
        np.cos(theta)[:, :, None] * geo.u[:, None, :] + np.sin(theta)[:, :, None] * geo.v[:, None, :]
    )
    bad = ~np.isfinite(geo.radius)
    if bad.any():
        poly = np.where(
            first[:, :, None],
            s[:, None, :] + h1[:, :, None] * (m - s)[:, None, :],
            m[:, None, :] + h2[:, :, None] * (e - m)[:, None, :],
        )
        pts[bad] = poly[bad]
    rows = np.arange(n)
    pts[:, 0] = s
    pts[rows, j] = m
    pts[:, -1] = e
    return np.asarray(pts, dtype=np.float64)


def _sample_lines(s: FloatArray, e: FloatArray, samples: int) -> FloatArray:
    t = np.linspace(0.0, 1.0, samples)
    pts = s[:, None, :] + t[None, :, None] * (e - s)[:, None, :]
    pts[:, -1] = e
    return np.asarray(pts, dtype=np.float64)


def _resolve(seg: Segment, ledger: PointLedger) -> tuple[FloatArray, FloatArray | None]:
    end = ledger.get(seg.end_id)
    if end is None:
        raise InvalidInput(f"point P{seg.end_id} does not exist")
    if not seg.is_arc:
        return xyz_of(end), None
    if seg.via_id is None:
        raise InvalidInput("the arc has no middle point")
    via = ledger.get(seg.via_id)
    if via is None:
        raise InvalidInput(f"point P{seg.via_id} does not exist")
    return xyz_of(end), xyz_of(via)


def segment_path(
    start_pose: PointLike, segment: Segment, ledger: PointLedger, samples: int = DEFAULT_SAMPLES
) -> FloatArray:
    """(samples, 3) XYZ along one segment from ``start_pose``, both ends included.

    Raises :class:`InvalidInput` for a missing point or an arc whose points define no circle
    (:func:`plan_path` draws those as a polyline instead)."""
    if samples < 3:
        raise InvalidInput("at least 3 samples per segment")
    s = xyz_of(start_pose)[None, :]
    end, via = _resolve(segment, ledger)
    if via is None:
        return np.asarray(_sample_lines(s, end[None, :], samples)[0], dtype=np.float64)
    geo = arc_geometry(s, via[None, :], end[None, :])
    if not np.isfinite(geo.radius[0]):
        raise InvalidInput("the arc's three points define no circle (they coincide or are collinear)")
    return np.asarray(_sample_arcs(s, via[None, :], end[None, :], geo, samples)[0], dtype=np.float64)


def segment_length(start_pose: PointLike, segment: Segment, ledger: PointLedger) -> float:
    """Path length (mm) of one segment from ``start_pose``."""
    s = xyz_of(start_pose)
    end, via = _resolve(segment, ledger)
    if via is None:
        return float(np.linalg.norm(end - s))
    geo = arc_geometry(s[None, :], via[None, :], end[None, :])
    if not np.isfinite(geo.radius[0]):
        raise InvalidInput("the arc's three points define no circle (they coincide or are collinear)")
    return float(geo.length[0])


@dataclass(frozen=True)
class PlanGeometry:
    """Per-segment geometry of a plan, vectorised; NaN where unknown (missing point, no start)."""

    starts: FloatArray  # (n, 3)
    vias: FloatArray  # (n, 3), NaN for lines
    ends: FloatArray  # (n, 3)
    is_arc: NDArray[np.bool_]  # (n,)
    arcs: ArcGeometry  # rows for every segment (NaN for lines)
    lengths: FloatArray  # (n,) mm; degenerate arcs count as the polyline S-M-E

    def __len__(self) -> int:
        return int(self.lengths.shape[0])


def plan_geometry(
    plan: Plan | Sequence[Segment], ledger: PointLedger, start: PointLike | None = None
) -> PlanGeometry:
    """Geometry of all segments at once; segment 0 starts at ``start`` (NaN if None)."""
    segments = plan.segments if isinstance(plan, Plan) else list(plan)
    n = len(segments)
    nan3 = np.full(3, np.nan)

    def pos(pid: int | None) -> FloatArray:
        if pid is None:
            return nan3
        p = ledger.get(pid)
        return nan3 if p is None else np.array((p.x, p.y, p.z), dtype=np.float64)

    ends = np.array([pos(seg.end_id) for seg in segments], dtype=np.float64).reshape(n, 3)
    vias = np.array([pos(seg.via_id) for seg in segments], dtype=np.float64).reshape(n, 3)
    is_arc = np.array([seg.is_arc for seg in segments], dtype=bool)
    starts = np.empty((n, 3))
    if n:
        starts[0] = nan3 if start is None else xyz_of(start)
        starts[1:] = ends[:-1]
    with np.errstate(invalid="ignore"):
        arcs = arc_geometry(starts, vias, ends).masked(is_arc)
    line_len = np.linalg.norm(ends - starts, axis=1)
    poly_len = np.linalg.norm(vias - starts, axis=1) + np.linalg.norm(ends - vias, axis=1)
    arc_len = np.where(np.isfinite(arcs.radius), arcs.length, poly_len)
    lengths = np.where(is_arc, arc_len, line_len)
    return PlanGeometry(starts, vias, ends, is_arc, arcs, np.asarray(lengths, dtype=np.float64))


@dataclass(frozen=True)
class PlanPath:
    """Sampled XYZ of a whole plan for drawing: NaN rows where a segment is unknown (draw with
    ``connect="finite"``); ``segment[i]`` is the segment index of row ``i``."""

    xyz: FloatArray  # (n * samples, 3)
    segment: NDArray[np.intp]  # (n * samples,)


def plan_path(
    plan: Plan | Sequence[Segment],
    ledger: PointLedger,
    start: PointLike | None = None,
    samples: int = DEFAULT_SAMPLES,
) -> PlanPath:
    """Sample every segment (vectorised). Arcs are true circles; an arc whose points define
    no circle is drawn as the polyline through them."""
    if samples < 3:
        raise InvalidInput("at least 3 samples per segment")
    geo = plan_geometry(plan, ledger, start)
    n = len(geo)
    pts = np.full((n, samples, 3), np.nan)
    lines = ~geo.is_arc
    if lines.any():
        pts[lines] = _sample_lines(geo.starts[lines], geo.ends[lines], samples)
    arcs = geo.is_arc
    if arcs.any():
        pts[arcs] = _sample_arcs(
            geo.starts[arcs], geo.vias[arcs], geo.ends[arcs], geo.arcs.rows(arcs), samples
        )
    unknown = ~np.isfinite(pts).all(axis=(1, 2))
    pts[unknown] = np.nan
    return PlanPath(pts.reshape(n * samples, 3), np.repeat(np.arange(n, dtype=np.intp), samples))
