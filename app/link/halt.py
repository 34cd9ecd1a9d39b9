"""Writes that stop motion, followed until the controller has confirmed them (issue 19, item 1).

Decision on PROTOCOL.md section 7 ("Exception 6 ... a write that stops motion is retried until
answered") that lives here: **a jog is over only when the controller has answered its speed 0
(GV203 <- 0) -- or a Stop (441 <- 1) -- and the pose is then seen still.** Until then:

* the write is sent again at every poll (the GUI's worker) or every ``JOG_POLL_INTERVAL``
  (teachpad-cli), whatever the controller answered before (busy, an exception, no answer);
* after :data:`app.timing.HALT_ESCALATE_AFTER` s without that confirmation -- refused all along,
  or answered while the arm kept moving -- a Stop (441) goes out too, at every poll, before the
  speed 0; at once when the envelope guard, which keeps deciding on the jog being released, sees
  the arm heading over a boundary;
* the operator is told: the jog panel says "releasing -- the controller has not confirmed".

A Stop the controller refused is followed the same way (its own write, 441, from the start).
teachpad-cli gives up after :data:`app.timing.HALT_CONFIRM_BUDGET` s and says so (exit 1).

:class:`HaltWatch` is the policy alone: what to write now, what the answers and the poses mean.
The caller does the writes and reads and passes the clock (the GUI's worker in
:class:`~app.link.jog.JogMachine`, the CLI in :func:`confirm_halt`), so both follow one rule and
a test can run it on an injected clock.
"""

from __future__ import annotations

import enum
import time
from collections.abc import Callable

from app import timing
from app.errors import ModbusExceptionError, ResponseTimeout, TeachPadError
from app.link.arrival import pose_moved
from app.link.types import HaltKind, JogRequest, UnconfirmedHalt
from app.models import Pose

__all__ = ["RETRY_EXCEPTIONS", "HaltWatch", "HaltWrite", "confirm_halt", "halt_refusal"]


class HaltWrite(enum.Enum):
    """One write that stops motion."""

    SPEED_ZERO = "jog speed 0"  # GV203 <- 0: the jog stops, teach mode stays on
    STOP = "stop"  # 441 <- 1: everything stops


#: Modbus exceptions that mean "not now" (PROTOCOL.md section 7): 4 server device failure,
#: 5 acknowledge (still working on an earlier request), 6 server device busy. Any other exception
#: (illegal function, address, value ...) refuses that write for good: it is not sent again (a
#: release then goes on with Stop at once).
RETRY_EXCEPTIONS = frozenset({4, 5, 6})


def halt_refusal(exc: TeachPadError) -> bool:
    """The controller refused the write (a Modbus exception) or did not answer it in time: the
    halt goes on. Anything else (the link is gone, a bad answer) is the link's failure and goes
    its own way (the write is tried again once the link is back)."""
    return isinstance(exc, ModbusExceptionError | ResponseTimeout)


def _for_good(exc: TeachPadError) -> bool:
    """A refusal that sending the same write again cannot change."""
    return isinstance(exc, ModbusExceptionError) and exc.exception_code not in RETRY_EXCEPTIONS


