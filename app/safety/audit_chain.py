"""Tamper evidence of the audit trail: each record carries ``prev``, the hash of the record before
it (the line before it in its file, and, for a file's first record, the last record of the file
before: the chain runs across rotation and across sessions), so a record rewritten or deleted
breaks the chain at the record after it. :func:`verify_chain` walks the files in order and says
where it breaks.

Records written before the chain existed have no ``prev``: they read as "no chain", not as broken.
The first record read may point at a file pruned long ago: the chain starts there. What the chain
cannot tell: the newest records cut off the end (nothing follows them), nor a whole rewrite of the
trail by someone who recomputes every hash (it is evidence against editing a record, not a
signature).
"""

from __future__ import annotations

import datetime as dt
import json
import os
from dataclasses import dataclass, field
from pathlib import Path

from app.safety.audit_read import audit_files

__all__ = ["ChainBreak", "ChainReport", "last_line_hash", "line_hash", "verify_chain"]

TAIL_BYTES = 64 * 1024  # what is read of a file's end to find its last record


def line_hash(line: bytes) -> str:
    """The hash a record's successor carries: SHA-256 of its line (without the newline), hex."""
    import hashlib  # (OpenSSL: loaded by the first record hashed, not with the window's modules)

    return hashlib.sha256(line.rstrip(b"\r\n")).hexdigest()


def _parses(raw: bytes) -> dict[str, object] | None:
    try:
        doc = json.loads(raw.decode("utf-8"))
    except (ValueError, UnicodeDecodeError):
        return None
    return doc if isinstance(doc, dict) else None


def last_line_hash(path: Path) -> str | None:
    """The hash of the last record (a complete line that parses) of ``path``; None: it has none."""
    try:
        with open(path, "rb") as f:
            size = f.seek(0, os.SEEK_END)
            f.seek(max(0, size - TAIL_BYTES))
            tail = f.read()
    except OSError:
        return None
    lines = tail.split(b"\n")[:-1]  # the part after the last newline is not a complete line
    if size > TAIL_BYTES and lines:
        lines = lines[1:]  # the first one may be cut by the seek
    for raw in reversed(lines):
        if raw.strip() and _parses(raw) is not None:
            return line_hash(raw)
    return None


@dataclass(frozen=True)
class ChainBreak:
    file: str  # the file's name
    line: int  # 1-based line of the first record after the break
    before: str  # "FILE line N" of the record read before it
    missing: str = ""  # "seq A..B of session S": records of its session removed ("": not told)

    @property
    def text(self) -> str:
        """What it means, in words (English; the viewer says it in the operator's language)."""
        if self.missing:
            return f"record(s) removed before it ({self.missing} are missing)"
        return (
            f"the chain breaks: the record before it ({self.before}) was changed, "
            "or records between them were removed"
        )

    def __str__(self) -> str:
        return f"{self.file} line {self.line}: {self.text}"


@dataclass
class ChainReport:
    records: int = 0
    chained: int = 0  # records carrying the hash of the one before
    unchained: int = 0  # records of an older TeachPad, without a hash ("no chain")
    breaks: list[ChainBreak] = field(default_factory=list)

    @property
    def intact(self) -> bool:
        return not self.breaks

    def summary(self) -> str:
        if self.records == 0:
            return "no records"
        if self.chained == 0:
            return f"{self.records} records, no chain (written before records carried hashes)"
        state = "intact" if self.intact else f"BROKEN in {len(self.breaks)} place(s)"
        older = f"; {self.unchained} older records without a chain" if self.unchained else ""
        return f"{self.records} records, the chain is {state}{older}"


@dataclass
class _Walk:
    report: ChainReport
    prev: str | None = None  # the hash of the last record read
    where: str = ""  # file:line of the last record read
    last_seq: dict[str, int] = field(default_factory=dict)

    def take(self, name: str, number: int, raw: bytes, doc: dict[str, object]) -> None:
        self.report.records += 1
        claimed = doc.get("prev")
        if not isinstance(claimed, str):
            self.report.unchained += 1
        else:
            self.report.chained += 1
            if self.prev is not None and claimed != self.prev:
                self.report.breaks.append(ChainBreak(name, number, self.where, self._missing(doc)))
        session, seq = doc.get("session"), doc.get("seq")
        if isinstance(session, str) and isinstance(seq, int):
            self.last_seq[session] = seq
        self.prev, self.where = line_hash(raw), f"{name} line {number}"

    def _missing(self, doc: dict[str, object]) -> str:
        session, seq = doc.get("session"), doc.get("seq")
        before = self.last_seq.get(session) if isinstance(session, str) else None
        if not isinstance(seq, int) or before is None or seq <= before + 1:
            return ""
        first, last = before + 1, seq - 1
        return f"{'seq ' + str(first) if first == last else f'seq {first}..{last}'} of session {session}"


def verify_chain(directory: Path, start: dt.date | None = None, end: dt.date | None = None) -> ChainReport:
    """Walk the audit files of days ``start``..``end`` (default: all) in order and report where the
    chain of hashes breaks (the first record read starts the chain)."""
    walk = _Walk(ChainReport())
    for path in audit_files(directory, start, end):
        try:
            data = path.read_bytes()
        except OSError:
            continue
        for number, raw in enumerate(data.split(b"\n"), start=1):
            if not raw.strip():
                continue
            doc = _parses(raw)
            if doc is not None:  # (a damaged line is skipped: the writer chained past it too)
                walk.take(path.name, number, raw, doc)
    return walk.report
