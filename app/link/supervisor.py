"""The link supervisor: connect, back off and retry, notice silence and restarts (worker thread).

* **Connect**: open, read status and pose, make jogging safe, write the restart canary, go live
  (``CONNECTED``), then the queued jobs run.
* **Not answering**: a poll that times out with the link still open shows ``NOT_ANSWERING`` at
  once (the held jog is dropped; ratio 0 goes out as soon as the controller answers again); a
  good poll shows ``CONNECTED`` again. Silence lasting :data:`app.timing.NOT_ANSWERING_DOWN_AFTER`
  declares the link down.
* **Link loss**: :data:`app.timing.LINK_LOSS_POLLS` failed transactions in a row (refused, reset,
  command timeouts) declare the link ``DOWN`` at once; reconnection follows
  :data:`app.timing.RECONNECT_BACKOFF` by itself and ends with ``controllerReconnected``.
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
import logging
import random
import time

from app import timing
from app.connection import ConnectionSettings
from app.errors import LinkError, Reason, ResponseTimeout, TeachPadError
from app.link.active import MotionTracker
from app.link.capture import TrafficCapture
from app.link.client import RobotClient
from app.link.foreign import ForeignSighting
from app.link.host import WorkerHost
from app.link.types import ConnectionState, ControllerIdentity, LinkState, Operation
from app.protocol import registers
from app.protocol.registers import UPLOAD_POSE_GV

__all__ = ["Cause", "LinkSupervisor", "check_canary_gv"]

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


class LinkSupervisor:
    """Owns the client and the link state."""

    def __init__(
        self, host: WorkerHost, canary_gv: int | None, *, tracker: MotionTracker, capture: TrafficCapture
    ) -> None:
        """``tracker``: the command under way (its outcome unknown when the link goes);
        ``capture``: the traffic recorder, attached to each new client."""
        check_canary_gv(canary_gv)
        self._host = host
        self._tracker = tracker
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
            self._host.publish_connection(new)

    # --- connecting ----------------------------------------------------------------------
    def connect_to(self, settings: ConnectionSettings) -> None:
        host = self._host
        # Jobs queued since the GUI asked for this connection run once it is up.
        self.close_link(Operation.CONNECT, LinkState.DISCONNECTED, "", emit=False, fail_queued=False)
        self.settings = settings
        self.client = RobotClient(settings)
        self.client.audit = getattr(host, "audit", None)  # the audit trail records every write
        self.client.caps = host.caps  # reduced-speed mode's caps
        # another master's parameter / command writes: the shared registers read with a status
        # read once a clock period (polls, and the reads of uploads and command waits alike)
        self.client.watch_shared_every = timing.CLOCK_POLL_PERIOD
        self._capture.attach(self.client)
        self._ever_connected = False
        self._backoff_index = 0
        host.jog.reset()
        self.set_state(LinkState.CONNECTING, "")
        self.try_connect()

    def try_connect(self) -> None:
        """One connection attempt: open, read status and pose, make jogging safe, go live."""
        host = self._host
        client = self.client
        if host.closed or client is None or self.link_up:
            return
        try:
            client.close()
            client.connect()
            status = client.read_status(with_clock=True)
            pose = client.read_pose()
            host.jog.make_teach_safe(status, self._ever_connected)
        except TeachPadError as exc:
            self.schedule_reconnect(exc)
            return
        self.link_up = True
        self.answering = True
        self._failures = 0
        self._backoff_index = 0
        reconnected = self._ever_connected
        self._ever_connected = True
        host.poller.reset(time.monotonic())
        self.identify(client)  # before the GUI hears of the link: a restart from now on is noticed
        self.set_state(LinkState.CONNECTED, "")
        host.poller.publish(pose, status)
        if reconnected:
            host.publish_reconnected()
        host.start_polling()
        host.run_jobs()

    def schedule_reconnect(self, cause: Cause, prefix: str = "") -> None:
        backoff = timing.RECONNECT_BACKOFF
        delay = backoff[min(self._backoff_index, len(backoff) - 1)]
        self._backoff_index += 1
        self.set_state(LinkState.DOWN, prefix + str(cause), self._reason(cause))
        if not self._host.closed:
            self._host.start_reconnect(delay)

    # --- which controller, the restart canary ------------------------------------------------
    def identify(self, client: RobotClient) -> None:
        """Decide the identity of the connection just opened (see the module docstring): keep
        the canary's token when it proves the same boot as the last connection, else arm a new one."""
        kept = self._surviving_token(client)
        if kept is not None:
            self.canary_token = kept
        else:
            self.arm_canary()
        self._set_identity()

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

    def arm_canary(self, token: float | None = None) -> None:
        """Write a fresh random token (or ``token``) to the canary GV (not in monitor-only mode,
        not when disabled)."""
        self.canary_token = None
        self._canary_foreign = None
        self._rearm_at = None
        client = self.client
        gv = self.canary_gv
        if gv is None or client is None or client.settings.monitor_only:
            return
        if token is None:
            token = self.new_token()
        try:
            client.write_gv(gv, [token])
        except TeachPadError as exc:
            self._host.emit_error(
                Operation.CANARY, f"could not write the restart canary GV{gv}: {exc}", None, exc.as_reason()
            )
            if isinstance(exc, (LinkError, ResponseTimeout)):
                self.transport_failed(exc)
            return
        self.canary_token = token

    @property
    def rearm_pending(self) -> bool:
        """A restart was seen and our fresh token is not written yet (see :meth:`canary_read`)."""
        return self._rearm_at is not None

    def new_token(self) -> float:
        return float(self._random.randint(1, 1 << 23))  # nonzero, exact in float32

    def canary_read(self, value: float) -> None:
        """The canary GV as read on the clock poll (issue 19). A restart clears GV0..GV99, so
        only 0 reads as "the controller restarted" (new identity, armed again). Any other value
        than ours was written by another master: not a restart (the identity and the points stay),
        a sighting of another master (:mod:`app.link.foreign`) once per value, and our token is
        not written back (two TeachPads would fight over it). A reconnect accepts the value last
        seen as well as ours (:meth:`_surviving_token`).

        After a restart our fresh token is written only :data:`app.timing.CANARY_REARM_DELAY`
        later, while the canary still reads 0: another TeachPad reading once a second sees the 0
        (the restart) too, instead of our token. When another host's token shows first, it
        stands for this boot and nothing is written."""
        if self.canary_token is None:
            return
        if self._rearm_at is not None and self._pending_rearm(value):
            return
        if value in (self.canary_token, self._canary_foreign):
            return
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
            return
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
        self._host.publish_restarted()

    def _pending_rearm(self, value: float) -> bool:
        """After a restart, before our token is written: True when ``value`` is dealt with here."""
        if value == 0.0:
            rearm_at = self._rearm_at
            if rearm_at is not None and time.monotonic() >= rearm_at:
                token = self.canary_token
                self.arm_canary(token)
                self._set_identity()  # the same token: the identity does not change
            return True
        self._rearm_at = None  # another host wrote its token first: it stands for this boot
        self._canary_foreign = value
        client = self.client
        if client is not None:  # (another master is there)
            client.foreign.add(ForeignSighting("canary", value, time.monotonic()))
        return True

    # --- failures ----------------------------------------------------------------------
    def poll_answered(self) -> None:
        """A good poll: back to CONNECTED after a silence (ratio 0 first if a jog was under way)."""
        self._failures = 0
        if self.answering:
            return
        self.answering = True
        try:
            self._host.jog.controller_answers()
        except TeachPadError as exc:
            self._host.emit_error(
                Operation.JOG_RELEASE, f"could not stop the jog: {exc}", None, exc.as_reason()
            )
            if isinstance(exc, (LinkError, ResponseTimeout)):
                self.transport_failed(exc)
                if not self.link_up:
                    return
        self.set_state(LinkState.CONNECTED, "")

    def poll_silent(self, cause: Cause, now: float) -> None:
        """A poll timed out with the link open: NOT_ANSWERING at once; DOWN when it lasts."""
        if self.answering:
            self.answering = False
            self._silent_since = now
            self.set_state(LinkState.NOT_ANSWERING, str(cause), self._reason(cause))
            self._host.jog.controller_silent()  # tells the operator itself when a jog was under way
        elif now - self._silent_since >= timing.NOT_ANSWERING_DOWN_AFTER:
            self.link_lost(cause)

    def transport_failed(self, cause: Cause) -> None:
        self._failures += 1
        if self._failures >= timing.LINK_LOSS_POLLS:
            self.link_lost(cause)

    def _reason(self, cause: Cause) -> Reason:
        """The GUI's reason for ``cause``: the typed error's own, else "link lost" (its English
        text is a detail for the log)."""
        if isinstance(cause, TeachPadError):
            return cause.as_reason()
        settings = self.settings
        return Reason("link_lost", {"endpoint": settings.endpoint} if settings else {})

    def link_lost(self, cause: Cause) -> None:
        """Declare the link down at once; the reconnect timer takes over."""
        if not self.link_up:
            return
        host = self._host
        self.link_up = False
        self.answering = True
        self._failures = 0
        host.stop_polling()
        host.jog.link_lost()
        self.canary_token = None
        host.uploader.end(f"link lost: {cause}")
        self._fail_active(
            "link lost while the command was under way; its outcome is unknown", "outcome_unknown_link_lost"
        )
        host.fail_queued("the link to the controller is down: not sent", "queued_link_down")
        if self.client is not None:
            self.client.close()
        self._backoff_index = 0
        self.schedule_reconnect(cause, "link lost: ")

    def close_link(
        self,
        operation: str,
        state: LinkState,
        message: str,
        *,
        emit: bool = True,
        fail_queued: bool = True,
        short: bool = False,
    ) -> None:
        """Stop jogging and switch teach off (if the controller answers), close, stop retrying.

        ``short`` (shutdown): those safety transactions wait at most the poll timeout each, so a
        dead controller cannot hold the window's close for the request timeout."""
        host = self._host
        host.stop_reconnect()
        host.stop_polling()
        client = self.client
        if client is not None and self.link_up and not client.settings.monitor_only:
            try:
                if short:
                    with client.io_timeout(client.settings.effective_poll_timeout):
                        host.jog.stop_jog_and_teach()
                else:
                    host.jog.stop_jog_and_teach()
            except TeachPadError as exc:
                host.emit_error(operation, f"could not stop teach mode: {exc}", None, exc.as_reason())
        self.canary_token = None
        host.uploader.end(f"{operation}: the link was closed")
        self._fail_active(
            f"{operation}: the link was closed while the command was under way", "outcome_unknown_link_closed"
        )
        if fail_queued:
            host.fail_queued(f"{operation}: the link was closed: not sent", "queued_link_closed")
        self.link_up = False
        self.answering = True
        if client is not None:
            self._capture.detach(client)
            client.close()
        self.client = None
        host.poller.forget()
        if emit:
            self.set_state(state, message)

    def _fail_active(self, message: str, code: str) -> None:
        active = self._tracker.take()
        if active is not None:
            # its outcome is unknown: said so, and recorded so against its command in the audit
            result = active.completion.unknown(
                time.monotonic(),
                message=f"{active.operation}: {message}",
                reason=Reason(code, {"operation": active.operation}),
            )
            self._host.emit_result(result, active.request_id)
