"""The watch list's values over time: what the plot draws and the CSV export writes. Qt-free.

Each entry keeps its last :data:`HISTORY_SAMPLES` readings (wall-clock time, value); entries are
read at different rates (app/watchlist/plan.py), so each has its own times. The CSV has one row
per reading, oldest first (``time,key,name,type,value,raw``), UTF-8 with a BOM (spreadsheets
read Chinese names), written atomically by the project's one atomic writer
(:func:`app.points.atomic.atomic_write_bytes`).
"""

from __future__ import annotations

import csv
import datetime as dt
import io
import os
import time
from collections import deque
from collections.abc import Iterable, Sequence

from app.points.atomic import atomic_write_bytes
from app.watchlist.entry import WatchEntry, WatchValue, format_value

__all__ = ["CSV_HEADER", "HISTORY_SAMPLES", "WatchHistory"]

HISTORY_SAMPLES = 3000  # readings kept per entry (a minute at 50 Hz)
CSV_HEADER = ("time", "key", "name", "type", "value", "raw")


class WatchHistory:
    """Readings per entry: ``(wall time s, value, raw)``; the last value and when it was read."""

    def __init__(self, capacity: int = HISTORY_SAMPLES) -> None:
        self.capacity = capacity
        self._samples: dict[WatchEntry, deque[tuple[float, float, tuple[int, ...]]]] = {}
        self.last: dict[WatchEntry, WatchValue] = {}

    def keep_only(self, entries: Iterable[WatchEntry]) -> None:
        """Forget the entries no longer watched."""
        wanted = set(entries)
        for entry in list(self._samples):
            if entry not in wanted:
                del self._samples[entry]
        for entry in list(self.last):
            if entry not in wanted:
                del self.last[entry]

    def add(
        self, values: Sequence[WatchValue], *, now_mono: float | None = None, now_wall: float | None = None
    ) -> None:
        """Readings of one poll (their monotonic times turned into wall-clock times)."""
        offset = (time.time() if now_wall is None else now_wall) - (
            time.monotonic() if now_mono is None else now_mono
        )
        for value in values:
            self.last[value.entry] = value
            if value.value is None:
                continue
            ring = self._samples.get(value.entry)
            if ring is None:
                ring = self._samples[value.entry] = deque(maxlen=self.capacity)
            ring.append((value.read_at + offset, float(value.value), value.raw))

    def series(self, entry: WatchEntry) -> list[tuple[float, float]]:
        """(wall time, value) of ``entry``, oldest first."""
        return [(t, v) for t, v, _ in self._samples.get(entry, ())]

    def count(self) -> int:
        return sum(len(ring) for ring in self._samples.values())

    def to_csv(self, entries: Sequence[WatchEntry]) -> str:
        rows: list[tuple[float, WatchEntry, float, tuple[int, ...]]] = []
        for entry in entries:
            rows.extend((t, entry, v, raw) for t, v, raw in self._samples.get(entry, ()))
        rows.sort(key=lambda row: row[0])
        out = io.StringIO()
        writer = csv.writer(out, lineterminator="\n")
        writer.writerow(CSV_HEADER)
        for t, entry, v, raw in rows:
            stamp = (
                dt.datetime.fromtimestamp(t, dt.UTC).isoformat(timespec="milliseconds").replace("+00:00", "Z")
            )
            shown = format_value(entry, int(v) if entry.type.count == 1 else v).replace(" ", "")
            writer.writerow(
                (stamp, entry.key, entry.name, entry.type.value, shown, " ".join(f"{r:04X}" for r in raw))
            )
        return out.getvalue()

    def export_csv(self, path: str | os.PathLike[str], entries: Sequence[WatchEntry]) -> int:
        """Write the CSV atomically; returns the rows written."""
        text = self.to_csv(entries)
        atomic_write_bytes(path, ("\ufeff" + text).encode("utf-8"))
        return text.count("\n") - 1
