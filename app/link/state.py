"""RobotState: the one observable picture of the robot on the GUI side (QtCore only, no widgets).

:class:`~app.link.robot_link.RobotLink` holds one (``link.state``) and feeds it from the
worker's signals; panels and controllers subscribe to the fields they show, the way napari's
views connect to ``dims.events.ndim``. One narrowly typed signal per field, emitted only when
the value changed:

=====================  ==========================  ===========================================
field (property)       signal                      what
=====================  ==========================  ===========================================
``connection``         ``connectionChanged``       :class:`ConnectionState` of the link
``fresh`` / ``age()``  ``freshnessChanged(bool)``  a good poll arrived within ``freshness_limit``
``pose``               ``poseChanged``             :class:`Pose` of the last good poll
``joints``             ``jointsChanged(object)``   J1..J6 (tuple of floats) when the pose has them
``status``             ``statusChanged``           :class:`ControllerStatus`
``alarms``             ``alarmsChanged(int)``      GV562 alarm bits
``last_result``        ``lastResultChanged``       the latest :class:`CommandResult` of any request
``rtt``                ``rttChanged(float)``       mean poll round trip, ms
``stats``              ``statsChanged``            :class:`LinkStats` snapshot of the client
``halt``               ``haltChanged(object)``     :class:`UnconfirmedHalt`: a jog's stop or a
                                                   Stop the controller has not confirmed (None)
(every good poll)      ``polled(float)``           its ``time.monotonic()``, after its pose (also
                                                   when nothing changed: measured stopping)
=====================  ==========================  ===========================================

Freshness: ``fresh`` is True only while the link is CONNECTED and the last good poll is
younger than the limit. It turns False at once on any other link state (NOT_ANSWERING, DOWN,
...) and, through one single-shot QTimer in the GUI thread that is re-armed only when it fires
(not at every poll), when no good poll arrived within the limit. The values keep their last
known contents when stale: a view shows them as stale, it does not blank them.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

from PySide6.QtCore import QObject, QTimer, Signal, Slot

from app.link.stats import LinkStats
from app.link.types import ConnectionState, LinkState, UnconfirmedHalt
from app.models import CommandResult, ControllerStatus, Pose

__all__ = ["DEFAULT_FRESHNESS_LIMIT", "PollUpdate", "RobotState"]

DEFAULT_FRESHNESS_LIMIT = 0.5  # s without a good poll before the values count as stale


@dataclass(frozen=True, slots=True)
class PollUpdate:
    """What one poll (or the first read of a new link) changed, delivered to the GUI thread in one
    queued call: the pose, the status and the alarm bits (None: unchanged), and ``good_at``, the
    ``time.monotonic()`` of the good poll (None for the connect read, which is not a poll).
    Applied in this order: pose, status, alarms, then the good poll."""

    pose: Pose | None = None
    status: ControllerStatus | None = None
    alarms: int | None = None
    good_at: float | None = None


class RobotState(QObject):
    """See the module docstring. The ``set_*`` / ``note_*`` slots are the link's side."""

    connectionChanged = Signal(ConnectionState)  # noqa: N815
    freshnessChanged = Signal(bool)  # noqa: N815
    poseChanged = Signal(Pose)  # noqa: N815
    jointsChanged = Signal(object)  # noqa: N815 - tuple[float, ...]
    statusChanged = Signal(ControllerStatus)  # noqa: N815
    alarmsChanged = Signal(int)  # noqa: N815
    lastResultChanged = Signal(CommandResult)  # noqa: N815
    rttChanged = Signal(float)  # noqa: N815
    statsChanged = Signal(LinkStats)  # noqa: N815
    haltChanged = Signal(object)  # noqa: N815 - UnconfirmedHalt | None
    polled = Signal(float)  # every good poll's time.monotonic(), after its pose and status

    def __init__(
        self, parent: QObject | None = None, *, freshness_limit: float = DEFAULT_FRESHNESS_LIMIT
    ) -> None:
        super().__init__(parent)
        if freshness_limit <= 0:
            raise ValueError(f"the freshness limit must be > 0 s, got {freshness_limit:g}")
        self._limit = float(freshness_limit)
        self._connection = ConnectionState(LinkState.DISCONNECTED)
        self._fresh = False
        self._last_good: float | None = None  # time.monotonic() of the last good poll
        self._pose: Pose | None = None
        self._joints: tuple[float, ...] | None = None
        self._status: ControllerStatus | None = None
        self._alarms: int | None = None
        self._last_result: CommandResult | None = None
        self._rtt: float | None = None
        self._stats = LinkStats()
        self._halt: UnconfirmedHalt | None = None
        self._stops = 0
        self._timer = QTimer(self)
        self._timer.setSingleShot(True)
        self._timer.timeout.connect(self._check_freshness)

    # --- the current values ---------------------------------------------------------------
    @property
    def connection(self) -> ConnectionState:
        return self._connection

    @property
    def connected(self) -> bool:
        return self._connection.connected

    @property
    def writable(self) -> bool:
        """Connected and not monitor-only: motion commands may go out."""
        return self._connection.connected and not self._connection.monitor_only

    @property
    def fresh(self) -> bool:
        return self._fresh

    def age(self, now: float | None = None) -> float | None:
        """Seconds since the last good poll (``time.monotonic()`` clock); None before the first."""
        if self._last_good is None:
            return None
        return max(0.0, (time.monotonic() if now is None else now) - self._last_good)

    @property
    def freshness_limit(self) -> float:
        return self._limit

    def set_freshness_limit(self, seconds: float) -> None:
        if seconds <= 0:
            raise ValueError(f"the freshness limit must be > 0 s, got {seconds:g}")
        self._limit = float(seconds)
        self._timer.stop()
        self._check_freshness()

    @property
    def pose(self) -> Pose | None:
        return self._pose

    @property
    def joints(self) -> tuple[float, ...] | None:
        return self._joints

    @property
    def status(self) -> ControllerStatus | None:
        return self._status

    @property
    def alarms(self) -> int | None:
        return self._alarms

    @property
    def last_result(self) -> CommandResult | None:
        return self._last_result

    @property
    def rtt(self) -> float | None:
        return self._rtt

    @property
    def stats(self) -> LinkStats:
        return self._stats

    # --- the link's side ------------------------------------------------------------------
    @Slot(ConnectionState)
    def set_connection(self, connection: ConnectionState) -> None:
        if connection == self._connection:
            return
        self._connection = connection
        if connection.state is not LinkState.CONNECTED:
            self._set_fresh(False)  # at once: silence or a lost link is never "live"
        self.connectionChanged.emit(connection)

    @Slot(float)
    def note_good_poll(self, when: float) -> None:
        """A poll answered (``when``: its ``time.monotonic()``); emitted after its pose and status."""
        self._last_good = when
        self.polled.emit(when)
        if self._connection.state is LinkState.CONNECTED:
            self._set_fresh(self._remaining() > 0)
        if self._fresh and not self._timer.isActive():
            self._arm()

    @Slot(Pose)
    def set_pose(self, pose: Pose) -> None:
        if pose == self._pose:
            return
        self._pose = pose
        self.poseChanged.emit(pose)
        joints = tuple(pose.joints) if pose.joints is not None else None
        if joints is not None and joints != self._joints:
            self._joints = joints
            self.jointsChanged.emit(joints)

    @Slot(ControllerStatus)
    def set_status(self, status: ControllerStatus) -> None:
        if status == self._status:
            return
        self._status = status
        self.statusChanged.emit(status)
        self.set_alarms(int(status.alarms))

    @Slot(int)
    def set_alarms(self, alarms: int) -> None:
        alarms = int(alarms)
        if alarms != self._alarms:
            self._alarms = alarms
            self.alarmsChanged.emit(alarms)

    @Slot(CommandResult)
    def set_last_result(self, result: CommandResult) -> None:
        # every result counts, also one equal to the previous (the same command twice)
        self._last_result = result
        self.lastResultChanged.emit(result)

    @Slot(float)
    def set_rtt(self, ms: float) -> None:
        if ms != self._rtt:
            self._rtt = ms
            self.rttChanged.emit(ms)

    @Slot(LinkStats)
    def set_stats(self, stats: LinkStats) -> None:
        if stats != self._stats:
            self._stats = stats
            self.statsChanged.emit(stats)

    @property
    def halt(self) -> UnconfirmedHalt | None:
        """A write that stops motion the controller has not confirmed yet (retried every poll)."""
        return self._halt

    @Slot(object)
    def set_halt(self, halt: UnconfirmedHalt | None) -> None:
        if halt != self._halt:
            self._halt = halt
            self.haltChanged.emit(halt)

    @property
    def stops_requested(self) -> int:
        """How many Stops were asked of the link so far (counted on the GUI thread, when asked,
        by the link's ``submit``).

        A controller that chains a move after another request (the point guard: create the
        points, then move) notes it when the chain begins and sends nothing more once it changed:
        a Stop asked between the create's answer and the move's request must not be followed by
        the move (the worker cancels only the motions queued *before* the Stop)."""
        return self._stops

    def note_stop(self) -> None:
        """A Stop was asked (the link's ``submit``, before anything else)."""
        self._stops += 1

    # --- freshness ------------------------------------------------------------------------
    def _remaining(self) -> float:
        age = self.age()
        return -1.0 if age is None else self._limit - age

    def _arm(self) -> None:
        self._timer.start(max(1, int(self._remaining() * 1000.0) + 1))

    def _set_fresh(self, fresh: bool) -> None:
        if fresh != self._fresh:
            self._fresh = fresh
            if not fresh:
                self._timer.stop()
            self.freshnessChanged.emit(fresh)

    @Slot()
    def _check_freshness(self) -> None:
        fresh = self._connection.state is LinkState.CONNECTED and self._remaining() > 0
        self._set_fresh(fresh)
        if fresh:
            self._arm()  # a poll came meanwhile: look again when that one gets old
