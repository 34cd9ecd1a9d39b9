"""Compact storage of the traffic inspector's frames (Qt-free): fixed rings allocated once, no
Python object per row and no buffer that is reallocated as the table rolls.

Measured (``python -m benchmarks.gui_memory --detail``, streaming at 100 Hz): a row kept as
Python objects (the row, its time, its frame as a bytes object, the list slot) cost ~390 bytes
with a 72-byte frame (20,000 rows: 7.7 MB), and freeing them 1,000 at a time as the table rolled
left CPython's small-object arenas fragmented (+1 MB in 3 minutes after the table was full).
Columns in growing ``array``/``bytearray`` buffers halved the bytes but were reallocated and
moved as they rolled: glibc's free heap grew 2.4 -> 6.3 MB in 3 minutes. Here every column is a
ring of ``capacity`` slots made by the first row, frames go back to back into one byte ring of
``capacity * FRAME_BYTES_PER_ROW`` bytes, and the oldest rows give way when either is full.

Rows have absolute indices (``base`` .. ``base + len - 1``) that never change while a row lives,
so a response can name its request even after older rows were dropped.
"""

from __future__ import annotations

from array import array
from typing import Final

__all__ = [
    "FIXED_BYTES_PER_ROW",
    "FRAME_BYTES_PER_ROW",
    "MAX_FRAME_BYTES",
    "NO_COMMAND",
    "NO_ROW",
    "TrafficStore",
]

# flag bits, one byte per row
RX: Final = 1
RTU: Final = 2
POLL: Final = 4
BAD: Final = 8

NO_ROW: Final = -1  # no request (a request row itself, or an answer that was not paired)
NO_COMMAND: Final = -1
MAX_FRAME_BYTES: Final = 260  # a Modbus TCP ADU at most; longer frames are cut to this
# Frame bytes per row slot. Polling averages 72.5 bytes a frame (status read 12 + 57, pose read
# 12 + 209), pose reads alone 110.5, so for polls the row count is the bound; frames bigger on
# average (long writes, the largest reads) give way to the byte ring first: fewer, longer rows.
FRAME_BYTES_PER_ROW: Final = 128
# time (8) + frame offset (8) + length (2) + request (8) + last command (2) + flags (1) + meaning (8)
FIXED_BYTES_PER_ROW: Final = 37


