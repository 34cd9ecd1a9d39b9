"""The active robot model profile, shared by the 3D view and the planner's checks.

One :class:`RobotModelSource` per window holds the profile the operator loaded (the
simulator's arm by default), its :class:`~app.view3d.kinematics.ArmModel` and one
:class:`~app.view3d.reach.ReachChecker` per profile (kept for the last :data:`CHECKERS_KEPT`
profiles, each caching the reach of every pose it solved), so the planner's checks list and the
3D view's red markers come from the same solutions. :meth:`plan_issues` is what
:func:`app.plan.checks.check_plan` takes as ``reach=``; it always asks the current profile.

The path of a loaded profile is remembered in the settings
(:attr:`ui.settings.AppSettings.robot_profile_path`); :meth:`restore` loads it at start-up and,
when the file is gone or malformed, says so (:attr:`problem`, ``problemRaised``), forgets it
and keeps the default profile.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Final

from PySide6.QtCore import QObject, Signal

from ui.settings import AppSettings

if TYPE_CHECKING:  # the arm model and its reach checks: imported by the first reach question; the
    # profiles' module by the first profile read (the default one, or one remembered or loaded)
    from app.plan.checks import PlanIssue
    from app.plan.geometry import PointLike
    from app.plan.segments import Plan
    from app.points.ledger import PointLedger
    from app.view3d.kinematics import ArmModel
    from app.view3d.profile import RobotProfile
    from app.view3d.reach import ReachChecker

CHECKERS_KEPT: Final = 4  # profiles whose reach caches are kept (switching back is free)


class RobotModelSource(QObject):
    """The active robot model. Signals: ``profileChanged(object)`` (the new
    :class:`RobotProfile`), ``problemRaised(str)`` (a profile file could not be used)."""

    profileChanged = Signal(object)
    problemRaised = Signal(str)

    def __init__(self, settings: AppSettings | None = None, parent: QObject | None = None) -> None:
        super().__init__(parent)
        self._settings = settings
        self._default: RobotProfile | None = None  # the shipped profile, read by its first use
        self._checkers: dict[RobotProfile, ReachChecker] = {}
        self.path = ""  # the profile's file ("" for the default profile)
        self.problem = ""  # the last profile file that could not be used, and why
        self._profile: RobotProfile | None = None  # None: the default profile (not read yet)
        self._reach: ReachChecker | None = None  # made by the first use: the arm model needs numpy,
        # which the window's first paint does not (the planner's checks and the 3D view come later)

    @property
    def reach(self) -> ReachChecker:
        """The current profile's reach checker (made now if it was not yet)."""
        reach = self._reach
        if reach is None:
            reach = self._reach = self._checker(self.profile)
        return reach

    @property
    def model(self) -> ArmModel:
        return self.reach.model

    @property
    def profile(self) -> RobotProfile:
        return self._profile if self._profile is not None else self.default

    @property
    def default(self) -> RobotProfile:
        """The shipped profile (the simulator's arm): read when first needed, not at start-up."""
        if self._default is None:
            from app.view3d.profile import default_profile

            self._default = default_profile()
        return self._default

    def _checker(self, profile: RobotProfile) -> ReachChecker:
        from app.view3d.kinematics import ArmModel
        from app.view3d.reach import ReachChecker

        checker = self._checkers.pop(profile, None) or ReachChecker(ArmModel(profile))
        self._checkers[profile] = checker  # most recent last
        while len(self._checkers) > CHECKERS_KEPT:
            del self._checkers[next(iter(self._checkers))]
        return checker

    def set_profile(self, profile: RobotProfile, path: str = "") -> None:
        """Use ``profile`` (from the file ``path``; "" for one that has none) and remember it."""
        self._profile = profile
        self._reach = None if self._reach is None else self._checker(profile)
        self.path = path
        if self._settings is not None:
            self._settings.robot_profile_path = path
        self.profileChanged.emit(profile)

    def use_default(self) -> None:
        self.set_profile(self.default)

    def load_file(self, path: str) -> str | None:
        """Load a profile file and use it; the loader's message when it cannot be used (the
        current profile stays)."""
        from app.view3d.profile import ProfileError, load_profile

        try:
            profile = load_profile(path)
        except ProfileError as exc:
            return str(exc)
        self.problem = ""
        self.set_profile(profile, path)
        return None

    def restore(self) -> bool:
        """Load the profile remembered from the last session; False (and :attr:`problem` set,
        ``problemRaised`` emitted, the path forgotten) when it cannot be used."""
        path = self._settings.robot_profile_path if self._settings is not None else ""
        if not path:
            return True
        error = self.load_file(path)
        if error is None:
            return True
        self.problem = (
            self.tr(
                "The robot model remembered from the last session could not be loaded: %1. "
                "The default robot model (%2) is used."
            )
            .replace("%1", error)
            .replace("%2", self.default.name)
        )
        self.set_profile(self.default)  # and forget the bad path
        self.problemRaised.emit(self.problem)
        return False

    def plan_issues(
        self, plan: Plan, ledger: PointLedger, current_pose: PointLike | None
    ) -> Sequence[PlanIssue]:
        """The current profile's reach issues of a plan (``check_plan(..., reach=...)``)."""
        return self.reach.plan_issues(plan, ledger, current_pose)
