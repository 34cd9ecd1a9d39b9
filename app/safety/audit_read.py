"""The audit trail's file format and its reader (the writer is :mod:`app.safety.audit`).

A file is ``audit-YYYY-MM-DD.jsonl`` (part 0) or ``audit-YYYY-MM-DD.N.jsonl``, one JSON object
per line (:class:`AuditRecord`). A write is two lines: the write itself with result ``pending``
(before the request goes out) and an ``outcome`` line (``args.ref`` = the write's ``seq``) once
it is answered. A command's write (``args.judged``) has a third, ``result``: what the controller
made of the command (done / refused / stopped / unknown, see :mod:`app.link.outcome`).
:func:`read_records` merges them into one record, so every write the controller may have
received is read exactly once; a write whose outcome line never came (the process died) reads
as ``unknown``, and so does a judged write answered but without its result line. Lines that do
not parse (a line cut short by a power cut, damage) are skipped and counted in
:class:`ReadStats`. :func:`query` filters (:class:`AuditFilter`), :func:`export_csv` writes what
the viewer shows.
"""

from __future__ import annotations

import contextlib
import csv
import datetime as dt
import json
import os
import re
from collections import deque
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, TextIO

from app.safety.roles import PLANT_ROLE

__all__ = [
    "CSV_COLUMNS",
    "FILE_RE",
    "MAX_OUTCOME_LAG",
    "OUTCOME",
    "RESULT",
    "UNKNOWN_DETAIL",
    "UNKNOWN_OUTCOME_DETAIL",
    "AuditFilter",
    "AuditRecord",
    "ReadStats",
    "Result",
    "audit_file_name",
    "audit_file_parts",
    "audit_files",
    "export_csv",
    "query",
    "read_records",
    "result_label",
]

FILE_RE = re.compile(r"audit-(\d{4}-\d{2}-\d{2})(?:\.(\d+))?\.jsonl")


class Result:
    OK = "ok"  # sent and answered (a write that is not a command: nothing more to tell)
    FAILED = "failed"  # sent, and the controller or the link failed the write
    BLOCKED = "blocked"  # not sent: monitor-only
    # kind "refused": not sent, the host refused (envelope, role, bad value, controller busy);
    # kind "write": the controller refused the command (args.status: its GV291 code, if any)
    REFUSED = "refused"
    PENDING = "pending"  # in the file only: sent, its outcome line follows (merged by the reader)
    UNKNOWN = "unknown"  # sent, and what the controller did is not known
    DONE = "done"  # a command the controller reported (or was seen) done
    STOPPED = "stopped"  # a command a stop ended


OUTCOME = "outcome"  # the kind of a write's second line (merged into the write by the reader)
RESULT = "result"  # the kind of a command write's third line: the controller's outcome (merged)
UNKNOWN_DETAIL = "sent; TeachPad stopped before the answer was recorded"
UNKNOWN_OUTCOME_DETAIL = (
    "sent and answered; the controller's outcome was not recorded (still under way when read, "
    "or TeachPad stopped first)"
)
MAX_OUTCOME_LAG = 4096  # records read after a pending write before the reader stops waiting


@dataclass(frozen=True)
class AuditRecord:
    host_time: str  # ISO 8601, local time with offset, milliseconds
    kind: str  # "write", "refused", "login", "action"
    command: str  # what, in words: "teach enable (440 ← 0x80)", "jog", ...
    role: str
    result: str  # Result.*
    args: dict[str, Any] = field(default_factory=dict)
    detail: str = ""  # the error or the reason, plain English
    controller_time: str | None = None  # the controller's clock, estimated from its last read
    session: str = ""  # one id per AuditLog: with seq, identifies a record
    seq: int = 0
    prev: str | None = None  # the hash of the record before it (app.safety.audit_chain); None: older

    @property
    def time(self) -> dt.datetime:
        return dt.datetime.fromisoformat(self.host_time)

    def to_line(self) -> bytes:
        doc = {
            "host_time": self.host_time,
            "kind": self.kind,
            "command": self.command,
            "role": self.role,
            "result": self.result,
            "args": self.args,
            "detail": self.detail,
            "controller_time": self.controller_time,
            "session": self.session,
            "seq": self.seq,
        }
        if self.prev is not None:
            doc["prev"] = self.prev
        return (json.dumps(doc, ensure_ascii=False, separators=(",", ":")) + "\n").encode("utf-8")

    @classmethod
    def from_json(cls, data: object) -> AuditRecord:
        if not isinstance(data, dict):
            raise ValueError("not an object")
        known = {k: data[k] for k in cls.__dataclass_fields__ if k in data}
        rec = cls(**known)
        dt.datetime.fromisoformat(rec.host_time)  # must parse
        return rec


