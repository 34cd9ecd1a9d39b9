"""Letting go of the controller with the robot in mind: Disconnect, Reconnect, closing the window.

TeachPad's Stop reaches the last controller whatever the link's state (a fresh connection when
there is no link: ``app/link/commands.py``), but once the window is gone nobody can press it, and
after a Disconnect nothing shows what the robot does. So, when motion or a program may be under
way (:class:`UnderWay`: the program state running or paused, a jog held, a motion request or a
plan run whose outcome is not back yet, the last known pose still changing), *Disconnect* and
closing the window first ask (:mod:`ui.dialogs.stop_first`), naming what is under way: stop,
then go on (the default) / go on without stopping / cancel. Nothing under way: no question. A
close nobody attends (``teachpad --screenshot``) stops first without asking.

*Reconnect* (any role, :data:`~app.safety.roles.Action.RECONNECT`) connects again to the controller
of the last connection with its settings unchanged: this session's link settings, else the
remembered ones. Another controller or other settings stay the administrator's *Connect…*.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

from PySide6.QtCore import QObject, Slot
from PySide6.QtWidgets import QWidget

from app.connection import ConnectionSettings
from app.link.ops import Stop
from app.link.robot_link import RobotLink
from app.link.types import LinkState, Operation
from app.models import Pose
from app.protocol.enums import ProgramState
from ui.dialogs.stop_first import AskStopFirst, StopFirst, StopFirstQuestion, ask_stop_first
from ui.messages import operation_text

if TYPE_CHECKING:
    from ui.controllers.plan_run_controller import PlanRunController
    from ui.panels.jog_panel import JogPanel
    from ui.settings import AppSettings

__all__ = ["MOVING_WINDOW", "POSE_MOVED", "LinkGuard", "UnderWay"]

#: mm or degrees: a smaller change between two polled poses is noise, not motion
POSE_MOVED = 0.01
#: s: the arm counts as moving while the last good poll came within this of its last movement
#: (a stale pose that was still changing when the link went counts as moving)
MOVING_WINDOW = 0.5


def _moved(before: Pose, after: Pose) -> bool:
    pairs = [*zip(before.xyzabc, after.xyzabc, strict=True), *zip(before.ext, after.ext, strict=True)]
    if before.joints is not None and after.joints is not None:
        pairs += list(zip(before.joints, after.joints, strict=False))
    return any(abs(a - b) > POSE_MOVED for a, b in pairs)


class UnderWay(QObject):
    """What may be moving the robot right now, as the GUI knows it (see the module docstring)."""

    def __init__(
        self, link: RobotLink, jog: JogPanel, runs: PlanRunController, parent: QObject | None = None
    ) -> None:
        super().__init__(parent)
        self._link = link
        self._jog = jog
        self._runs = runs
        self._pose: Pose | None = link.state.pose
        self._moved_at: float | None = None  # time.monotonic() when a pose that moved arrived
        link.state.poseChanged.connect(self._on_pose)

    @Slot(Pose)
    def _on_pose(self, pose: Pose) -> None:
        before, self._pose = self._pose, pose
        if before is not None and _moved(before, pose):
            self._moved_at = time.monotonic()

    def pose_moving(self, now: float | None = None) -> bool:
        """The last known pose was still changing (see :data:`MOVING_WINDOW`)."""
        now = time.monotonic() if now is None else now
        age = self._link.state.age(now)
        if self._moved_at is None or age is None:
            return False
        return (now - age) - self._moved_at <= MOVING_WINDOW

    def items(self) -> list[str]:
        """What is under way, one translated phrase each (empty: nothing)."""
        out: list[str] = []
        status = self._link.state.status
        program = status.program_state if status is not None else None
        if program == ProgramState.RUNNING:
            out.append(self.tr("a program is running"))
        elif program == ProgramState.PAUSED:
            out.append(self.tr("a program is paused"))
        if self._jog.is_jogging:
            out.append(self.tr("a jog is held"))
        for operation in dict.fromkeys(self._link.motions_in_flight):
            if operation == Operation.RUN_PROGRAM and program in (ProgramState.RUNNING, ProgramState.PAUSED):
                continue  # said above, from the program's own state
            out.append(self.tr("{operation}: under way").format(operation=operation_text(operation)))
        if self._runs.running:
            out.append(self.tr("a plan run is under way"))
        if self.pose_moving():
            out.append(
                self.tr("the arm is moving")
                if self._link.state.fresh
                else self.tr("the arm was moving when last seen")
            )
        return out


class LinkGuard(QObject):
    """Disconnect, Reconnect and the close's question (see the module docstring). ``ask``
    (settable) answers the question; tests replace it."""

    def __init__(
        self,
        link: RobotLink,
        jog: JogPanel,
        runs: PlanRunController,
        settings: AppSettings,
        parent: QWidget,
    ) -> None:
        super().__init__(parent)
        self._link = link
        self._jog = jog
        self._settings = settings
        self.under_way = UnderWay(link, jog, runs, self)
        self.ask: AskStopFirst = ask_stop_first(parent)

    # --- Disconnect ---------------------------------------------------------------------
    @Slot()
    def disconnect_link(self) -> None:
        """Disconnect; first the question when something is under way (Cancel keeps the link)."""
        items = self.under_way.items()
        self._jog.release_all()  # the dead-man, before any question
        if items:
            question = StopFirstQuestion(
                self.tr("Disconnect"),
                self._text(
                    items,
                    self.tr(
                        "Disconnecting does not stop the robot, and TeachPad no longer shows what it "
                        "does. Stop all motion first?"
                    ),
                ),
                self.tr("Stop, then disconnect"),
                self.tr("Disconnect without stopping"),
            )
            answer = self.ask(question)
            if answer is StopFirst.CANCEL:
                return
            if answer is StopFirst.STOP:
                self._link.submit(Stop())  # queued before the disconnect: it goes out first
        self._link.disconnect()

    # --- closing the window ---------------------------------------------------------------
    def allow_close(self) -> bool:
        """The window is about to close (the link with it): the question when something is
        under way and the link is not already closed. False: the operator cancelled."""
        items = self._items_while_linked()
        if not items:
            return True
        question = StopFirstQuestion(
            self.tr("Close TeachPad"),
            self._text(items, self.tr("Closing TeachPad does not stop the robot. Stop all motion first?")),
            self.tr("Stop, then close"),
            self.tr("Close without stopping"),
        )
        answer = self.ask(question)
        if answer is StopFirst.STOP:
            self._link.submit(Stop())  # queued before the link's shutdown
        return answer is not StopFirst.CANCEL

    def stop_if_under_way(self) -> bool:
        """A close nobody attends: stop when something is under way (no question). True if sent."""
        if not self._items_while_linked():
            return False
        self._link.submit(Stop())
        return True

    def _items_while_linked(self) -> list[str]:
        if self._link.state.connection.state is LinkState.DISCONNECTED:
            return []  # the operator let go already (Disconnect asked then)
        return self.under_way.items()

    def _text(self, items: list[str], ending: str) -> str:
        endpoint = self._link.state.connection.endpoint or self.tr("the controller")
        listed = "\n".join(f"• {item}" for item in items)
        return self.tr("Under way on {endpoint}:\n{items}\n\n{ending}").format(
            endpoint=endpoint, items=listed, ending=ending
        )

    # --- Reconnect ------------------------------------------------------------------------
    def last_connection(self) -> ConnectionSettings | None:
        """The controller of the last connection, with its settings: this session's link's,
        else the remembered ones (None when none was ever saved)."""
        if self._link.settings is not None:
            return self._link.settings
        if self._settings.has_saved_connection():
            return self._settings.connection()
        return None

    def reconnect(self) -> bool:
        """Connect again to :meth:`last_connection` (the caller checked the role). False: none."""
        settings = self.last_connection()
        if settings is None:
            return False
        self._jog.release_all()
        self._link.connect_to(settings)
        return True
