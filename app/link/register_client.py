"""RegisterClient: the controller's registers over one checked link, with the one write guard.

The lower half of :class:`~app.link.client.RobotClient` (which adds the commands and their
completion on top): it owns the :class:`~app.link.transport.Transport` (TCP, RTU over serial,
or RTU framing over TCP for tests), which checks every answer against its request and counts
what the wire did (:attr:`RegisterClient.stats`); every write passes :meth:`_write` (monitor-only
mode, the audit trail); raw register/GV access refuses bad values before anything is sent; the
pose and status blocks are read and decoded here. Not thread-safe: one thread owns it.

* Control registers 440-445 are written with 0x06 only; raw multi-register writes that touch
  them are refused (:class:`InvalidInput`).
* A request that timed out or got a malformed answer closes the link (the next request
  reconnects), so a late answer is never read as the next request's; on a serial line the input
  is dropped until the line is quiet, and what is safe to repeat is sent again
  (:mod:`app.link.line_retry`: every read; a write of value registers when asked, read back first).
* Traffic observers are called synchronously in the client's thread, inside the request:
  keep them short (the GUI should only queue the record).
"""

from __future__ import annotations

import contextlib
import functools
import logging
import time
from collections.abc import Callable, Iterator, Sequence
from typing import Self

from app import timing
from app.connection import ConnectionSettings
from app.errors import InvalidInput, WriteBlocked
from app.link.checks import check_float, check_int, check_settings, range_name
from app.link.decode import decode_pose, decode_status
from app.link.foreign import ForeignMasterWatch
from app.link.line_retry import LINE_ERRORS, LineRetry, on_noisy_line
from app.link.stats import LinkStats
from app.link.transport import TrafficObserver, Transport
from app.models import ControllerStatus, Pose
from app.protocol import registers
from app.protocol.codec import decode_floats, encode_floats
from app.protocol.datetime_regs import ControllerClock, decode_clock
from app.safety.audit import AuditLog
from app.safety.audit_read import AuditRecord

__all__ = ["RegisterClient"]

_log = logging.getLogger(__name__)

CONTROL_REGISTERS = range(registers.REG_RUN_COMMAND, registers.REG_GO_ZERO + 1)  # 440..445: 0x06 only
MAX_REGISTER = 0xFFFF


@functools.lru_cache(maxsize=512)
def _what(verb: str, address: int, count: int) -> str:
    """E.g. "read of registers 560..583 (...)": made once per block, not per request (hot path)."""
    return f"{verb} {range_name(address, count)}"


#: The parameter and command registers every master shares, read in two blocks and compared:
#: GV200..GV205 (registers 400..411; GV206.. are the live pose) but not GV203, the jog ratio a
#: controller's watchdog may zero itself; and GV221..GV227 (442..455). Not the command and stop
#: registers 440/441: our own Stop may go on the stop line (app/link/stop_line.py), and a read
#: touching the stop register must not stand between a Stop and the controller.
SHARED_BLOCKS = (
    (registers.gv_reg(registers.GV_PARAM0), registers.gv_reg(206) - registers.gv_reg(registers.GV_PARAM0)),
    (registers.REG_PAUSE, registers.gv_reg(228) - registers.REG_PAUSE),
)
_RATIO = (registers.gv_reg(registers.GV_PARAM3), registers.gv_reg(registers.GV_PARAM3) + 1)