class TrafficStore:
    """At most ``capacity`` rows in arrival order; ``drop_oldest`` forgets from the front."""

    __slots__ = (
        "_base",
        "_capacity",
        "_cmds",
        "_count",
        "_data",
        "_data_size",
        "_end",
        "_flags",
        "_lens",
        "_meanings",
        "_offsets",
        "_reqs",
        "_times",
    )

    def __init__(self, capacity: int) -> None:
        if capacity < 1:
            raise ValueError("capacity must be >= 1")
        self._capacity = capacity
        self._data_size = max(capacity * FRAME_BYTES_PER_ROW, 2 * MAX_FRAME_BYTES)
        self._base = 0  # absolute index of the oldest row
        self._count = 0
        self._end = 0  # absolute byte position where the next frame goes (never decreases)
        self._times = array("d")  # the rings: allocated by the first row (see _allocate)
        self._offsets = array("q")  # absolute byte position of each frame
        self._lens = array("H")
        self._reqs = array("q")  # absolute index of the request a response answers, or NO_ROW
        self._cmds = array("h")  # the last run command (RunCommand value) at the frame, or NO_COMMAND
        self._flags = bytearray()
        self._data = bytearray()
        self._meanings: list[str | None] = []  # the decoded meaning once shown (shared strings)

    def _allocate(self) -> None:
        cap = self._capacity
        self._times = array("d", bytes(8 * cap))
        self._offsets = array("q", bytes(8 * cap))
        self._lens = array("H", bytes(2 * cap))
        self._reqs = array("q", bytes(8 * cap))
        self._cmds = array("h", bytes(2 * cap))
        self._flags = bytearray(cap)
        self._data = bytearray(self._data_size)
        self._meanings = [None] * cap

    def __len__(self) -> int:
        return self._count

    @property
    def base(self) -> int:
        return self._base

    @property
    def capacity(self) -> int:
        return self._capacity

    @property
    def frame_capacity(self) -> int:
        """Bytes of the frame ring."""
        return self._data_size

    def room_for(self, sizes: list[int]) -> int:
        """How many of the oldest rows must go before frames of these sizes are appended."""
        count, end, data = self._count, self._end, self._data_size
        for size in sizes:
            end = self._start_of(end, min(size, MAX_FRAME_BYTES)) + min(size, MAX_FRAME_BYTES)
        drop = max(0, count + len(sizes) - self._capacity)
        while drop < count and end - self._offsets[(self._base + drop) % self._capacity] > data:
            drop += 1
        return drop

    def _start_of(self, end: int, size: int) -> int:
        """Where a frame of ``size`` bytes starts: at ``end``, or at the ring's next turn if it
        would run past the ring's end (frames are never split)."""
        if end % self._data_size + size > self._data_size:
            return end + self._data_size - end % self._data_size
        return end

    def append(self, t: float, frame: bytes, flags: int, request: int, command: int) -> int:
        """Add a row (the caller made room: see :meth:`room_for`); returns its absolute index."""
        if not self._data:
            self._allocate()
        if self._count >= self._capacity:
            self.drop_oldest(1)
        frame = frame[:MAX_FRAME_BYTES]
        start = self._start_of(self._end, len(frame))
        while (
            self._count and start + len(frame) - self._offsets[self._base % self._capacity] > self._data_size
        ):
            self.drop_oldest(1)
        index = self._base + self._count
        slot = index % self._capacity
        pos = start % self._data_size
        self._data[pos : pos + len(frame)] = frame
        self._end = start + len(frame)
        self._times[slot] = t
        self._offsets[slot] = start
        self._lens[slot] = len(frame)
        self._flags[slot] = flags
        self._reqs[slot] = request
        self._cmds[slot] = command
        self._meanings[slot] = None
        self._count += 1
        return index

    def drop_oldest(self, n: int) -> None:
        """Forget the ``n`` oldest rows (all if ``n`` >= len)."""
        n = min(n, self._count)
        cap = self._capacity
        for index in range(self._base, self._base + n):
            self._meanings[index % cap] = None  # the strings go now, not when the slot is reused
        self._base += n
        self._count -= n

    def clear(self) -> None:
        self.drop_oldest(self._count)

    # --- one row, by local index (0 = oldest) --------------------------------------------
    def _slot(self, i: int) -> int:
        if not 0 <= i < self._count:
            raise IndexError(f"no traffic row {i}")
        return (self._base + i) % self._capacity

    def time(self, i: int) -> float:
        return self._times[self._slot(i)]

    def frame(self, i: int) -> bytes:
        slot = self._slot(i)
        pos = self._offsets[slot] % self._data_size
        return bytes(self._data[pos : pos + self._lens[slot]])

    def byte(self, i: int, k: int) -> int | None:
        """Byte ``k`` of row ``i``'s frame (None past its end)."""
        slot = self._slot(i)
        if k >= self._lens[slot]:
            return None
        return self._data[(self._offsets[slot] + k) % self._data_size]

    def flags(self, i: int) -> int:
        return self._flags[self._slot(i)]

    def set_flag(self, i: int, flag: int) -> None:
        self._flags[self._slot(i)] |= flag

    def request(self, i: int) -> int:
        """Absolute index of the request row ``i`` answers (NO_ROW if none or already dropped)."""
        index = self._reqs[self._slot(i)]
        return index if index >= self._base else NO_ROW

    def command(self, i: int) -> int:
        return self._cmds[self._slot(i)]

    def meaning(self, i: int) -> str | None:
        return self._meanings[self._slot(i)]

    def set_meaning(self, i: int, text: str) -> None:
        self._meanings[self._slot(i)] = text

    def frame_bytes(self) -> int:
        """Bytes of the stored frames."""
        return sum(self._lens[(self._base + i) % self._capacity] for i in range(self._count))

    def nbytes(self) -> int:
        """Bytes allocated for the rings (0 before the first row; the meanings' strings not counted)."""
        if not self._data:
            return 0
        return self._data_size + self._capacity * FIXED_BYTES_PER_ROW
