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

Changing the model is an engineer's (it feeds the reach checks that block or allow a run): the
window gives the source a :class:`ModelGuard` (the safety controller), which refuses the
operator (audited, with the file) and audits every model loaded with its file and name
(:meth:`load_file`; the start-up :meth:`restore` of the model an engineer chose is not a change).

Once bound to the robot's state (:meth:`bind`), the source compares the model with the
controller at most every :data:`AGREEMENT_CHECK_MS`: the model's forward kinematics of the
joints the controller reports against the pose it reports (:mod:`app.view3d.agreement`).
:attr:`agreement` is the last verdict (None: not compared -- no link, or no joint angles);
``agreementChanged`` says when it changed enough to be said again. A model that disagrees adds
an error to the plan's reach checks (:meth:`plan_issues`), which blocks Run.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Final, Protocol

from PySide6.QtCore import QObject, QTimer, Signal, Slot

from app.link.state import RobotState
from app.link.types import ConnectionState, LinkState
from app.models import Pose
from ui.settings import AppSettings

if TYPE_CHECKING:  # the arm model and its reach checks: imported by the first reach question; the
    # profiles' module by the first profile read (the default one, or one remembered or loaded)
    from app.plan.checks import PlanIssue
    from app.plan.geometry import PointLike
    from app.plan.segments import Plan
    from app.points.ledger import PointLedger
    from app.view3d.agreement import ModelAgreement
    from app.view3d.kinematics import ArmModel
    from app.view3d.profile import RobotProfile
    from app.view3d.reach import ReachChecker

CHECKERS_KEPT: Final = 4  # profiles whose reach caches are kept (switching back is free)
AGREEMENT_CHECK_MS: Final = 250  # the model is compared with the controller's pose at most this often


class ModelGuard(Protocol):
    """Who may change the robot model (the safety controller)."""

    def robot_model_refusal(self, path: str) -> str | None:
        """None when the role in force may load the model ``path`` ("": not chosen yet); else
        why not, in words (the refusal is audited)."""
        ...

    def robot_model_loaded(self, path: str, name: str) -> None:
        """Audit the model now in use."""
        ...


class RobotModelSource(QObject):
    """The active robot model. Signals: ``profileChanged(object)`` (the new
    :class:`RobotProfile`), ``problemRaised(str)`` (a profile file could not be used),
    ``agreementChanged(object)`` (the new :class:`~app.view3d.agreement.ModelAgreement`, or
    None: not compared)."""

    profileChanged = Signal(object)
    problemRaised = Signal(str)
    agreementChanged = Signal(object)

    def __init__(self, settings: AppSettings | None = None, parent: QObject | None = None) -> None:
        super().__init__(parent)
        self.guard: ModelGuard | None = None  # None: anyone (a source without a window)
        self.agreement: ModelAgreement | None = None
        self._state: RobotState | None = None
        self._compare_timer = QTimer(self)
        self._compare_timer.setSingleShot(True)
        self._compare_timer.setInterval(AGREEMENT_CHECK_MS)
        self._compare_timer.timeout.connect(self.compare)
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
        if self._state is not None:
            self.compare()  # the new model against the controller, now

    def use_default(self) -> None:
        self.set_profile(self.default)

    def refusal(self, path: str = "") -> str | None:
        """Why the role in force may not change the model (None: it may); audited."""
        return self.guard.robot_model_refusal(path) if self.guard is not None else None

    def load_file(self, path: str) -> str | None:
        """Load a profile file and use it (an engineer's: see :class:`ModelGuard`); why not, in
        words, when it cannot be used or the role may not (the current profile stays)."""
        refused = self.refusal(path)
        if refused is not None:
            return refused
        error = self._load(path)
        if error is None and self.guard is not None:
            self.guard.robot_model_loaded(path, self.profile.name)
        return error

    def _load(self, path: str) -> str | None:
        from app.errors import ProfileError
        from app.view3d.profile import load_profile

        try:
            profile = load_profile(path)
        except ProfileError as exc:
            from ui.messages import error_text

            return error_text(exc)  # in the operator's language (ui/messages_profile.py)
        self.problem = ""
        self.set_profile(profile, path)
        return None

    def restore(self) -> bool:
        """Load the profile remembered from the last session; False (and :attr:`problem` set,
        ``problemRaised`` emitted, the path forgotten) when it cannot be used."""
        path = self._settings.robot_profile_path if self._settings is not None else ""
        if not path:
            return True
        error = self._load(path)  # the model an engineer chose: no change, nothing to allow
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
        """The current profile's reach issues of a plan (``check_plan(..., reach=...)``), after
        the model's disagreement with the controller when it disagrees (an error: blocks Run)."""
        issues = self.reach.plan_issues(plan, ledger, current_pose)
        agreement = self.agreement
        if agreement is None or agreement.agrees:
            return issues
        from app.view3d.agreement import model_issue

        return [model_issue(agreement), *issues]

    # --- the model against the controller ------------------------------------------------
    def bind(self, state: RobotState) -> None:
        """Compare the model with the controller's joints and pose from now on."""
        self._state = state
        state.poseChanged.connect(self._on_pose)
        state.connectionChanged.connect(self._on_connection)

    @Slot(Pose)
    def _on_pose(self, _pose: Pose) -> None:
        if not self._compare_timer.isActive():
            self._compare_timer.start()

    @Slot(ConnectionState)
    def _on_connection(self, connection: ConnectionState) -> None:
        if connection.state is not LinkState.CONNECTED:
            self._compare_timer.stop()
            self._set_agreement(None)  # another controller may come: compare it afresh

    @Slot()
    def compare(self) -> None:
        """Compare the model with the controller's latest joints and pose now."""
        state = self._state
        pose = state.pose if state is not None else None
        connected = state is not None and state.connection.state is LinkState.CONNECTED
        if pose is None or pose.joints is None or not connected:
            self._set_agreement(None)
            return
        from app.view3d.agreement import compare_model

        self._set_agreement(compare_model(self.model, pose.joints, pose.xyzabc))

    def _set_agreement(self, agreement: ModelAgreement | None) -> None:
        previous, self.agreement = self.agreement, agreement
        news = previous is not None if agreement is None else agreement.differs_from(previous)
        if news:
            self.agreementChanged.emit(agreement)
