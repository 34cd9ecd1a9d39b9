"""The link supervisor: the client and the link's state, its decisions on connect, silence,
failures and restarts (worker thread). It calls no other part: each method says what happened
(returns it) and :mod:`app.link.lifecycle` hands it on to the jog, the poller, the upload and the
worker's timers in the order docs/DESIGN.md describes, as :mod:`app.link.sequence` does a poll's.

* **Connect**: open, read status and pose (:meth:`LinkSupervisor.open`), the jog made safe, go
  live (:meth:`LinkSupervisor.go_live`), the restart canary, ``CONNECTED``; then the queued jobs run.
* **Not answering**: a poll that times out with the link still open shows ``NOT_ANSWERING`` at
  once (the held jog is dropped; ratio 0 goes out as soon as the controller answers again); a
  good poll shows ``CONNECTED`` again. Silence lasting :data:`app.timing.NOT_ANSWERING_DOWN_AFTER`
  declares the link down (:meth:`LinkSupervisor.poll_silent` says which).
* **Link loss**: :data:`app.timing.LINK_LOSS_POLLS` failed transactions in a row (refused, reset,
  command timeouts) declare the link ``DOWN`` at once (:meth:`LinkSupervisor.transport_failed`
  says so); reconnection follows :data:`app.timing.RECONNECT_BACKOFF` by itself
  (:meth:`LinkSupervisor.down` gives the delay) and ends with ``controllerReconnected``.
* **Restart canary**: a random token in a spare GV, read back on the clock poll; 0 means the
  controller restarted under a live link (``controllerRestarted``: a restart clears GV0..GV99);
  another nonzero value is another master's token (a sign of another master, not a restart;
  see :meth:`LinkSupervisor.canary_read`).
* **Which controller**: every connect decides the :class:`~app.link.types.ControllerIdentity`
  (endpoint, unit, word order, the canary's token) and publishes it in the
  ``ConnectionState`` (``controller``) before the link goes live. The canary is *read* first
  (write-free): when the last connection was to the same endpoint and unit and the canary still
  holds the token written then, it is the same boot and the token is kept; otherwise a fresh one
  is written, a new identity. A restart under a live link gives a new identity too, published
  before ``controllerRestarted``. The GUI's points follow it (``ui/controllers/point_sync.py``).
"""

from __future__ import annotations

import dataclasses
import enum
import logging
import random
import time
from typing import Protocol

from app import timing
from app.connection import ConnectionSettings
from app.errors import LinkError, Reason, ResponseTimeout, TeachPadError
from app.link.capture import TrafficCapture
from app.link.client import RobotClient
from app.link.foreign import ForeignSighting
from app.link.types import ConnectionState, ControllerIdentity, LinkState, Operation
from app.models import ControllerStatus, Pose
from app.protocol import registers
from app.protocol.registers import UPLOAD_POSE_GV
from app.safety.audit import AuditLog
from app.safety.caps import MotionCaps

__all__ = ["Cause", "LinkSupervisor", "Opened", "Silence", "SupervisorOutputs", "check_canary_gv"]

#: Why the link changed: the typed error (its reason goes to the GUI), or only English text
#: (the link-loss reason without a detail then).
Cause = TeachPadError | str

_log = logging.getLogger(__name__)


def check_canary_gv(canary_gv: int | None) -> None:
    if canary_gv is not None and not (UPLOAD_POSE_GV + 6 <= canary_gv <= registers.GV_GENERAL_LAST):
        raise ValueError(
            f"the restart canary must be a spare general-purpose GV in "
            f"GV{UPLOAD_POSE_GV + 6}..GV{registers.GV_GENERAL_LAST} (uploads use "
            f"GV{UPLOAD_POSE_GV}..GV{UPLOAD_POSE_GV + 5}), got GV{canary_gv}"
        )


class SupervisorOutputs(Protocol):
    """What the supervisor emits (the worker's signals); no part, no timer."""

    def publish_connection(self, state: ConnectionState) -> None: ...
    def publish_restarted(self) -> None: ...
    def emit_error(
        self, operation: str, message: str, request_id: int | None = -1, reason: Reason | None = None
    ) -> None: ...


