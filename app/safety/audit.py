"""The audit trail: every write TeachPad sends and every refused action, one JSON line each.

Files: ``<data dir>/audit/audit-YYYY-MM-DD.jsonl`` per (host, local) day; when a day's file
reaches :data:`MAX_FILE_BYTES` the next part is ``audit-YYYY-MM-DD.1.jsonl``, ``.2`` ...
(new files, never renames). After each new file, old ones go: the files of all but the newest
``keep_days`` days *on which something was recorded*, then the oldest until the total is under
``max_total_bytes``.

The PC's clock is not trusted to age files: a clock one year ahead must not delete a year of
records, so nothing is deleted because of what the clock says (only by the count of days on disk
and the size cap: a clock jump deletes at most what an ordinary new day would). A clock stepped
back does not make the writer go back to an older day's file either: within a process the day of
the file only moves forward, so a session's records are in file order, and the reader pairs a
write with its outcome by ``(session, seq)``, whatever the times say.

Crash safety: the file is opened with ``O_APPEND`` and each record is one ``os.write`` of a
whole line, so a ``kill -9`` loses at most the record being written, and a partly written last
line (possible only on a power cut or a full disk) is skipped by the reader and closed with a
newline by the next writer before it appends. ``fsync`` guards against power loss, not process
death (the page cache survives a killed process); :data:`FsyncPolicy.INTERVAL` (the default)
syncs at most once per :data:`FSYNC_INTERVAL` seconds — see ``benchmarks`` in the report for the
cost of syncing every line.

Write-ahead: :meth:`AuditLog.writing` (the client's write guard) appends the write's line
(result ``pending``) *before* the request goes out, and a short ``outcome`` line (``args.ref`` =
the write's ``seq``) once it is answered. The reader merges the two into one record, so every write
the controller may have received is in the file exactly once, also after a ``kill -9``: a write
whose outcome line never came reads as ``unknown`` ("sent; TeachPad stopped before the answer").

A command's write (440, 445, and the CLI's plain commands) is *judged*: an answer says only that
it arrived, so a third line, ``result`` (:meth:`AuditLog.record_result`), records what the
controller made of the command once that is known -- ``done``, ``refused`` (with the GV291 code
in ``args.status`` when there is one), ``stopped`` or ``unknown`` (see
:mod:`app.link.outcome`) -- and the reader merges it into the write too. A judged write answered
but without its result line reads ``unknown``.

The record format and the reader (:func:`read_records`, :func:`query`, :func:`export_csv`,
:class:`AuditFilter`, :class:`ReadStats`) live in :mod:`app.safety.audit_read`.
"""

from __future__ import annotations

import contextlib
import datetime as dt
import enum
import os
import sys
import threading
import time
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import Any

from app.errors import (
    LinkError,
    MalformedResponse,
    ModbusExceptionError,
    ResponseTimeout,
    TeachPadError,
    WriteBlocked,
)
from app.protocol import registers
from app.protocol.codec import WordOrder
from app.protocol.exceptions import not_carried_out
from app.safety.audit_chain import last_line_hash, line_hash
from app.safety.audit_read import (
    OUTCOME,
    RESULT,
    AuditRecord,
    Result,
    audit_file_name,
    audit_file_parts,
)
from app.safety.location import safety_location, user_data_dir

__all__ = [  # the reader's names stay importable from here (app.safety.audit_read)
    "FSYNC_INTERVAL",
    "KEEP_DAYS",
    "MAX_DETAIL_CHARS",
    "MAX_FILE_BYTES",
    "MAX_TOTAL_BYTES",
    "MAX_VALUES_KEPT",
    "AuditLog",
    "AuditUnavailable",
    "FsyncPolicy",
    "brings_to_rest",
    "default_audit_dir",
    "default_data_dir",
]

MAX_FILE_BYTES = 8 * 1024 * 1024
MAX_TOTAL_BYTES = 256 * 1024 * 1024
KEEP_DAYS = 90
FSYNC_INTERVAL = 1.0  # s
MAX_VALUES_KEPT = 64  # register values stored per write record
MAX_DETAIL_CHARS = 300


