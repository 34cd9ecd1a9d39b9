"""Reachability by a robot profile: taught points and sampled plan paths that the profile's IK
cannot reach, or only past a joint limit.

Results are cached per pose (points are re-checked only when they change), and
:meth:`ReachChecker.plan_issues` remembers its last answer (same segments, points and start:
no work at all). A path is checked
at up to :data:`PATH_SAMPLES` samples per segment, fewer for long plans so that a plan costs
at most about :data:`MAX_PATH_SAMPLES` IK solutions. New poses are solved together in one
numpy batch (:meth:`ArmModel.inverse_batch`, seeded with joint 1 turned towards the target,
then once more from the home joints).

:meth:`ReachChecker.plan_issues` has the signature :func:`app.plan.checks.check_plan` takes as
``reach=``: the issues (:data:`IssueCode.UNREACHABLE`, :data:`IssueCode.JOINT_LIMIT`) are errors,
which block Run like the other errors: a pose the arm cannot take (or only past a joint limit)
would stop the controller mid-plan. (The profile is a model of the arm: a wrong verdict is
fixed by loading the right profile.)
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Final

from app.geometry import pose_to_transform
from app.models import Pose
from app.plan.checks import IssueCode, PlanIssue
from app.plan.geometry import PointLike, plan_path
from app.plan.issue_kind import IssueKind
from app.plan.segments import Plan
from app.points.ledger import PointLedger
from app.points.point import TempPoint
from app.view3d.kinematics import ArmModel, Reach
from app.view3d.path import sample_poses, segment_rotations, start_of

if TYPE_CHECKING:
    import numpy as np
    from numpy.typing import NDArray
else:  # numpy is imported by its first use, not with this module (app/lazy_numpy.py)
    from app.lazy_numpy import np
from app.lazy_numpy import FloatArray

PATH_SAMPLES: Final = 9
MIN_PATH_SAMPLES: Final = 3
MAX_PATH_SAMPLES: Final = 3000
CACHE_SIZE: Final = 50_000

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
    """Reachability of points and paths for one :class:`ArmModel` (cached, batched IK)."""

    def __init__(self, model: ArmModel) -> None:
        self.model = model
        self._cache: dict[Pose6, Reach] = {}
        self._last: tuple[object, tuple[PlanIssue, ...]] | None = None  # plan_issues' last answer

    def poses(self, poses: Sequence[Sequence[float]]) -> list[Reach]:
        """Reach of X Y Z A B C poses; the ones not seen before are solved in one batch."""
        if not len(poses):
            return []
        rounded = np.round(np.array([p[:6] for p in poses], dtype=np.float64), 4)  # one array op
        keys: list[Pose6] = list(map(tuple, rounded.tolist()))
        todo = list(dict.fromkeys(k for k in keys if k not in self._cache))
        if todo:
            targets = np.array([pose_to_transform(*k) for k in todo])
            _joints, reach = self.model.inverse_batch(targets)
            retry = [i for i, r in enumerate(reach) if r is not Reach.OK]
            if retry:  # a second guess: the plain home joints
                seeds = np.tile(self.model.home, (len(retry), 1))
                _j2, again = self.model.inverse_batch(targets[retry], seeds)
                for i, r in zip(retry, again, strict=True):
                    if r is Reach.OK or (r is Reach.JOINT_LIMIT and reach[i] is Reach.UNREACHABLE):
                        reach[i] = r
            if len(self._cache) + len(todo) > CACHE_SIZE:
                self._cache.clear()
            self._cache.update(zip(todo, reach, strict=True))
        return [self._cache.get(k, Reach.OK) for k in keys]

    def point(self, point: TempPoint) -> Reach:
        return self.poses([point.xyzabc])[0]

    def points(self, points: Sequence[TempPoint]) -> dict[int, Reach]:
        reach = self.poses([p.xyzabc for p in points])
        return {p.id: r for p, r in zip(points, reach, strict=True)}

    def path(self, plan: Plan, ledger: PointLedger, pose: Pose | None) -> PathReach:
        n = len(plan)
        k = max(MIN_PATH_SAMPLES, min(PATH_SAMPLES, MAX_PATH_SAMPLES // max(1, n)))
        start, start_rot = start_of(plan, ledger, pose)
        path = plan_path(plan, ledger, start, k)
        rots = segment_rotations(plan, ledger, start_rot)
        xyz = path.xyz.reshape(n, k, 3)
        fractions = np.linspace(0.0, 1.0, k)
        known = [i for i in range(n) if np.isfinite(xyz[i]).all()]
        samples: list[Pose6] = []
        for i in known:
            samples.extend(sample_poses(xyz[i], rots[i], fractions))
        solved = iter(self.poses(samples))
        reach: list[Reach] = []
        first_bad: list[Reach | None] = []
        known_set = set(known)
        for i in range(n):
            if i not in known_set:
                reach.extend([Reach.OK] * k)  # unknown: the other checks report it
                first_bad.append(None)
                continue
            rows = [next(solved) for _ in range(k)]
            reach.extend(rows)
            first_bad.append(next((r for r in rows if r is not Reach.OK), None))
        return PathReach(path.xyz, tuple(reach), path.segment, tuple(first_bad))

    def plan_issues(self, plan: Plan, ledger: PointLedger, current_pose: PointLike | None) -> list[PlanIssue]:
        """Reach issues of a plan (for ``check_plan(..., reach=checker.plan_issues)``)."""
        pose = current_pose if isinstance(current_pose, Pose) else None
        used = [
            p
            for pid in dict.fromkeys(pid for seg in plan.segments for pid in seg.point_ids)
            if (p := ledger.get(pid)) is not None
        ]
        # the same plan, points and start as last time (a recheck after an unrelated change)
        key = (
            tuple(plan.segments),
            tuple((p.id, p.label, p.xyzabc) for p in used),
            None if pose is None else tuple(round(float(v), 3) for v in pose.xyzabc),
        )
        if self._last is not None and self._last[0] == key:
            return list(self._last[1])
        issues = self._plan_issues(plan, ledger, pose, used)
        self._last = (key, tuple(issues))
        return issues

    def _plan_issues(
        self, plan: Plan, ledger: PointLedger, pose: Pose | None, used: list[TempPoint]
    ) -> list[PlanIssue]:
        issues: list[PlanIssue] = []
        point_reach = self.points(used)  # one batch
        reported: set[int] = set()
        for i, seg in enumerate(plan.segments):
            for pid in seg.point_ids:
                point = ledger.get(pid)
                r = point_reach.get(pid, Reach.OK)
                if point is None or pid in reported or r is Reach.OK:
                    continue
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
        return PlanIssue(
            index,
            IssueKind.ERROR,
            IssueCode.JOINT_LIMIT,
            f"{name}: {what} passes a joint limit of the robot model",
            point_id,
            args={"point": what} if point_id is not None else {},
        )
    return PlanIssue(
        index,
        IssueKind.ERROR,
        IssueCode.UNREACHABLE,
        f"{name}: {what} is out of the robot model's reach",
        point_id,
        args={"point": what} if point_id is not None else {},
    )
