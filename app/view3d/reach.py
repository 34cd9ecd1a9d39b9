"""Reachability by a robot profile: taught points and sampled plan paths that the profile's IK
cannot reach, or only past a joint limit.

Results are cached per pose (points are re-checked only when they change). A path is checked
at up to :data:`PATH_SAMPLES` samples per segment, fewer for long plans so that a plan costs
at most about :data:`MAX_PATH_SAMPLES` IK solutions; each sample is seeded from the previous
one's solution (a continuous path converges in a few iterations).

:meth:`ReachChecker.plan_issues` has the signature :func:`app.plan.checks.check_plan` takes as
``reach=``: the issues are warnings (:data:`IssueCode.UNREACHABLE`, :data:`IssueCode.JOINT_LIMIT`)
because the profile is a model of the arm, which the controller has the last word on.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Final

import numpy as np
from numpy.typing import NDArray

from app.models import Pose
from app.plan.checks import IssueCode, IssueKind, PlanIssue
from app.plan.geometry import PointLike, plan_path
from app.plan.segments import Plan
from app.points.ledger import PointLedger, TempPoint
from app.view3d.kinematics import ArmModel, Reach
from app.view3d.path import sample_poses, segment_rotations, start_of

PATH_SAMPLES: Final = 9
MIN_PATH_SAMPLES: Final = 3
MAX_PATH_SAMPLES: Final = 3000
CACHE_SIZE: Final = 50_000

FloatArray = NDArray[np.float64]
Pose6 = tuple[float, float, float, float, float, float]


@dataclass(frozen=True)
class PathReach:
    """Reach along a sampled path: ``xyz`` (n * k, 3), ``reach`` per sample, ``segment`` per
    sample, and the first bad sample of each segment (None where all are fine)."""

    xyz: FloatArray
    reach: tuple[Reach, ...]
    segment: NDArray[np.intp]
    first_bad: tuple[Reach | None, ...]

    @property
    def bad_mask(self) -> NDArray[np.bool_]:
        return np.array([r is not Reach.OK for r in self.reach], dtype=bool)


class ReachChecker:
    """Reachability of points and paths for one :class:`ArmModel` (cached)."""

    def __init__(self, model: ArmModel) -> None:
        self.model = model
        self._cache: dict[Pose6, Reach] = {}

    def pose(self, pose: Sequence[float], seed: FloatArray | None = None) -> tuple[Reach, FloatArray | None]:
        key: Pose6 = tuple(round(float(v), 4) for v in pose[:6])  # type: ignore[assignment]
        cached = self._cache.get(key)
        if cached is not None and seed is None:
            return cached, None
        result = self.model.inverse_pose(key, seed)
        if result.reach is Reach.UNREACHABLE and seed is not None:
            result = self.model.inverse_pose(key, None)
        if len(self._cache) >= CACHE_SIZE:
            self._cache.clear()
        self._cache[key] = result.reach
        return result.reach, result.joints

    def point(self, point: TempPoint) -> Reach:
        return self.pose(point.xyzabc)[0]

    def points(self, points: Sequence[TempPoint]) -> dict[int, Reach]:
        return {p.id: self.point(p) for p in points}

    def path(self, plan: Plan, ledger: PointLedger, pose: Pose | None) -> PathReach:
        n = len(plan)
        k = max(MIN_PATH_SAMPLES, min(PATH_SAMPLES, MAX_PATH_SAMPLES // max(1, n)))
        start, start_rot = start_of(plan, ledger, pose)
        path = plan_path(plan, ledger, start, k)
        rots = segment_rotations(plan, ledger, start_rot)
        xyz = path.xyz.reshape(n, k, 3)
        fractions = np.linspace(0.0, 1.0, k)
        reach: list[Reach] = []
        first_bad: list[Reach | None] = []
        seed: FloatArray | None = None
        for i in range(n):
            bad: Reach | None = None
            if not np.isfinite(xyz[i]).all():
                reach.extend([Reach.OK] * k)  # unknown: the other checks report it
                first_bad.append(None)
                continue
            for p in sample_poses(xyz[i], rots[i], fractions):
                r, joints = self.pose(p, seed)
                seed = joints if joints is not None else seed
                reach.append(r)
                if r is not Reach.OK and bad is None:
                    bad = r
            first_bad.append(bad)
        return PathReach(path.xyz, tuple(reach), path.segment, tuple(first_bad))

    def plan_issues(self, plan: Plan, ledger: PointLedger, current_pose: PointLike | None) -> list[PlanIssue]:
        """Reach issues of a plan (for ``check_plan(..., reach=checker.plan_issues)``)."""
        pose = current_pose if isinstance(current_pose, Pose) else None
        issues: list[PlanIssue] = []
        reported: set[int] = set()
        for i, seg in enumerate(plan.segments):
            for pid in seg.point_ids:
                point = ledger.get(pid)
                if point is None or pid in reported:
                    continue
                r = self.point(point)
                if r is not Reach.OK:
                    reported.add(pid)
                    issues.append(_issue(i, r, f"{point.label}", pid))
        path = self.path(plan, ledger, pose)
        for i, bad in enumerate(path.first_bad):
            if bad is not None and not any(it.segment == i for it in issues):
                issues.append(_issue(i, bad, "the path", None))
        return issues


def _issue(index: int, reach: Reach, what: str, point_id: int | None) -> PlanIssue:
    name = f"segment {index + 1}"
    if reach is Reach.JOINT_LIMIT:
        return PlanIssue(index, IssueKind.WARNING, IssueCode.JOINT_LIMIT,
                         f"{name}: {what} passes a joint limit of the robot model", point_id)
    return PlanIssue(index, IssueKind.WARNING, IssueCode.UNREACHABLE,
                     f"{name}: {what} is out of the robot model's reach", point_id)
