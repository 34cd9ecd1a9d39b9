"""A plan as the 3D view and the dry run see it: the sampled path (from
:mod:`app.plan.geometry`), the tool's orientation along it, and a timeline from the planner's
time estimates (:mod:`app.plan.estimates`).

Orientation along a segment turns from the start's to the end point's (about the fixed
relative axis, :func:`app.geometry.slerp_matrix`) when the segment's orientation changes, and
stays the start's when it is kept. The first segment starts at the robot's pose when known,
else where the plan ends (the planner's assumption, :func:`app.plan.presenter.plan_start`).
During one segment the dry run first waits the estimate's per-segment overhead (command round
trip, acceleration), then moves at constant speed along the path. A plan of N loops plays all N:
the first from the start, each later one from where the plan ends (as the runner runs them).
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

from app.geometry import abc_to_matrix, matrix_to_abc, slerp_matrix
from app.models import Pose
from app.plan.estimates import SEGMENT_OVERHEAD_S, estimate_plan
from app.plan.geometry import plan_path
from app.plan.segments import Plan
from app.points.ledger import PointLedger

if TYPE_CHECKING:
    import numpy as np
else:  # numpy is imported by its first use, not with this module (app/lazy_numpy.py)
    from app.lazy_numpy import np
from app.lazy_numpy import FloatArray, Matrix

DRY_RUN_SAMPLES = 32  # per segment
ENDLESS_LOOPS_SHOWN = 2  # an endless plan plays its first loop and one later loop

Pose6 = tuple[float, float, float, float, float, float]


def start_of(plan: Plan, ledger: PointLedger, pose: Pose | None) -> tuple[FloatArray | None, Matrix | None]:
    """Where (XYZ) and how (rotation) the plan starts, or None for what is unknown."""
    if pose is not None:
        return np.array([pose.x, pose.y, pose.z]), abc_to_matrix(pose.a, pose.b, pose.c)
    if len(plan):
        last = ledger.get(plan[len(plan) - 1].end_id)
        if last is not None:
            return np.array(last.xyz, dtype=np.float64), abc_to_matrix(last.a, last.b, last.c)
    return None, None


def segment_rotations(
    plan: Plan, ledger: PointLedger, start_rot: Matrix | None
) -> list[tuple[Matrix, Matrix]]:
    """(start, end) tool rotation of each segment; unknown ends keep the previous rotation."""
    out: list[tuple[Matrix, Matrix]] = []
    current = start_rot
    for seg in plan.segments:
        end = ledger.get(seg.end_id)
        end_rot = abc_to_matrix(end.a, end.b, end.c) if end is not None else current
        if end_rot is None:
            end_rot = np.eye(3)
        begin = end_rot if current is None else current
        if not seg.orientation_changes:
            end_rot = begin
        out.append((begin, end_rot))
        current = end_rot
    return out


def sample_poses(xyz: FloatArray, rots: tuple[Matrix, Matrix], fractions: FloatArray) -> list[Pose6]:
    """X Y Z A B C of samples along one segment at the given 0..1 fractions."""
    poses: list[Pose6] = []
    if rots[0] is rots[1] or np.array_equal(rots[0], rots[1]):  # orientation kept: one A B C for all
        a, b, c = matrix_to_abc(rots[0])
        return [(float(p[0]), float(p[1]), float(p[2]), a, b, c) for p in xyz]
    for p, s in zip(xyz, fractions, strict=True):
        a, b, c = matrix_to_abc(slerp_matrix(rots[0], rots[1], float(s)))
        poses.append((float(p[0]), float(p[1]), float(p[2]), a, b, c))
    return poses


@dataclass(frozen=True)
class DryRunState:
    time: float  # s from the start
    segment: int  # 0-based; -1 before anything is known
    fraction: float  # 0..1 along the segment
    pose: tuple[float, float, float, float, float, float] | None  # X Y Z A B C of the tool
    loop: int = 1  # 1-based: the loop being played
    loops: int = 1  # the plan's loops (0: endless)


class LoopTimeline:
    """One loop of the plan from a start (XYZ and tool rotation): :meth:`at` gives the segment,
    the fraction along it and the tool's pose at a time from the loop's start."""

    def __init__(
        self,
        plan: Plan,
        ledger: PointLedger,
        start: FloatArray | None,
        start_rot: Matrix | None,
        samples: int,
        overhead: float,
    ) -> None:
        path = plan_path(plan, ledger, start, samples)
        est = estimate_plan(plan, ledger, start, loops=1, overhead=overhead)
        n = len(plan)
        self.overhead = overhead
        self.xyz = path.xyz.reshape(n, samples, 3) if n else np.zeros((0, samples, 3))
        self.rotations = segment_rotations(plan, ledger, start_rot)
        times = np.where(np.isfinite(est.times), est.times, 0.0)
        self.known = np.isfinite(self.xyz).all(axis=(1, 2)) & np.isfinite(est.times)
        self.durations = np.where(self.known, times, 0.0)
        self.starts = np.concatenate([[0.0], np.cumsum(self.durations)])[:-1] if n else np.zeros(0)
        self.duration = float(self.durations.sum()) if n else 0.0
        # arc length along each segment's samples, normalised to 0..1
        if n:
            steps = np.linalg.norm(np.diff(self.xyz, axis=1), axis=2)
            cum = np.concatenate([np.zeros((n, 1)), np.cumsum(steps, axis=1)], axis=1)
            total = cum[:, -1:]
            even = np.linspace(0.0, 1.0, samples)
            self.along = np.where(total > 0, cum / np.where(total > 0, total, 1.0), even)
        else:
            self.along = np.zeros((0, samples))

    def __len__(self) -> int:
        return int(self.durations.shape[0])

    def end_rotation(self) -> Matrix | None:
        return self.rotations[-1][1] if self.rotations else None

    def at(self, t: float, *, last: bool) -> tuple[int, float, Pose6 | None]:
        """(segment, fraction, pose) at ``t`` s into the loop; ``last``: the end of this loop is
        the end of the run (the tool arrives there, it does not wait at the next start)."""
        if not len(self) or not self.known.any():
            return -1, 0.0, None
        t = max(0.0, min(self.duration, t))
        known = np.flatnonzero(self.known)
        starts = [float(self.starts[k]) for k in known]
        pos = bisect.bisect_right(starts, t) - 1
        i = int(known[max(0, pos)])
        local = t - float(self.starts[i])
        moving = max(0.0, float(self.durations[i]) - self.overhead)
        fraction = 1.0 if moving <= 0 else max(0.0, min(1.0, (local - self.overhead) / moving))
        if local < self.overhead and not (last and t >= self.duration):
            fraction = 0.0
        along = self.along[i]
        xyz = np.array([np.interp(fraction, along, self.xyz[i, :, k]) for k in range(3)])
        r = slerp_matrix(self.rotations[i][0], self.rotations[i][1], fraction)
        a, b, c = matrix_to_abc(r)
        return i, fraction, (float(xyz[0]), float(xyz[1]), float(xyz[2]), a, b, c)


class DryRun:
    """Every loop of the plan as one timeline: :meth:`at` gives where the tool is at a time and
    in which loop. The first loop starts at the robot's pose (or where the plan ends); every later
    loop starts where the plan ends, as the runner runs it (:mod:`app.plan.segments`), so all
    later loops share one :class:`LoopTimeline`. An endless plan (loops 0) plays its first loop
    and :data:`ENDLESS_LOOPS_SHOWN` - 1 later one(s): every further loop is the same."""

    def __init__(
        self,
        plan: Plan,
        ledger: PointLedger,
        pose: Pose | None,
        samples: int = DRY_RUN_SAMPLES,
        overhead: float = SEGMENT_OVERHEAD_S,
    ) -> None:
        start, start_rot = start_of(plan, ledger, pose)
        self.samples = samples
        self.overhead = overhead
        self.loops = plan.loops
        self.first = LoopTimeline(plan, ledger, start, start_rot, samples, overhead)
        self.shown_loops = plan.loops if plan.loops > 0 else ENDLESS_LOOPS_SHOWN
        self.later = self.first
        if self.shown_loops > 1:
            end, _end_rot = start_of(plan, ledger, None)
            self.later = LoopTimeline(plan, ledger, end, self.first.end_rotation(), samples, overhead)
        self.duration = self.first.duration + (self.shown_loops - 1) * self.later.duration

    def __len__(self) -> int:
        return len(self.first)

    def loop_at(self, t: float) -> tuple[int, float]:
        """(1-based loop, seconds into it) at ``t``."""
        t = max(0.0, min(self.duration, t))
        if t <= self.first.duration or self.later.duration <= 0:
            return 1, t
        later = t - self.first.duration
        k = min(self.shown_loops - 2, int(later // self.later.duration))
        return 2 + k, later - k * self.later.duration

    def at(self, t: float) -> DryRunState:
        loop, local = self.loop_at(t)
        timeline = self.first if loop == 1 else self.later
        segment, fraction, pose = timeline.at(local, last=loop == self.shown_loops)
        return DryRunState(t, segment, fraction, pose, loop, self.loops)

    def segment_time(self, index: int) -> float:
        """When the first loop's segment ``index`` starts."""
        return float(self.first.starts[index]) if 0 <= index < len(self) else math.nan