def audit_file_name(day: str, part: int) -> str:
    return f"audit-{day}.jsonl" if part == 0 else f"audit-{day}.{part}.jsonl"


def audit_file_parts(directory: Path) -> list[tuple[Path, str, int]]:
    """(path, day, part) of every audit file in ``directory``."""
    found = []
    with contextlib.suppress(OSError):
        for entry in os.scandir(directory):
            m = FILE_RE.fullmatch(entry.name)
            if m and entry.is_file():
                found.append((Path(entry.path), m.group(1), int(m.group(2) or 0)))
    return found


@dataclass
class ReadStats:
    files: int = 0
    records: int = 0
    skipped: int = 0  # lines that did not parse (a line cut short by a crash, damage)
    unknown: int = 0  # writes sent whose outcome was never recorded (TeachPad stopped)


def audit_files(directory: Path, start: dt.date | None = None, end: dt.date | None = None) -> list[Path]:
    """The audit files of days ``start``..``end`` (inclusive), in time order."""
    out = []
    for p, d, part in audit_file_parts(directory):
        day = dt.date.fromisoformat(d)
        if (start is None or day >= start) and (end is None or day <= end):
            out.append((d, part, p))
    return [p for _, _, p in sorted(out)]


def result_label(record: AuditRecord) -> str:
    """The result as the CLI prints it: ``refused:13`` for a command the controller refused with
    GV291 code 13, else the result word."""
    status = record.args.get("status")
    if record.result == Result.REFUSED and record.kind == "write" and isinstance(status, int):
        return f"{record.result}:{status}"
    return record.result


class _Slot:
    """A record waiting in file order; a pending write waits for its outcome line, a judged one
    (a command) also for its result line."""

    __slots__ = ("judged", "pending", "record")

    def __init__(self, record: AuditRecord) -> None:
        self.record, self.pending = record, record.result == Result.PENDING
        self.judged = self.pending and record.args.get("judged") is True

    def take(self, line: AuditRecord) -> None:
        """Merge an ``outcome`` or ``result`` line into the write."""
        extra = {k: v for k, v in line.args.items() if k != "ref"}
        self.record = replace(
            self.record, result=line.result, detail=line.detail, args={**self.record.args, **extra}
        )
        # an answered command still waits for the controller's outcome; anything else is final
        self.pending = line.kind == OUTCOME and self.judged and line.result == Result.OK


def read_records(
    directory: Path, start: dt.date | None = None, end: dt.date | None = None, stats: ReadStats | None = None
) -> Iterator[AuditRecord]:
    """Every record of days ``start``..``end``, in file order; lines that do not parse are skipped
    and counted. A write's outcome line is merged into the write (see the module docstring); a
    write without one within :data:`MAX_OUTCOME_LAG` records (the process died) ends ``unknown``,
    so at most that many records are held back."""
    stats = stats if stats is not None else ReadStats()
    held: deque[_Slot] = deque()
    waiting: dict[tuple[str, int], _Slot] = {}
    early: _Early = {}
    for rec in _parsed_lines(directory, start, end, stats):
        _hold(rec, held, waiting, early)
        if len(held) > MAX_OUTCOME_LAG:  # the oldest waits in vain: its process died
            _give_up(held[0], stats)
            waiting.pop((held[0].record.session, held[0].record.seq), None)
        while held and not held[0].pending:
            stats.records += 1
            yield held.popleft().record
    for slot in held:
        if slot.pending:
            _give_up(slot, stats)
        stats.records += 1
        yield slot.record


def _parsed_lines(
    directory: Path, start: dt.date | None, end: dt.date | None, stats: ReadStats
) -> Iterator[AuditRecord]:
    """Every line of the day files that parses, in file order (files counted; a file that cannot
    be read is passed over, a line that does not parse is counted as skipped)."""
    for path in audit_files(directory, start, end):
        stats.files += 1
        try:
            data = path.read_bytes()
        except OSError:
            continue
        for raw in data.split(b"\n"):
            if not raw.strip():
                continue
            rec = _parse_line(raw)
            if rec is None:
                stats.skipped += 1
            else:
                yield rec


def _parse_line(raw: bytes) -> AuditRecord | None:
    try:
        return AuditRecord.from_json(json.loads(raw.decode("utf-8")))
    except (ValueError, TypeError, UnicodeDecodeError):
        return None