class FsyncPolicy(enum.Enum):
    ALWAYS = "always"  # every line: survives power loss, costs a disk flush per write
    INTERVAL = "interval"  # at most once per FSYNC_INTERVAL
    NEVER = "never"  # the OS decides (a killed process still loses nothing written)


def default_data_dir() -> Path:
    """Per-user data directory of TeachPad."""
    return user_data_dir()


def default_audit_dir() -> Path:
    """The audit trail's folder: machine-wide when an administrator made one, else the user's
    (:mod:`app.safety.location`; never beside a settings file)."""
    return safety_location().audit_dir


class AuditUnavailable(WriteBlocked):
    """A write refused before the wire because its audit record could not be written first."""

    code = "audit_unavailable"


_REST_WRITES = (
    (registers.REG_STOP, (1,)),
    (registers.REG_PAUSE, (1,)),
    (registers.gv_reg(registers.GV_PARAM3), (0, 0)),  # the jog ratio 0 (float 0.0: both words 0)
)


def brings_to_rest(address: int, values: Sequence[int]) -> bool:
    """A write that only stops the arm (Stop, Pause, the jog ratio 0): it goes out also when its
    audit record cannot be written (the failure is reported, see ``AuditLog.on_error``)."""
    vals = tuple(int(v) for v in values)
    return any(address == a and vals == v for a, v in _REST_WRITES)


def _write_result(error: BaseException | None, judged: bool = False) -> tuple[str, str]:
    if error is None:
        return Result.OK, ""
    if isinstance(error, WriteBlocked):
        return Result.BLOCKED, str(error)
    if judged and _went_out_unconfirmed(error):
        return Result.UNKNOWN, str(error)
    return Result.FAILED, str(error) or type(error).__name__


def _error_reason(error: BaseException | None) -> dict[str, Any]:
    """A write's error as its reason code and plain arguments beside the English detail (the
    viewer words it in the operator's language; ui/audit_words.py); {} for an untyped error."""
    if not isinstance(error, TeachPadError) or error.code == "error":
        return {}
    plain = {k: v for k, v in error.params.items() if v is None or isinstance(v, str | int | float | bool)}
    return {"reason": error.code, "reason_args": plain}


def _went_out_unconfirmed(error: BaseException) -> bool:
    """A command's write went out and what it did is not known: answered with an exception that
    does not say it was not carried out (device failure, acknowledge, an undefined code; see
    app/link/command_client.py send_trigger), no answer in time, a malformed answer, or the link
    lost during the request (``link_lost``; ``link_closed`` is seen before the request goes out)."""
    if isinstance(error, ModbusExceptionError):
        return not not_carried_out(error.exception_code)
    if isinstance(error, ResponseTimeout | MalformedResponse):
        return True
    return isinstance(error, LinkError) and error.code == "link_lost"


def _short(text: str, limit: int = MAX_DETAIL_CHARS) -> str:
    return text if len(text) <= limit else text[: limit - 1] + "…"


