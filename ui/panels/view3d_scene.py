"""What the 3D view (:mod:`ui.panels.view3d_panel`) draws of the points and the plan, worked out
without widgets: the markers' colours by sync state, the points checked for reach, how densely
the ghost path is sampled, the arcs' middle points, and which path samples are red (out of the
robot model's reach).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Final

import numpy as np

from app.plan.segments import Plan
from app.points.ledger import PointLedger
from app.points.point import SyncState, TempPoint
from app.view3d.reach import PathReach
from ui.palette import COLOR_CURVE_PURPLE, COLOR_NEUTRAL, COLOR_OK, COLOR_WARN

PATH_SAMPLES: Final = 24  # per segment for the ghost path
MAX_PATH_ROWS: Final = 40_000  # fewer samples per segment for long plans
REACH_MAX_POINTS: Final = 10_000  # points checked for reach (more: only those the plan uses)

SYNC_COLORS: Final[dict[SyncState, str]] = {
    SyncState.ON_CONTROLLER: COLOR_OK,
    SyncState.CHANGED: COLOR_WARN,
    SyncState.FAILED: COLOR_CURVE_PURPLE,
    SyncState.UNCONFIRMED: COLOR_WARN,
    SyncState.UNKNOWN: COLOR_NEUTRAL,
}


def reach_checked(points: Sequence[TempPoint], plan: Plan | None) -> Sequence[TempPoint]:
    """The points whose reach is checked: all of them, or only the plan's when there are more
    than :data:`REACH_MAX_POINTS`."""
    used = {pid for seg in plan.segments for pid in seg.point_ids} if plan is not None else set()
    return points if len(points) <= REACH_MAX_POINTS else [p for p in points if p.id in used]


def path_samples(plan: Plan) -> int:
    """Samples per segment of the ghost path (fewer for long plans, at least 3)."""
    return max(3, min(PATH_SAMPLES, MAX_PATH_ROWS // len(plan)))


def arc_middles(plan: Plan, ledger: PointLedger) -> np.ndarray:
    """The middle points of the plan's arcs, (n arcs, 3); NaN where the point does not exist."""
    vias = [ledger.get(s.via_id) if s.via_id is not None else None for s in plan.segments if s.is_arc]
    return np.array(
        [via.xyz if via is not None else (np.nan, np.nan, np.nan) for via in vias], dtype=np.float64
    ).reshape(-1, 3)


def bad_path_samples(xyz: np.ndarray, segment: np.ndarray, reach: PathReach | None) -> np.ndarray:
    """Which samples of the path (``xyz``, ``segment`` per sample) are drawn red: from the first
    bad reach sample of their segment on (path samples are denser than reach samples: the ones
    nearest a bad reach sample)."""
    bad = np.zeros(len(xyz), dtype=bool)
    if reach is None:
        return bad
    bad_seg = {i for i, b in enumerate(reach.first_bad) if b is not None}
    if not bad_seg:
        return bad
    rmask = reach.bad_mask
    bad_xyz = reach.xyz[rmask]
    bad_of_seg = reach.segment[rmask]
    for i in bad_seg:
        rows = np.flatnonzero(segment == i)
        targets = bad_xyz[bad_of_seg == i]
        if not len(rows) or not len(targets):
            continue
        d = np.linalg.norm(xyz[rows][:, None, :] - targets[None, :, :], axis=2)
        spacing = np.nanmax(np.linalg.norm(np.diff(reach.xyz[reach.segment == i], axis=0), axis=1))
        bad[rows] = np.nanmin(d, axis=1) <= max(float(spacing) * 0.51, 1e-6)
    return bad