def _hold(rec: AuditRecord, held: deque[_Slot], waiting: dict[tuple[str, int], _Slot], early: _Early) -> None:
    """Take one record in: an outcome or result line is merged into its write; any other record
    is held in file order (a write until its outcome arrives)."""
    if rec.kind in (OUTCOME, RESULT):
        _pair(rec, waiting, early)
        return
    # (an outcome whose write is outside the range read shows nothing)
    slot = _Slot(rec)
    held.append(slot)
    if slot.pending:
        waiting[(rec.session, rec.seq)] = slot
        for line in early.pop((rec.session, rec.seq), []):  # read before it (a clock set back)
            _pair(line, waiting, early)


_Early = dict[tuple[str, int], list[AuditRecord]]


def _pair(line: AuditRecord, waiting: dict[tuple[str, int], _Slot], early: _Early) -> None:
    """Merge an outcome or result line into its write, paired by ``(session, seq)``, never by time:
    a line read before its write (files written by a clock stepped back across midnight) waits in
    ``early`` (at most :data:`MAX_OUTCOME_LAG` of them) for the write."""
    ref = line.args.get("ref")
    if not isinstance(ref, int):
        return
    slot = waiting.pop((line.session, ref), None)
    if slot is None:
        if len(early) < MAX_OUTCOME_LAG:
            early.setdefault((line.session, ref), []).append(line)
        return
    slot.take(line)
    if slot.pending:  # (ref is the slot's seq)
        waiting[(line.session, slot.record.seq)] = slot
    for later in early.pop((line.session, ref), []):
        _pair(later, waiting, early)


def _give_up(slot: _Slot, stats: ReadStats) -> None:
    answered = slot.record.result == Result.OK  # a command answered, its outcome not recorded
    slot.pending = False
    slot.record = replace(
        slot.record, result=Result.UNKNOWN, detail=UNKNOWN_OUTCOME_DETAIL if answered else UNKNOWN_DETAIL
    )
    stats.unknown += 1


@dataclass(frozen=True)
class AuditFilter:
    """What the viewer shows: a time range (host time), role, command text, result, kind."""

    start: dt.datetime | None = None
    end: dt.datetime | None = None
    role: str | None = None
    command: str | None = None  # case-insensitive substring
    result: str | None = None
    kind: str | None = None

    def matches(self, rec: AuditRecord) -> bool:
        if self.role is not None and not role_matches(self.role, rec.role):
            return False
        if self.result is not None and rec.result != self.result:
            return False
        if self.kind is not None and rec.kind != self.kind:
            return False
        if self.command and self.command.lower() not in rec.command.lower():
            return False
        if self.start is not None or self.end is not None:
            t = rec.time
            if self.start is not None and _cmp_time(t, self.start) < 0:
                return False
            if self.end is not None and _cmp_time(t, self.end) > 0:
                return False
        return True

    def days(self) -> tuple[dt.date | None, dt.date | None]:
        # a day's file may hold records of the day before near midnight across zones: widen by one
        one = dt.timedelta(days=1)
        return (
            None if self.start is None else self.start.date() - one,
            None if self.end is None else self.end.date() + one,
        )


def role_matches(wanted: str, role: str) -> bool:
    """A record's ``role`` is the one ``wanted``; the plant (:data:`~app.safety.roles.PLANT_ROLE`)
    is each of its robots' ``plant (R1)`` (app/gateway/plant.py)."""
    return role == wanted or (wanted == PLANT_ROLE and role.startswith(f"{PLANT_ROLE} ("))


def _cmp_time(a: dt.datetime, b: dt.datetime) -> int:
    if (a.tzinfo is None) != (b.tzinfo is None):
        a, b = a.replace(tzinfo=None), b.replace(tzinfo=None)
    return (a > b) - (a < b)


def query(
    directory: Path, flt: AuditFilter | None = None, stats: ReadStats | None = None
) -> list[AuditRecord]:
    flt = flt or AuditFilter()
    start, end = flt.days()
    return [r for r in read_records(directory, start, end, stats) if flt.matches(r)]


CSV_COLUMNS = ("host_time", "controller_time", "role", "kind", "command", "result", "detail", "args")


def export_csv(records: Iterable[AuditRecord], out: TextIO) -> int:
    """Write records as CSV (args as JSON); returns how many."""
    writer = csv.writer(out)
    writer.writerow(CSV_COLUMNS)
    n = 0
    for r in records:
        writer.writerow(
            (
                r.host_time,
                r.controller_time or "",
                r.role,
                r.kind,
                r.command,
                r.result,
                r.detail,
                json.dumps(r.args, ensure_ascii=False),
            )
        )
        n += 1
    return n