class AuditLog:
    """Appends records; thread-safe (the worker records writes, the GUI refusals)."""

    def __init__(
        self,
        directory: Path | None = None,
        *,
        role: Callable[[], str] | str = "operator",
        fsync: FsyncPolicy = FsyncPolicy.INTERVAL,
        max_file_bytes: int = MAX_FILE_BYTES,
        max_total_bytes: int = MAX_TOTAL_BYTES,
        keep_days: int = KEEP_DAYS,
        word_order: WordOrder = WordOrder.LOW_FIRST,
        now: Callable[[], dt.datetime] | None = None,
        on_error: Callable[[str], None] | None = None,
    ) -> None:
        self.directory = directory or default_audit_dir()
        self._role = role
        self.fsync = fsync
        self.max_file_bytes = max_file_bytes
        self.max_total_bytes = max_total_bytes
        self.keep_days = keep_days
        self.word_order = word_order
        self._now = now or (lambda: dt.datetime.now().astimezone())
        self._lock = threading.Lock()
        self._fd: int | None = None
        self._path: Path | None = None
        self._size = 0
        self._day = ""
        self._last_sync = 0.0
        self._unsynced = False
        self._clock: tuple[dt.datetime, float] | None = None
        self._prev: str | None = None  # the hash of the last record written (the chain)
        self.session = os.urandom(6).hex()  # 12 hex digits (not uuid4: its import costs 7 ms at start-up)
        self._seq = 0
        # A full disk must not stop a write (least of all a stop): records that cannot be
        # written are counted, and on_error hears of each new problem once.
        self.on_error = on_error
        self.last_error: str | None = None
        self.last_cause = ""  # the OS's words of the last failure ("No space left on device")
        self.dropped = 0

    # --- context ---------------------------------------------------------------------------
    @property
    def role(self) -> str:
        return self._role() if callable(self._role) else self._role

    def set_role(self, role: Callable[[], str] | str) -> None:
        self._role = role

    def note_controller_clock(self, clock: dt.datetime | None, at: float | None = None) -> None:
        """The controller's clock as just read (``at``: ``time.monotonic()`` of the read)."""
        with self._lock:
            self._clock = None if clock is None else (clock, time.monotonic() if at is None else at)

    def _controller_time(self) -> str | None:
        if self._clock is None:
            return None
        clock, at = self._clock
        return (clock + dt.timedelta(seconds=time.monotonic() - at)).isoformat(timespec="seconds")

    # --- recording --------------------------------------------------------------------------
    def record(
        self,
        kind: str,
        command: str,
        *,
        result: str = Result.OK,
        args: dict[str, Any] | None = None,
        detail: str = "",
        role: str | None = None,
    ) -> AuditRecord:
        with self._lock:
            now = self._now()
            rec = AuditRecord(
                now.isoformat(timespec="milliseconds"),
                kind,
                command,
                role or self.role,
                result,
                dict(args or {}),
                _short(detail),
                self._controller_time(),
                self.session,
                self._seq,
            )
            self._seq += 1
            try:
                self._append(rec, now)
            except OSError as exc:
                self._failed(exc)
            else:
                self.last_error = None
            return rec

    def _failed(self, exc: OSError) -> None:
        self.dropped += 1
        self._close_fd()
        self.last_cause = exc.strerror or str(exc)
        message = f"the audit trail cannot be written in {self.directory} ({self.last_cause})"
        if message != self.last_error:
            self.last_error = message
            if self.on_error is not None:
                self.on_error(message)

    def record_write(
        self,
        address: int,
        values: Sequence[int],
        *,
        single: bool = False,
        error: BaseException | None = None,
        pending: bool = False,
        judged: bool = False,
    ) -> AuditRecord:
        """One write to the controller and how it ended (``error`` None: it succeeded; ``pending``:
        not known yet, an outcome line follows -- see :meth:`writing`; ``judged``: a command's
        write, whose outcome the controller tells later, see :meth:`record_result`)."""
        vals = [int(v) for v in values]
        try:
            # the register tables: imported by the first write, not with the window (start-up)
            from app.protocol.naming import describe_registers
            from app.protocol.summaries import single_write_text, write_summary

            if single and len(vals) == 1:
                command = single_write_text(address, vals[0])
            else:
                command = write_summary(address, describe_registers(address, vals, self.word_order))
        except Exception:  # naming is a courtesy; never lose the record over it
            command = f"write {len(vals)} register(s) at {address}"
        result, detail = (Result.PENDING, "") if pending else _write_result(error)
        args: dict[str, Any] = {
            "fc": 6 if single else 16,
            "address": address,
            "values": vals[:MAX_VALUES_KEPT],
        }
        if not pending:
            args.update(_error_reason(error))
        if len(vals) > MAX_VALUES_KEPT:
            args["count"] = len(vals)
        if judged:
            args["judged"] = True
        return self.record("write", command, result=result, args=args, detail=detail)

    @contextlib.contextmanager
    def writing(
        self, address: int, values: Sequence[int], *, single: bool = False, judged: bool = False
    ) -> Iterator[AuditRecord]:
        """Wrap one write, write-ahead: its line (``pending``) before the request goes out, its
        outcome line after; the reader merges them. Errors pass through unchanged. Yields the
        write's record (``judged``: the command's outcome is recorded against it later).

        No write without its record: when the write's line cannot be written (a full disk, the
        folder gone) this raises :class:`AuditUnavailable` and the write is not sent -- except a
        write that only brings the arm to rest (:func:`brings_to_rest`: Stop, Pause, jog ratio
        0), which must go out whatever the disk says."""
        dropped = self.dropped
        intent = self.record_write(address, values, single=single, pending=True, judged=judged)
        if self.dropped != dropped and not brings_to_rest(address, values):
            raise AuditUnavailable(
                f"not sent: {intent.command} could not be recorded first ({self.last_error}); "
                "no write goes out without its audit record (Stop still does)",
                params={"folder": str(self.directory), "cause": self.last_cause},
            )
        try:
            yield intent
        except Exception as exc:
            self._record_outcome(intent, exc)
            raise
        self._record_outcome(intent, None)

    def _record_outcome(self, intent: AuditRecord, error: BaseException | None) -> None:
        result, detail = _write_result(error, intent.args.get("judged") is True)
        args = {"ref": intent.seq, **_error_reason(error)}
        self.record(OUTCOME, intent.command, result=result, args=args, detail=detail, role=intent.role)

    def record_result(
        self, write: AuditRecord, result: str, detail: str, args: dict[str, Any] | None = None
    ) -> AuditRecord:
        """What the controller made of the command ``write`` sent (``done``, ``refused``,
        ``stopped``, ``unknown``; ``detail``: in words); the reader merges it into the write."""
        return self.record(
            RESULT,
            write.command,
            result=result,
            args={"ref": write.seq, **(args or {})},
            detail=detail,
            role=write.role,
        )

    def record_refused(self, action: str, reason: str, args: dict[str, Any] | None = None) -> AuditRecord:
        """An action the host refused (envelope, role, bad value): nothing was sent."""
        return self.record("refused", action, result=Result.REFUSED, args=args, detail=reason)

    def close(self) -> None:
        with self._lock:
            self._close_fd()

    def __enter__(self) -> AuditLog:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # --- files ------------------------------------------------------------------------------
    def _close_fd(self) -> None:
        if self._fd is not None:
            with contextlib.suppress(OSError):
                if self._unsynced and self.fsync is not FsyncPolicy.NEVER:
                    os.fsync(self._fd)
                os.close(self._fd)
            self._fd = None
            self._unsynced = False

    def _append(self, rec: AuditRecord, now: dt.datetime) -> None:
        """Append ``rec``'s line chained to the record before it: the line ends with ``prev`` (the
        record object stays without it; one JSON encoding per record, spliced: this is the hot path)."""
        # a clock stepped back keeps writing to the day's file it was at (never back to an older one)
        day = max(now.date().isoformat(), self._day)
        body = rec.to_line()  # ends with b"}\n"; AuditRecord.to_line puts "prev" last, the same way
        need = len(body) + _PREV_CHARS
        if self._fd is None or day != self._day or self._size + need > self.max_file_bytes:
            self._open_for(day, need)
        assert self._fd is not None and self._path is not None
        with _locked(self._fd):  # another TeachPad (the GUI and the CLI) may append to the same file
            size = os.fstat(self._fd).st_size
            if size != self._size:  # it did: chain to its last record
                self._prev = last_line_hash(self._path) or self._prev
                self._size = size
            line = b'%s,"prev":"%s"}\n' % (body[:-2], (self._prev or "").encode("ascii"))
            view = memoryview(line)
            while view:
                view = view[os.write(self._fd, view) :]
        self._prev = line_hash(line)
        self._size += len(line)
        self._sync()

    def _sync(self) -> None:
        assert self._fd is not None
        if self.fsync is FsyncPolicy.ALWAYS:
            os.fsync(self._fd)
            return
        self._unsynced = True
        if self.fsync is FsyncPolicy.INTERVAL and time.monotonic() - self._last_sync >= FSYNC_INTERVAL:
            os.fsync(self._fd)
            self._last_sync = time.monotonic()
            self._unsynced = False

    def _open_for(self, day: str, need: int) -> None:
        self._close_fd()
        self.directory.mkdir(parents=True, exist_ok=True)
        on_disk = sorted((d, part, p) for p, d, part in audit_file_parts(self.directory))
        if on_disk and on_disk[-1][0] > day:  # a clock set back since: keep to the newest day's file
            day = on_disk[-1][0]
        parts = sorted((part, p) for p, d, part in audit_file_parts(self.directory) if d == day)
        part = parts[-1][0] if parts else 0
        while True:
            path = self.directory / audit_file_name(day, part)
            size = path.stat().st_size if path.exists() else 0
            if size == 0 or size + need <= self.max_file_bytes:
                break
            part += 1
        fd = os.open(path, os.O_WRONLY | os.O_APPEND | os.O_CREAT | getattr(os, "O_BINARY", 0), 0o600)
        if size and not _ends_with_newline(path):
            os.write(fd, b"\n")  # close a line cut short by a crash; the reader skips it
            size += 1
        # the chain: from this file's last record, else from the newest file before it
        before = [p for _, _, p in on_disk if p != path]
        self._prev = last_line_hash(path) if size else (last_line_hash(before[-1]) if before else None)
        self._fd, self._path, self._size, self._day = fd, path, size, day
        self._prune(keep=path)

    def _prune(self, keep: Path) -> None:
        """Delete the files of all but the newest ``keep_days`` days on disk, then the oldest until
        the total fits ``max_total_bytes``; never by the clock (see the module docstring)."""
        files = sorted(
            ((d, part, p) for p, d, part in audit_file_parts(self.directory)), key=lambda t: (t[0], t[1])
        )
        days = sorted({d for d, _, _ in files})
        kept_days = set(days[-self.keep_days :]) if self.keep_days > 0 else set(days)
        remaining: list[tuple[Path, int]] = []
        for d, _, p in files:
            if p == keep:
                continue
            if d not in kept_days:
                with contextlib.suppress(OSError):
                    p.unlink()
                continue
            with contextlib.suppress(OSError):
                remaining.append((p, p.stat().st_size))
        total = sum(s for _, s in remaining) + self.max_file_bytes  # room for the new file to fill
        for p, s in remaining:  # oldest first
            if total <= self.max_total_bytes:
                break
            with contextlib.suppress(OSError):
                p.unlink()
                total -= s