class HaltWatch:
    """One motion being stopped: a jog being released (``HaltKind.RELEASE``) or a Stop the
    controller refused (``HaltKind.STOP``). See the module docstring.

    ``request``: the jog being released (the envelope guard keeps deciding on it); None when
    there was none (a Stop of a move or program).
    """

    def __init__(
        self,
        kind: HaltKind,
        request: JogRequest | None,
        now: float,
        *,
        escalate_after: float | None = None,
    ) -> None:
        self.kind = kind
        self.request = request
        self.since = now
        self._clock_from = now  # the escalation's clock: from the release, or the controller's return
        self.escalate_after = timing.HALT_ESCALATE_AFTER if escalate_after is None else escalate_after
        self.escalated = kind is HaltKind.STOP  # a refused Stop: 441 is the write to repeat
        self.answered_at: float | None = None  # the controller answered a halting write
        self.answered_by: HaltWrite | None = None
        self.speed_zero_answered = False
        self.refusals = 0  # halting writes refused or unanswered
        self.silent = False  # the controller stopped answering while this jog ran
        self.last_error: TeachPadError | None = None
        self.refused_for_good: set[HaltWrite] = set()  # not sent again (see RETRY_EXCEPTIONS)
        self.over = False
        self._still_from: Pose | None = None  # the pose of the last poll after the answer
        self._moving_after_answer = False  # answered, and the pose still changed after that

    # -- what to send ------------------------------------------------------------------------
    @property
    def unconfirmed(self) -> bool:
        """Something went wrong on the way: a write refused or unanswered, the controller silent,
        or a Stop needed. (A release answered at once and seen still never is.)"""
        return not self.over and (self.refusals > 0 or self.silent or self.escalated)

    def due(self, now: float) -> tuple[HaltWrite, ...]:
        """The writes to send now, in order (none while an answered halt waits for a still pose)."""
        if self.over:
            return ()
        if self.answered_at is not None:
            if not self._moving_after_answer or now - self.answered_at < self.escalate_after:
                return ()
            self.answered_at = None  # answered, yet the arm still moves: a Stop
            self.escalated = True
        if now - self._clock_from >= self.escalate_after:
            self.escalated = True
        if self.kind is HaltKind.STOP and self.request is None:
            writes: tuple[HaltWrite, ...] = (HaltWrite.STOP,)
        elif self.escalated:
            writes = (HaltWrite.STOP, HaltWrite.SPEED_ZERO)
        else:
            writes = (HaltWrite.SPEED_ZERO,)
        return tuple(w for w in writes if w not in self.refused_for_good)

    @property
    def given_up(self) -> bool:
        """Every write that could stop the arm was refused for good and none was answered: there
        is nothing left to send (the arm may still move)."""
        if self.over or self.answered_at is not None:
            return False
        needed = {HaltWrite.STOP} if self.kind is HaltKind.STOP and self.request is None else set(HaltWrite)
        return needed <= self.refused_for_good

    def answering_again(self, now: float) -> None:
        """The controller answers again after a silence: it gets the speed 0 first, and
        ``escalate_after`` from now to take it (nothing could reach it while it was silent)."""
        if self.silent and not self.escalated:
            self._clock_from = now

    def escalate(self) -> bool:
        """The envelope guard sees the arm heading over a boundary: a Stop at once -- unless the
        controller answered and the arm has not been seen moving since. True when it escalated."""
        if self.over or (self.answered_at is not None and not self._moving_after_answer):
            return False
        self.escalated = True
        self.answered_at = None
        return True

    # -- what came back ----------------------------------------------------------------------
    def took(self, write: HaltWrite, now: float) -> None:
        """The controller answered ``write``."""
        if write is HaltWrite.SPEED_ZERO:
            self.speed_zero_answered = True
        if self.answered_at is None:
            self.answered_at = now
            self.answered_by = write
            self._still_from = None
            self._moving_after_answer = False
        self.silent = False

    def refused(self, write: HaltWrite, exc: TeachPadError) -> None:
        """The controller did not take ``write``: refused (``exc``, a Modbus exception) or no
        answer. Refused for good: not sent again, and a Stop goes out at once instead."""
        self.refusals += 1
        self.last_error = exc
        if _for_good(exc):
            self.refused_for_good.add(write)
            self.escalated = True

    def pose_seen(self, pose: Pose) -> bool:
        """A poll's pose; True once the halt is over (answered, then the pose unchanged from one
        poll to the next)."""
        if self.over:
            return True
        if self.answered_at is None:
            self._still_from = None
            return False
        if self._still_from is not None:
            if not pose_moved(pose, self._still_from):
                self.over = True
                return True
            self._moving_after_answer = True
        self._still_from = pose
        return False

    def state(self) -> UnconfirmedHalt | None:
        """What the operator is shown: None while nothing is wrong (or once it is over)."""
        if not self.unconfirmed:
            return None
        return UnconfirmedHalt(self.kind, self.since, self.escalated)

    def words(self, now: float) -> str:
        """The English sentence for logs and the CLI: what was tried and what came back."""
        seconds = f"{now - self.since:.1f}"
        what = "the jog's speed 0" if self.kind is HaltKind.RELEASE else "the stop"
        cause = f": {self.last_error}" if self.last_error is not None else ""
        stop = " and Stop (441)" if self.escalated and self.kind is HaltKind.RELEASE else ""
        return (
            f"the controller did not confirm {what}{stop} within {seconds} s "
            f"({self.refusals} refused or unanswered{cause})"
        )


def confirm_halt(
    write: Callable[[HaltWrite], None],
    read_pose: Callable[[], Pose],
    watch: HaltWatch,
    *,
    budget: float | None = None,
    interval: float,
    clock: Callable[[], float] = time.monotonic,
    sleep: Callable[[float], None] = time.sleep,
) -> bool:
    """Blocking (teachpad-cli): send what ``watch`` asks for, read the pose, every ``interval``
    s, until the halt is over (True), or ``budget`` s (default
    :data:`app.timing.HALT_CONFIRM_BUDGET`) have passed since the watch began, or every write
    was refused for good (False).

    ``write`` raises a :class:`TeachPadError` when the controller did not take it: refused or
    unanswered (:func:`halt_refusal`) counts and is tried again; anything else is raised. A pose
    read that fails the same way is tried again at the next turn."""
    budget = timing.HALT_CONFIRM_BUDGET if budget is None else budget
    while True:
        _send_due(write, watch, clock)
        if watch.answered_at is not None and _seen_still(read_pose, watch):
            return True
        if watch.given_up or clock() - watch.since >= budget:
            return False
        sleep(interval)


def _send_due(write: Callable[[HaltWrite], None], watch: HaltWatch, clock: Callable[[], float]) -> None:
    """Send what ``watch`` asks for now; a refusal or no answer (:func:`halt_refusal`) is counted."""
    for item in watch.due(clock()):
        try:
            write(item)
        except TeachPadError as exc:
            if not halt_refusal(exc):
                raise
            watch.refused(item, exc)
        else:
            watch.took(item, clock())


def _seen_still(read_pose: Callable[[], Pose], watch: HaltWatch) -> bool:
    """The pose read now is the one read before (a read refused or unanswered: not yet)."""
    try:
        pose = read_pose()
    except TeachPadError as exc:
        if not halt_refusal(exc):
            raise
        return False
    return watch.pose_seen(pose)
