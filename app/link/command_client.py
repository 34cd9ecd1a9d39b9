"""CommandClient: send a command (440) and follow it to its end -- the completion rule.

The middle layer of :class:`~app.link.client.RobotClient`: above
:class:`~app.link.register_client.RegisterClient` (the link, the write guard, raw access), below
the operations (step, create/move/teach ...). It writes 440, hands back a
:class:`~app.link.tracker.CommandTracker` and polls it to its result. Not thread-safe: one thread
owns it.

Decision on the open questions of PROTOCOL.md section 7 that lives here:

* **Completion rule** (``ConnectionSettings.completion``, see app/link/tracker.py): "sentinel"
  writes GV291 <- 0xA5 before each create/teach/move command (one extra 0x10) so the
  controller's own write proves the result; "observe" never writes GV291 and may end an
  instant command *done, unconfirmed*; "auto" (default) probes once, before the first such
  command: write the sentinel, wait ``SENTINEL_PROBE_SETTLE``, read it back -- kept: sentinel;
  Modbus exception or overwritten: observe. Never in monitor-only mode (no command is sent).
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable

from app import timing
from app.connection import ConnectionSettings
from app.errors import (
    ForeignMasterRefused,
    LinkError,
    MalformedResponse,
    ModbusExceptionError,
    Reason,
    ResponseTimeout,
)
from app.link.outcome import outcome_note
from app.link.pacer import ResultPacer
from app.link.register_client import RegisterClient
from app.link.tracker import CommandTracker, CompletionRule, command_text
from app.link.watch import MotionWatch, StateCheck
from app.models import CommandResult, ControllerStatus, Pose
from app.protocol import registers
from app.protocol.enums import (
    STATUS_SENTINEL,
    CommandKind,
    CommandStatus,
    RunCommand,
    decode_command_status,
    decode_status_registers,
)
from app.protocol.exceptions import exception_text, not_carried_out

__all__ = ["CommandClient", "Completion"]

_log = logging.getLogger(__name__)

#: How a command under way is followed: by GV291, by motion (run program, go to zero), or by the
#: state it asks for (the CLI's plain commands).
Completion = CommandTracker | MotionWatch | StateCheck
#: A status or pose read that failed: the command's outcome is not told by it (follow retries).
_READ_ERRORS = (LinkError, ResponseTimeout, MalformedResponse, ModbusExceptionError)
#: Modbus exceptions to the GV291 probe's write that say GV291 cannot be written (illegal
#: function, address, value); any other code says nothing about it.
_READ_ONLY_CODES = frozenset({0x01, 0x02, 0x03})


class CommandClient(RegisterClient):
    """Commands (440) and their completion over the register layer. Blocking; owned by one thread."""

    def __init__(self, settings: ConnectionSettings) -> None:
        super().__init__(settings)
        self._last_kind: CommandKind | None = None
        self.last_tracker: CommandTracker | None = None
        self._gv291_writable: bool | None = None  # completion "auto": None until probed
        self._ack_latency = 0.0  # s, decaying maximum of the acknowledgement times seen
        self._pacer = ResultPacer()  # when results show on this link (tracker.py)

    def command_status(self) -> CommandStatus:
        """GV291 decoded with the table of the last command this client sent."""
        regs = self._read(registers.gv_reg(registers.GV_COMMAND_STATUS), 2)
        code = decode_status_registers(regs, self.settings.word_order)
        now = time.monotonic()
        self.foreign.note_status(code, now)
        self.watch_shared_if_due(now)
        return decode_command_status(self._last_kind, code)

    # -- completion rule (see app/link/tracker.py) ---------------------------------------
    @property
    def completion_rule(self) -> CompletionRule | None:
        """The rule in force; None while "auto" has not probed GV291 yet."""
        mode = self.settings.completion
        if mode != "auto":
            return mode
        if self._gv291_writable is None:
            return None
        return "sentinel" if self._gv291_writable else "observe"

    def probe_gv291(self) -> bool:
        """Does the controller keep what the host writes into GV291? (Completion "auto".)

        Writes the sentinel, waits ``timing.SENTINEL_PROBE_SETTLE`` (a controller that
        re-publishes its status every scan has overwritten it by then) and reads it back. A
        Modbus exception that refuses the write itself (illegal function, address or value: a
        read-only GV291) means no; any other exception (busy, device failure, acknowledge, a
        gateway's, a code the standard does not define) says nothing about GV291: it is raised
        (the command is not sent) and the next command probes again. Safe: GV291 only reports
        the last command's result, which the next command overwrites; the probe runs just before
        a command, never in monitor-only mode. The answer is kept for this client's lifetime.
        """
        self._require_writable("GV291 probe")
        try:
            self._write_floats(registers.GV_COMMAND_STATUS, [float(STATUS_SENTINEL)])
        except ModbusExceptionError as exc:
            if exc.exception_code not in _READ_ONLY_CODES:
                raise
            _log.info("GV291 is read-only (%s): completion rule observe", exc)
            writable = False
        else:
            time.sleep(timing.SENTINEL_PROBE_SETTLE)
            writable = self.read_status().command_status_code == STATUS_SENTINEL
            _log.info(
                "GV291 %s: completion rule %s",
                "keeps the host's value" if writable else "ignores the host's writes",
                "sentinel" if writable else "observe",
            )
        self._gv291_writable = writable
        return writable

    def _unconfirmed_window(self) -> float:
        """How long an unchanged 0xFF waits before "done, unconfirmed" (observe rule)."""
        base = self.settings.unconfirmed_after
        base = timing.UNCONFIRMED_AFTER if base is None else base
        learned = timing.UNCONFIRMED_LATENCY_FACTOR * self._ack_latency
        return min(max(base, learned), timing.ACK_TIMEOUT / 2)

    def _learn_latency(self) -> None:
        """Decay the learned latency by 5 % a command; take in the previous command's
        acknowledgement time (an instant command that was seen to change GV291)."""
        self._ack_latency *= 0.95
        last = self.last_tracker
        if last is None or last.result is None or last.ack_time is None or last.is_move:
            return
        self._ack_latency = max(last.ack_time - last.started, self._ack_latency)

    def begin_command(
        self,
        command: RunCommand,
        before: ControllerStatus,
        before_pose: Pose | None,
        *,
        timeout: float | None = None,
    ) -> CommandTracker:
        """Write 440 <- ``command`` (parameters already written) and return its tracker.

        With the sentinel rule GV291 <- sentinel goes out first (completion "auto" probes
        GV291 before the first command).
        """
        if CommandKind.of(command) is CommandKind.MOVE:  # (the parameters are written by now)
            self.check_no_foreign_master(command_text(command), int(command))
        rule: CompletionRule = "observe"
        pre_code: int | None = None
        if CommandKind.of(command) is not None:
            self._learn_latency()
            probe = self.settings.completion == "auto" and self._gv291_writable is None
            if probe and not self.probe_gv291() and self.last_status is not None:
                pre_code = self.last_status.command_status_code  # the freshest read
            rule = self.completion_rule or "observe"
            if rule == "sentinel":
                self._write_floats(registers.GV_COMMAND_STATUS, [float(STATUS_SENTINEL)])
                pre_code = STATUS_SENTINEL
        tracker = CommandTracker(
            command,
            before,
            before_pose,
            time.monotonic(),
            timeout=timeout,
            rule=rule,
            pre_code=pre_code,
            unconfirmed_after=self._unconfirmed_window(),
            pacer=self._pacer,
        )
        tracker.foreign = self.foreign
        self._last_kind = tracker.kind
        self.last_tracker = tracker
        self.send_trigger(registers.REG_RUN_COMMAND, int(command), tracker)
        return tracker

    def send_trigger(self, register: int, value: int, completion: Completion) -> None:
        """The write that sets a command going (440 <- command, 445 <- axes), judged: its outcome
        goes to the audit trail through ``completion.note`` (:func:`outcome_note`).

        A Modbus exception answer is a refusal only when its code says the request was not
        carried out (:data:`app.protocol.exceptions.NOT_CARRIED_OUT`: raised as it is); any other
        code (device failure, acknowledge, a gateway's target that did not respond, an unknown
        code) leaves open what the controller did: ``completion`` ends *unknown* and its
        :class:`~app.errors.OutcomeUnknown` is raised ("sent; the outcome is unknown -- check the
        robot before sending it again"), and its write reads so in the audit trail."""
        with self.judged_writes() as judged:
            try:
                self._write_control(register, value)
            except ModbusExceptionError as exc:
                if not_carried_out(exc.exception_code):
                    raise
                # (no result line: the write's own outcome line reads unknown, app/safety/audit.py)
                code = exc.exception_code
                completion.unknown(
                    time.monotonic(),
                    f"the controller answered Modbus exception {code} "
                    f"({exception_text(code, 'a code the standard does not define')}), "
                    "which does not say it was not carried out",
                )
                assert completion.error is not None
                raise completion.error from exc
        completion.note = outcome_note(self.audit, judged)  # its outcome goes to the audit trail

    def check_no_foreign_master(self, operation: str, command: int | None = None) -> None:
        """Just before a motion's trigger: read the shared registers back (our parameters still
        there?) and refuse (audited, :class:`ForeignMasterRefused`) when another master was seen
        within :data:`app.timing.FOREIGN_MOVE_HOLD`: a move is never sent over a foreign write."""
        if self.watch_shared_every is not None:  # (a client that does not watch them: GV291 only)
            self.watch_shared_registers()
        foreign = self.foreign
        hold = timing.FOREIGN_MOVE_HOLD
        if not foreign.seen_within(time.monotonic(), hold):
            return
        sighting = foreign.last_sighting
        sign = sighting.message if sighting is not None else "another Modbus master was seen"
        error = ForeignMasterRefused(operation, hold, sign, command)
        if self.audit is not None:
            self.audit.record_refused(operation, str(error), dict(error.params))
        raise error

    def poll(self, tracker: CommandTracker) -> CommandResult | None:
        """One status read (plus the pose for moves) fed to ``tracker``."""
        status = self.read_status()
        pose = self.read_pose() if tracker.is_move else None
        return tracker.update(status, pose, time.monotonic())

    def wait(
        self,
        tracker: CommandTracker,
        *,
        raise_errors: bool = True,
        meanwhile: Callable[[], None] | None = None,
        between: Callable[[], None] | None = None,
    ) -> CommandResult:
        """Poll until ``tracker`` ends; raise its typed error when it failed (by default).

        ``between`` runs after every read that did not end the command, before anything else:
        the worker's urgent jobs (stop, pause, cancel, jog release), so none waits for a
        command's result. A stop it writes on this client ends the command there
        (:meth:`~app.link.tracker.CommandTracker.stopped`: the host sent the stop itself,
        PROTOCOL.md section 7) and the wait returns that result without another read. It may
        raise to abandon the wait (the link went down meanwhile).

        ``meanwhile`` runs once, after the first read when the command has not ended by then:
        a transaction that fills the controller's latency (an upload writes the next point's
        pose into the other pose GVs there). It must not touch what the command reads.
        """
        while True:
            result = self.poll(tracker)  # the first poll is immediate: keep the ack window small
            if result is None and between is not None:
                between()
                result = tracker.result  # a stop the host sent meanwhile ended it
            if result is not None:
                if raise_errors and tracker.error is not None:
                    raise tracker.error
                return result
            if meanwhile is not None:
                work: Callable[[], None] = meanwhile
                meanwhile = None
                work()
            interval = tracker.poll_interval(time.monotonic())
            if interval > 0:
                time.sleep(interval)

    def follow(self, completion: Completion, *, until_started: bool = False) -> CommandResult | None:
        """Poll a command the controller took to its end and return its result; raise its typed
        error when it did not end done. ``completion``: a :class:`CommandTracker` (polled by
        :meth:`wait`) or a :class:`~app.link.watch.MotionWatch` (status and pose every
        ``MOVE_POLL_INTERVAL``); ``until_started`` (a watch): return None once it is seen under way.

        Once the command was answered, a status read that fails does not fail the command: reads
        are retried every ``timing.OUTCOME_READ_RETRY`` for ``timing.OUTCOME_READ_BUDGET`` after the
        first failure (or, unless the link is gone, while the command's own time runs, if longer);
        then the command ends
        *unknown* (:class:`~app.errors.OutcomeUnknown`: "sent; the outcome is unknown -- check the
        robot before sending it again"), recorded so in the audit trail."""
        failed_since: float | None = None
        while True:
            try:
                return self._poll_to_end(completion, until_started)
            except _READ_ERRORS as exc:
                if completion.finished:  # (not a read of this command's: its end is its own)
                    raise
                now = time.monotonic()
                if failed_since is None or self._read_since(failed_since):
                    failed_since = now
                limit = failed_since + timing.OUTCOME_READ_BUDGET
                if not isinstance(exc, LinkError):  # a controller gone for good is not waited for
                    limit = max(limit, completion.deadline)
                if now >= limit:
                    completion.unknown(now, exc)
                    assert completion.error is not None
                    raise completion.error from exc
                time.sleep(timing.OUTCOME_READ_RETRY)

    def _read_since(self, moment: float) -> bool:
        """A status read was answered after ``moment`` (monotonic)."""
        return self.status_read_at > moment

    def _poll_to_end(self, completion: Completion, until_started: bool) -> CommandResult | None:
        if isinstance(completion, CommandTracker):
            return self.wait(completion)
        while True:
            status = self.read_status()
            pose = self.read_pose()
            result = completion.update(status, pose, time.monotonic())
            if result is not None:
                if completion.error is not None:
                    raise completion.error
                return result
            if until_started and completion.seen:
                return None
            time.sleep(timing.MOVE_POLL_INTERVAL)

    def _finish(self, tracker: CommandTracker, wait: bool) -> CommandResult:
        if wait:
            result = self.follow(tracker)
            assert result is not None
            return result
        return CommandResult(
            tracker.command,
            tracker.kind,
            None,
            True,
            f"{tracker.text}: sent",
            reason=Reason("sent", {"command": int(tracker.command)}),
        )