_PREV_CHARS = len(',"prev":""') + 64  # what the chain adds to a line


@contextlib.contextmanager
def _locked(fd: int) -> Iterator[None]:
    """An exclusive lock on the open file while one record is appended: ``flock`` on POSIX; on
    Windows (no fcntl) a lock of the file's first byte with ``msvcrt.locking``, the same byte for
    every writer whatever the file's length (the file is opened O_APPEND: each write goes to
    the end wherever the position is). ``LK_LOCK`` retries for 10 s, then raises OSError: the
    record is then not written, like any other failed append."""
    if sys.platform == "win32":
        import msvcrt

        os.lseek(fd, 0, os.SEEK_SET)
        msvcrt.locking(fd, msvcrt.LK_LOCK, 1)
        try:
            yield
        finally:
            os.lseek(fd, 0, os.SEEK_SET)
            msvcrt.locking(fd, msvcrt.LK_UNLCK, 1)
        return
    import fcntl

    fcntl.flock(fd, fcntl.LOCK_EX)
    try:
        yield
    finally:
        fcntl.flock(fd, fcntl.LOCK_UN)


def _ends_with_newline(path: Path) -> bool:
    with open(path, "rb") as f:
        f.seek(-1, os.SEEK_END)
        return f.read(1) == b"\n"