@dataclasses.dataclass(frozen=True, slots=True)
class Opened:
    """A connection attempt that read the controller (:meth:`LinkSupervisor.open`)."""

    client: RobotClient
    status: ControllerStatus
    pose: Pose
    ever_connected: bool  # a reconnection: a jog left running by the lost link is stopped first


class Silence(enum.Enum):
    """What a silent poll means (:meth:`LinkSupervisor.poll_silent`)."""

    BEGAN = "began"  # NOT_ANSWERING now: the held jog is dropped
    GOES_ON = "goes on"  # still silent, not for long enough to declare the link down
    LOST = "lost"  # silent for NOT_ANSWERING_DOWN_AFTER: the link is lost


class LinkSupervisor:
    """Owns the client and the link state; decides, and returns what it decided."""

    def __init__(self, out: SupervisorOutputs, canary_gv: int | None, *, capture: TrafficCapture) -> None:
        """``out``: the signals it emits; ``capture``: the traffic recorder, attached to each new client."""
        check_canary_gv(canary_gv)
        self._out = out
        self._capture = capture
        self.canary_gv = canary_gv
        self.client: RobotClient | None = None
        self.settings: ConnectionSettings | None = None
        self.state = ConnectionState(LinkState.DISCONNECTED)
        self.link_up = False
        self.answering = True  # False while the link is up but polls time out
        self._silent_since = 0.0
        self._ever_connected = False
        self._failures = 0
        self._backoff_index = 0
        self.canary_token: float | None = None  # what we wrote to the canary GV (None: not checking)
        self._canary_foreign: float | None = None  # another master's value last seen there
        self._rearm_at: float | None = None  # after a restart: when our token is written (monotonic)
        # the controller of the live connection, kept after it ends: the next connect compares
        self.identity: ControllerIdentity | None = None
        self._random = random.Random()

    # --- state ----------------------------------------------------------------------------
    def set_state(self, state: LinkState, message: str, reason: Reason | None = None) -> None:
        settings = self.settings
        new = ConnectionState(
            state,
            message,
            settings.endpoint if settings else "",
            bool(settings and settings.monitor_only),
            reason,
            self.identity if self.link_up else None,
        )
        if new != self.state:
            self.state = new
            _log.info("link %s %s%s", new.endpoint, state.value, f": {message}" if message else "")
            self._out.publish_connection(new)

    # --- connecting ----------------------------------------------------------------------
    def begin(self, settings: ConnectionSettings, *, audit: AuditLog | None, caps: MotionCaps | None) -> None:
        """A new connection (the last one closed): a new client for ``settings`` (CONNECTING is
        the caller's to say, once the jog has forgotten the last connection's teach mode)."""
        self.settings = settings
        self.client = RobotClient(settings)
        self.client.audit = audit  # the audit trail records every write
        self.client.caps = caps  # reduced-speed mode's caps
        # another master's parameter / command writes: the shared registers read with a status
        # read once a clock period (polls, and the reads of uploads and command waits alike)
        self.client.watch_shared_every = timing.CLOCK_POLL_PERIOD
        self._capture.attach(self.client)
        self._ever_connected = False
        self._backoff_index = 0

    def open(self) -> Opened | None:
        """One connection attempt: open, read status and pose (None: nothing to attempt). Raises
        the :class:`TeachPadError` of the attempt (then :meth:`down` gives the retry's delay)."""
        client = self.client
        if client is None or self.link_up:
            return None
        client.close()
        client.connect()
        status = client.read_status(with_clock=True)
        pose = client.read_pose()
        return Opened(client, status, pose, self._ever_connected)

    def go_live(self) -> bool:
        """The attempt succeeded (the jog made safe): the link is up. True: a reconnection."""
        self.link_up = True
        self.answering = True
        self._failures = 0
        self._backoff_index = 0
        reconnected = self._ever_connected
        self._ever_connected = True
        return reconnected

    def down(self, cause: Cause, prefix: str = "") -> float:
        """DOWN with ``cause``; the delay (s) before the next attempt (the backoff's next step)."""
        backoff = timing.RECONNECT_BACKOFF
        delay = backoff[min(self._backoff_index, len(backoff) - 1)]
        self._backoff_index += 1
        self.set_state(LinkState.DOWN, prefix + str(cause), self._reason(cause))
        return delay

    # --- which controller, the restart canary ------------------------------------------------
    def identify(self, client: RobotClient) -> TeachPadError | None:
        """Decide the identity of the connection just opened (see the module docstring): keep
        the canary's token when it proves the same boot as the last connection, else arm a new
        one. Returns the link's failure to count (:meth:`arm_canary`)."""
        kept = self._surviving_token(client)
        failure = None
        if kept is not None:
            self.canary_token = kept
        else:
            failure = self.arm_canary()
        self._set_identity()
        return failure

    def _place(self) -> ControllerIdentity | None:
        """The identity of the current settings with the current token (None: no settings)."""
        settings = self.settings
        if settings is None:
            return None
        return ControllerIdentity(
            settings.endpoint, settings.unit, settings.word_order.value, self.canary_gv, self.canary_token
        )

    def _set_identity(self) -> None:
        self.identity = self._place()

    def _surviving_token(self, client: RobotClient) -> float | None:
        """The last connection's token when the canary here still reads it (one read, no write),
        else None: another endpoint or unit, a restart, another master's write, no canary."""
        last, here = self.identity, self._place()
        gv = self.canary_gv
        if last is None or last.boot is None or here is None or gv is None or client.settings.monitor_only:
            return None
        if dataclasses.replace(here, boot=last.boot) != last:  # another endpoint, unit, word order
            return None
        try:
            value = client.read_gv(gv)[0]
        except TeachPadError as exc:
            _log.warning("could not read the restart canary GV%s: %s", gv, exc)
            return None
        if value == self._canary_foreign and value != 0.0:
            return last.boot  # another master's token we saw under the live link: the same boot
        if value != last.boot:
            _log.info(
                "restart canary GV%s reads %g, not %g: another controller or another boot",
                gv,
                value,
                last.boot,
            )
            return None
        return last.boot

    def arm_canary(self, token: float | None = None) -> TeachPadError | None:
        """Write a fresh random token (or ``token``) to the canary GV (not in monitor-only mode,
        not when disabled). A failed write is reported; returned when it is the link's failure
        (to count against the link: :func:`app.link.lifecycle.link_failed`), else None."""
        self.canary_token = None
        self._canary_foreign = None
        self._rearm_at = None
        client = self.client
        gv = self.canary_gv
        if gv is None or client is None or client.settings.monitor_only:
            return None
        if token is None:
            token = self.new_token()
        try:
            client.write_gv(gv, [token])
        except TeachPadError as exc:
            self._out.emit_error(
                Operation.CANARY, f"could not write the restart canary GV{gv}: {exc}", None, exc.as_reason()
            )
            return exc if isinstance(exc, (LinkError, ResponseTimeout)) else None
        self.canary_token = token
        return None

    @property
    def rearm_pending(self) -> bool:
        """A restart was seen and our fresh token is not written yet (see :meth:`canary_read`)."""
        return self._rearm_at is not None

    def new_token(self) -> float:
        return float(self._random.randint(1, 1 << 23))  # nonzero, exact in float32

    def canary_read(self, value: float) -> TeachPadError | None:
        """The canary GV as read on the clock poll (issue 19). A restart clears GV0..GV99, so
        only 0 reads as "the controller restarted" (new identity, armed again). Any other value
        than ours was written by another master: not a restart (the identity and the points stay),
        a sighting of another master (:mod:`app.link.foreign`) once per value, and our token is
        not written back (two TeachPads would fight over it). A reconnect accepts the value last
        seen as well as ours (:meth:`_surviving_token`).

        After a restart our fresh token is written only :data:`app.timing.CANARY_REARM_DELAY`
        later, while the canary still reads 0: another TeachPad reading once a second sees the 0
        (the restart) too, instead of our token. When another host's token shows first, it
        stands for this boot and nothing is written. Returns the link's failure to count (the
        rearm's write: :meth:`arm_canary`), else None."""
        if self.canary_token is None:
            return None
        if self._rearm_at is not None:
            return self._pending_rearm(value)
        if value in (self.canary_token, self._canary_foreign):
            return None
        if value != 0.0:
            _log.warning(
                "restart canary GV%s reads %g instead of %g: another master wrote it (not a restart)",
                self.canary_gv,
                value,
                self.canary_token,
            )
            self._canary_foreign = value
            client = self.client
            if client is not None:
                client.foreign.add(ForeignSighting("canary", value, time.monotonic()))
            return None
        _log.warning(
            "restart canary GV%s reads 0 instead of %g: the controller restarted",
            self.canary_gv,
            self.canary_token,
        )
        if self.client is not None:
            self.client.invalidate_cache()  # GV245 and friends may have been reset too
        self.canary_token, self._canary_foreign = self.new_token(), None  # written after the delay
        self._rearm_at = time.monotonic() + timing.CANARY_REARM_DELAY
        self._set_identity()  # another boot: published before the restart itself, so the GUI's
        if self.link_up:  # points are unknown by the time it hears of the restart
            self.set_state(self.state.state, self.state.message, self.state.reason)
        self._out.publish_restarted()
        return None

    def _pending_rearm(self, value: float) -> TeachPadError | None:
        """After a restart, before our token is written: ``value`` dealt with here (the rearm's
        failure to count returned, see :meth:`arm_canary`)."""
        if value == 0.0:
            rearm_at = self._rearm_at
            failure = None
            if rearm_at is not None and time.monotonic() >= rearm_at:
                token = self.canary_token
                failure = self.arm_canary(token)
                self._set_identity()  # the same token: the identity does not change
            return failure
        self._rearm_at = None  # another host wrote its token first: it stands for this boot
        self._canary_foreign = value
        client = self.client
        if client is not None:  # (another master is there)
            client.foreign.add(ForeignSighting("canary", value, time.monotonic()))
        return None

    # --- failures ----------------------------------------------------------------------
    def answering_again(self) -> bool:
        """A good poll (the failures in a row end). True when it ends a silence: the jog gets
        its ratio 0 first, then :meth:`set_state` ``CONNECTED`` (:func:`app.link.lifecycle.answered`)."""
        self._failures = 0
        if self.answering:
            return False
        self.answering = True
        return True

    def poll_silent(self, cause: Cause, now: float) -> Silence:
        """A poll timed out with the link open: NOT_ANSWERING at once; lost when it lasts."""
        if self.answering:
            self.answering = False
            self._silent_since = now
            self.set_state(LinkState.NOT_ANSWERING, str(cause), self._reason(cause))
            return Silence.BEGAN
        if now - self._silent_since >= timing.NOT_ANSWERING_DOWN_AFTER:
            return Silence.LOST
        return Silence.GOES_ON

    def transport_failed(self, cause: Cause) -> bool:
        """A failed transaction counted; True when they are :data:`app.timing.LINK_LOSS_POLLS`
        in a row (the link is lost: :func:`app.link.lifecycle.lose_link`)."""
        self._failures += 1
        return self._failures >= timing.LINK_LOSS_POLLS

    def _reason(self, cause: Cause) -> Reason:
        """The GUI's reason for ``cause``: the typed error's own, else "link lost" (its English
        text is a detail for the log)."""
        if isinstance(cause, TeachPadError):
            return cause.as_reason()
        settings = self.settings
        return Reason("link_lost", {"endpoint": settings.endpoint} if settings else {})

    def lost(self) -> None:
        """The link is declared down (the jog, the upload and the queue are told by the caller);
        the canary stops being checked."""
        self.link_up = False
        self.answering = True
        self._failures = 0
        self.canary_token = None

    def drop_client(self) -> None:
        """After a loss: the client's connection closed (the client kept for the next attempt)."""
        if self.client is not None:
            self.client.close()
        self._backoff_index = 0

    def close(self) -> None:
        """The link closed for good (disconnect, new settings, shutdown): the client goes."""
        client = self.client
        self.canary_token = None
        self.link_up = False
        self.answering = True
        if client is not None:
            self._capture.detach(client)
            client.close()
        self.client = None