class RegisterClient:
    """Registers, GVs and the pose/status blocks of one controller. Blocking; owned by one thread."""

    def __init__(self, settings: ConnectionSettings) -> None:
        check_settings(settings)
        self.settings = settings
        self._transport = Transport(settings, on_link_change=self.invalidate_cache)
        self.last_status: ControllerStatus | None = None
        self.status_read_at = 0.0  # when the last status read was answered (monotonic)
        self.write_count = 0  # writes handed to the link (the CLI uses it to know what to undo)
        self._io_timeout: float | None = None  # see io_timeout()
        self.audit: AuditLog | None = None  # every write (and monitor-only block) is recorded here
        # The writes other than Stop: all answered (writes_settled), the last one when (monotonic)
        self.writes_settled = True
        self.write_answered_at = 0.0
        self.write_lost_until = 0.0  # a write without its answer may be acted on until then
        self._judged: list[AuditRecord] | None = None  # see judged_writes()
        self.foreign = ForeignMasterWatch()  # another master's GV291 results (app/link/foreign.py)
        # read the shared registers with a status read at most this often (s; None: never; the
        # GUI's link and the CLI set it, app/link/foreign.py)
        self.watch_shared_every: float | None = None
        self._shared_read_at = -1e9
        self._noisy_line = on_noisy_line(settings)  # damaged frames are sent again (line_retry.py)
        # the registers of the last pose and status reads, as answered (the watch list decodes the
        # values it watches inside them from these: app/link/watch_list.py)
        self.pose_registers: list[int] | None = None
        self.status_registers: list[int] | None = None

    # -- connection ----------------------------------------------------------------------
    def connect(self) -> None:
        """Open the link; :class:`LinkError` naming the cause when the controller cannot be reached."""
        self._transport.open()

    def close(self) -> None:
        self._transport.close()

    @property
    def connected(self) -> bool:
        return self._transport.connected

    def __enter__(self) -> Self:
        self.connect()
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def invalidate_cache(self) -> None:
        """Called whenever the link is made or lost: forget what was cached about the controller.

        Nothing at this layer; :class:`~app.link.client.RobotClient` drops its parameter cache.
        """

    @property
    def stats(self) -> LinkStats:
        """The link's counters so far (a snapshot)."""
        return self._transport.stats

    # -- observers -----------------------------------------------------------------------
    def add_observer(self, cb: TrafficObserver) -> None:
        self._transport.add_observer(cb)

    def remove_observer(self, cb: TrafficObserver) -> None:
        self._transport.remove_observer(cb)

    # -- the transport: every answer is checked against its request ----------------------
    def _read(self, address: int, count: int, timeout: float | None = None) -> list[int]:
        """0x03; on a serial line a read whose frame was damaged is sent again (a read changes
        nothing), up to :data:`app.timing.LINE_READ_RETRIES` times."""
        timeout = self._io_timeout if timeout is None else timeout
        what = _what("read of", address, count)
        try:
            return self._transport.read(what, address, count, timeout)
        except LINE_ERRORS as exc:
            if not self._noisy_line:
                raise
            return self._read_again(what, address, count, timeout, exc)

    def _read_again(
        self, what: str, address: int, count: int, timeout: float | None, error: BaseException
    ) -> list[int]:
        """A read whose frame was damaged on the serial line, sent again within its budget."""
        retry = LineRetry(self.settings, timing.LINE_READ_RETRIES)
        while retry.may_retry(error):
            try:
                return self._transport.read(what, address, count, timeout)
            except LINE_ERRORS as exc:
                error = exc
        raise error

    @contextlib.contextmanager
    def io_timeout(self, seconds: float) -> Iterator[None]:
        """Every transaction inside waits at most ``seconds`` per attempt (unless it passes its
        own ``timeout``): the shutdown's ratio 0 / teach disable must not hang on a dead controller."""
        outer, self._io_timeout = self._io_timeout, float(seconds)
        try:
            yield
        finally:
            self._io_timeout = outer

    @contextlib.contextmanager
    def judged_writes(self) -> Iterator[list[AuditRecord]]:
        """The writes inside await the controller's outcome in the audit trail: each is recorded
        as judged (its record reads *unknown* until an outcome is recorded against it, see
        :meth:`AuditLog.record_result`), and the list yielded collects their records (empty without
        a trail). :func:`app.link.outcome.outcome_note` records the outcome against them."""
        outer, self._judged = self._judged, []
        try:
            yield self._judged
        finally:
            self._judged = outer

    def _require_writable(self, what: str) -> None:
        if self.settings.monitor_only:
            raise WriteBlocked(f"monitor-only mode: {what} was not sent")

    def _write(
        self, address: int, values: Sequence[int], *, single: bool = False, timeout: float | None = None
    ) -> None:
        """The write guard: every write to the controller passes here (and, with an audit trail,
        is recorded there once, blocked ones too). ``timeout`` (s per attempt) overrides the
        request timeout (default: :meth:`io_timeout`'s, else the settings')."""
        timeout = self._io_timeout if timeout is None else timeout
        judged = self._judged
        audit = self.audit
        ctx = (
            audit.writing(address, values, single=single, judged=judged is not None)
            if audit
            else contextlib.nullcontext()
        )
        with ctx as intent:
            if judged is not None and intent is not None:
                judged.append(intent)
            what = _what("write to", address, len(values))
            self._require_writable(what)
            if not values:
                raise InvalidInput("nothing to write")
            tracked = address != registers.REG_STOP
            if tracked:  # settled again below, when the controller has answered it
                self.writes_settled = False
            self.foreign.note_write(time.monotonic())
            try:
                self._send_write(what, address, values, single, timeout)
            except BaseException:
                self.foreign.note_registers(address, values, stored=False)
                if tracked:  # no answer (or a refusal): it may still be acted on, until the timeout ran out
                    self.write_lost_until = time.monotonic() + self.settings.timeout
                raise
            self.foreign.note_write(time.monotonic())  # its answer may come from now on
            self.foreign.note_registers(address, values, stored=True)
            if tracked:
                self.write_answered_at = time.monotonic()
                self.writes_settled = True

    def _send_write(
        self, what: str, address: int, values: Sequence[int], single: bool, timeout: float | None
    ) -> None:
        """One 0x06 or 0x10 on the transport (checked, counted)."""
        if single:
            if len(values) != 1:
                raise InvalidInput("a single-register write takes one value")
            _log.debug("%s: 0x06 <- %d", what, values[0])
            self.write_count += 1
            self._transport.write_single(what, address, int(values[0]), timeout)
        else:
            if _log.isEnabledFor(logging.DEBUG):  # the hex text costs more than the write's own Python
                _log.debug("%s: 0x10 <- %s", what, " ".join(f"{v:04X}" for v in values))
            self.write_count += 1
            self._transport.write_multiple(what, address, list(map(int, values)), timeout)

    def writes_settled_before(self, moment: float) -> bool:
        """Every write but Stop's (441) this client began was answered before ``moment``
        (``time.monotonic()``): the controller took each of them before anything sent later on
        another connection. False while a write is without its answer, and until one timeout
        after a write that failed (no answer, refused): a controller acts on a request within the
        link timeout or not at all (the decision of ``app.cli.context.stop_on_a_fresh_link``)."""
        return self.writes_settled and self.write_answered_at < moment and self.write_lost_until < moment

    def _write_floats(
        self,
        gv: int,
        values: Sequence[float],
        timeout: float | None = None,
        *,
        repeatable: bool = False,
        halted: Callable[[], bool] | None = None,
    ) -> None:
        """GVs from ``gv`` on (one 0x10). ``repeatable``: they only hold values (no motion, no
        mode) and may be written again on a noisy line (:meth:`_write_repeatable`)."""
        regs = encode_floats(values, self.settings.word_order)
        if repeatable and self._noisy_line:
            self._write_repeatable(registers.gv_reg(gv), regs, timeout, halted)
        else:
            self._write(registers.gv_reg(gv), regs, timeout=timeout)

    def _write_repeatable(
        self, address: int, regs: Sequence[int], timeout: float | None, halted: Callable[[], bool] | None
    ) -> None:
        """A write of value registers over a noisy serial line: after a damaged frame (its answer
        or its request) they are read back -- the values there: it took; else written again at
        once, up to :data:`app.timing.LINE_WRITE_RETRIES` times (not once ``halted``). Nothing else
        is written in between: a repeated write never lands after a newer one."""
        retry = LineRetry(self.settings, timing.LINE_WRITE_RETRIES, halted)
        while True:
            try:
                self._write(address, regs, timeout=timeout)
                return
            except LINE_ERRORS as exc:
                if not retry.may_retry(exc):
                    raise
            if self._read_back_holds(address, regs):
                return

    def _read_back_holds(self, address: int, regs: Sequence[int]) -> bool:
        """After a write whose frame was damaged: do the registers hold what it wrote? Yes: the
        write took (its answer was damaged), noted as answered for the foreign-master watch. (Its
        audit record keeps the error its answer met: what the wire did.)"""
        try:
            held = self._read(address, len(regs))
        except LINE_ERRORS:
            return False  # not known: written again
        if held != [int(v) & 0xFFFF for v in regs]:
            return False
        _log.info("%s: its answer was damaged; read back, it took", _what("write to", address, len(regs)))
        self.foreign.note_registers(address, regs, stored=True)
        self.write_answered_at = time.monotonic()
        self.writes_settled = True
        return True

    def _write_control(self, register: int, value: int) -> None:
        self._write(register, [value], single=True)

    # -- raw access ----------------------------------------------------------------------
    def read_registers(self, addr: int, count: int) -> list[int]:
        addr = check_int(addr, 0, MAX_REGISTER, "register address")
        count = check_int(count, 1, MAX_REGISTER + 1 - addr, "register count")
        out: list[int] = []
        while count > 0:
            n = min(count, registers.MAX_READ_REGISTERS)
            out.extend(self._read(addr, n))
            addr += n
            count -= n
        return out

    def write_register(self, addr: int, value: int) -> None:
        """0x06 write of one register (the way 440..445 must be written)."""
        addr = check_int(addr, 0, MAX_REGISTER, "register address")
        value = check_int(value, 0, 0xFFFF, "register value")
        self._write(addr, [value], single=True)

    def write_registers(self, addr: int, values: Sequence[int]) -> None:
        """0x10 write (split every 123 registers); refuses the control registers 440..445."""
        addr = check_int(addr, 0, MAX_REGISTER, "register address")
        regs = [check_int(v, 0, 0xFFFF, "register value") for v in values]
        if not regs:
            raise InvalidInput("nothing to write")
        if addr + len(regs) - 1 > MAX_REGISTER:
            raise InvalidInput("write goes past register 65535")
        end = addr + len(regs)
        if addr < CONTROL_REGISTERS.stop and end > CONTROL_REGISTERS.start:
            raise InvalidInput(
                "registers 440..445 (GV220..GV222) are control registers written one at a time "
                "with 0x06; use write_register or the command methods"
            )
        for i in range(0, len(regs), registers.MAX_WRITE_REGISTERS):
            self._write(addr + i, regs[i : i + registers.MAX_WRITE_REGISTERS])

    def read_gv(self, n: int, count: int = 1) -> list[float]:
        n = check_int(n, 0, MAX_REGISTER // 2, "GV index")
        count = check_int(count, 1, (MAX_REGISTER + 1) // 2 - n, "GV count")
        return decode_floats(self.read_registers(registers.gv_reg(n), 2 * count), self.settings.word_order)

    def write_gv(self, n: int, values: Sequence[float]) -> None:
        n = check_int(n, 0, MAX_REGISTER // 2, "GV index")
        floats = [check_float(v, f"GV{n + i}") for i, v in enumerate(values)]
        self.write_registers(registers.gv_reg(n), encode_floats(floats, self.settings.word_order))

    # -- the pose and status blocks ------------------------------------------------------
    def read_pose(self, *, timeout: float | None = None) -> Pose:
        """Pose, external axes and joints (GV206..GV255) in one FC03 of 100 registers.

        ``timeout`` overrides the request timeout (the poller passes the poll timeout).
        """
        regs = self._read(registers.POSE_BLOCK_START, registers.POSE_BLOCK_COUNT, timeout)
        self.pose_registers = regs
        return decode_pose(regs, self.settings.word_order)

    def read_status(self, with_clock: bool = False, *, timeout: float | None = None) -> ControllerStatus:
        """Table 2 (560..583) in one FC03; the clock (576..579) comes from the same block."""
        regs = self._read(registers.STATUS_BLOCK_START, registers.STATUS_BLOCK_COUNT, timeout)
        self.status_registers = regs
        status = decode_status(
            regs, self.settings.word_order, self.settings.datetime_layout if with_clock else None
        )
        self.last_status = status
        self.status_read_at = time.monotonic()
        self.foreign.note_status(status.command_status_code, self.status_read_at)
        self.watch_shared_if_due(self.status_read_at, timeout)
        return status

    def watch_shared_if_due(self, now: float, timeout: float | None = None) -> None:
        """Read the shared registers when ``watch_shared_every`` says so (a status read calls it);
        not before this client's first command or write (a read-only session has nothing to guard)."""
        every = self.watch_shared_every
        if every is None or (self.write_count == 0 and not self.foreign.has_baseline):
            return
        if now - self._shared_read_at >= every:
            self._shared_read_at = now
            self.watch_shared_registers(timeout=timeout)

    def watch_shared_baseline(self) -> None:
        """Before a command's first write: what the shared registers hold (once per connection)."""
        if self.watch_shared_every is not None and not self.foreign.has_baseline:
            self._shared_read_at = time.monotonic()
            self.watch_shared_registers()

    def watch_shared_registers(self, *, timeout: float | None = None) -> None:
        """One read of the registers every master shares (GV200..GV227: the motion parameters and
        the command register) for the foreign-master watch (:mod:`app.link.foreign`)."""
        watched: list[tuple[int, int]] = []
        for start, count in SHARED_BLOCKS:
            regs = self._read(start, count, timeout)
            watched += [(start + i, v) for i, v in enumerate(regs) if start + i not in _RATIO]
        self.foreign.note_shared(watched, time.monotonic())

    def read_clock(self) -> ControllerClock:
        return decode_clock(self._read(registers.gv_reg(registers.GV_DATE), 4), self.settings.datetime_layout)
