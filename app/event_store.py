"""The event log on disk: kept across restarts, bounded, in TeachPad's data folder. Qt-free.

The GUI's event log (``ui/panels/event_log.py``) appends each event it shows here as one JSON
line and, at start, shows the events of the last :data:`KEEP_DAYS` days again: the support
bundle carries "the event log of the last days", not only this session's.

Files: ``<data folder>/events/events.jsonl`` (appended) and ``events.1.jsonl`` (the previous
one). Each line is written whole with one ``write`` on a file opened for appending, so a crash
leaves at worst a torn last line, which the reader skips; when the current file passes
``max_bytes`` it becomes ``events.1.jsonl`` (``os.replace``, atomic) and a new one begins, so the
two never hold more than ``2 * max_bytes``. A line::

    {"when": "2026-11-29T07:01:02.345", "level": "error", "source": "link", "text": "..."}

The text is stored as it was shown (in the language of that session). A disk that cannot be
written never stops the GUI: :meth:`EventStore.append` reports the first failure through
``on_error`` (the folder and the system's reason) and the events stay in memory only.
"""

from __future__ import annotations

import datetime as dt
import json
import os
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Final

from app.safety.audit import default_data_dir

__all__ = ["KEEP_DAYS", "MAX_BYTES", "EventStore", "StoredEvent", "default_events_dir", "export_line"]

KEEP_DAYS: Final = 7  # days of events shown again at start (and so in the support bundle)
MAX_BYTES: Final = 2 * 1024 * 1024  # one file; with the previous one at most twice this on disk
CURRENT: Final = "events.jsonl"
PREVIOUS: Final = "events.1.jsonl"
LEVELS: Final = ("info", "warning", "error")


def default_events_dir() -> Path:
    """``events`` in TeachPad's per-user data folder (beside the audit trail)."""
    return default_data_dir() / "events"


@dataclass(frozen=True, slots=True)
class StoredEvent:
    when: dt.datetime
    level: str
    source: str
    text: str


def export_line(event: StoredEvent) -> str:
    """The event as the log's export and the support bundle write it: time, LEVEL, source and
    text, tab-separated, on one line."""
    return "\t".join(
        (
            event.when.isoformat(sep=" ", timespec="milliseconds"),
            event.level.upper(),
            event.source,
            " ".join(event.text.split()),
        )
    )


class EventStore:
    """Append events to ``directory``; read back the recent ones."""

    def __init__(
        self,
        directory: Path | None = None,
        *,
        max_bytes: int = MAX_BYTES,
        keep_days: int = KEEP_DAYS,
        on_error: Callable[[str], None] | None = None,
    ) -> None:
        if max_bytes < 1024:
            raise ValueError("max_bytes must be at least 1024")
        self.directory = directory or default_events_dir()
        self.max_bytes = max_bytes
        self.keep_days = keep_days
        self._on_error = on_error
        self._failed = False

    @property
    def path(self) -> Path:
        return self.directory / CURRENT

    def append(self, event: StoredEvent) -> bool:
        """Append one event (rotating first when the file is full); False when it could not be
        written (said once through ``on_error``)."""
        line = json.dumps(
            {
                "when": event.when.isoformat(timespec="milliseconds"),
                "level": event.level,
                "source": event.source,
                "text": event.text,
            },
            ensure_ascii=False,
        )
        data = (line.replace("\n", " ") + "\n").encode("utf-8")
        try:
            self.directory.mkdir(parents=True, exist_ok=True)
            self._rotate_if_full(len(data))
            fd = os.open(self.path, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o600)
            try:
                os.write(fd, data)
            finally:
                os.close(fd)
        except OSError as exc:
            said, self._failed = self._failed, True  # before on_error, which may log (and append)
            if not said and self._on_error is not None:
                self._on_error(f"{self.directory}: {exc.strerror or exc}")
            return False
        self._failed = False
        return True

    def _rotate_if_full(self, adding: int) -> None:
        try:
            size = self.path.stat().st_size
        except FileNotFoundError:
            return
        if size and size + adding > self.max_bytes:
            os.replace(self.path, self.directory / PREVIOUS)

    def recent(self, now: dt.datetime | None = None, limit: int | None = None) -> list[StoredEvent]:
        """The events of the last ``keep_days`` days, oldest first (the last ``limit`` of them);
        damaged lines are skipped."""
        now = now or dt.datetime.now()
        since = now - dt.timedelta(days=self.keep_days)
        events = [e for e in self._read_all() if e.when >= since]
        return events[-limit:] if limit is not None and limit >= 0 else events

    def _read_all(self) -> Iterator[StoredEvent]:
        for name in (PREVIOUS, CURRENT):
            try:
                with open(self.directory / name, encoding="utf-8", errors="replace") as handle:
                    lines = handle.read().splitlines()
            except OSError:
                continue
            for line in lines:
                event = _parse(line)
                if event is not None:
                    yield event


def _parse(line: str) -> StoredEvent | None:
    """One stored event, or None for a damaged line (a torn last line after a crash)."""
    try:
        doc = json.loads(line)
        when = dt.datetime.fromisoformat(doc["when"])
        level, source, text = doc["level"], doc["source"], doc["text"]
    except (ValueError, KeyError, TypeError):
        return None
    if when.tzinfo is not None:
        when = when.astimezone().replace(tzinfo=None)
    ok = level in LEVELS and isinstance(source, str) and isinstance(text, str)
    return StoredEvent(when, level, source, text) if ok else None
