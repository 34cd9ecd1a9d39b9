"""Compact storage of the traffic inspector's frames (Qt-free): one row is its raw bytes in a
shared byte buffer plus a few fixed-size fields in typed arrays, no Python object per row.

Measured (``python -m benchmarks.gui_memory``, the 10-minute soak): a row kept as a Python object
(the row, its time as a float, its frame as a bytes object, the list slot) cost ~250 bytes for a
~110-byte frame, 20,000 rows ~5 MB, and hundreds of thousands of small objects freed in chunks
of 1,000 as the table rolled left CPython's small-object arenas fragmented. Here a row costs its
frame's bytes plus ``FIXED_BYTES_PER_ROW``, held in a handful of large buffers. Text (time, hex,
decoded meaning) is made when a row is shown and kept only for the rows the model keeps views of.

Rows have absolute indices (``base`` .. ``base + len - 1``) that never change while a row lives,
so a response can name its request even after older rows were dropped.
"""

from __future__ import annotations

from array import array
from typing import Final

__all__ = ["FIXED_BYTES_PER_ROW", "NO_COMMAND", "NO_ROW", "TrafficStore"]

# flag bits, one byte per row
RX: Final = 1
RTU: Final = 2
POLL: Final = 4
BAD: Final = 8

NO_ROW: Final = -1  # no request (a request row itself, or an answer that was not paired)
NO_COMMAND: Final = -1
# time (8) + frame offset (8) + request (8) + last command (2) + flags (1) + meaning slot (8)
FIXED_BYTES_PER_ROW: Final = 35


class TrafficStore:
    """Rows in arrival order; ``drop_oldest`` forgets from the front."""

    __slots__ = ("_base", "_cmds", "_data", "_data_base", "_flags", "_offsets", "_reqs", "_times", "meanings")

    def __init__(self) -> None:
        self._base = 0  # absolute index of local row 0
        self._data_base = 0  # absolute offset of _data[0]
        self._times = array("d")
        self._offsets = array("q")  # absolute offset of each frame's first byte
        self._reqs = array("q")  # absolute index of the request a response answers, or NO_ROW
        self._cmds = array("h")  # the last run command (RunCommand value) at the frame, or NO_COMMAND
        self._flags = bytearray()
        self._data = bytearray()  # all frames, back to back
        self.meanings: list[str | None] = []  # the decoded meaning once shown (shared strings)

    def __len__(self) -> int:
        return len(self._times)

    @property
    def base(self) -> int:
        return self._base

    def append(self, t: float, frame: bytes, flags: int, request: int, command: int) -> int:
        """Add a row; returns its absolute index."""
        self._times.append(t)
        self._offsets.append(self._data_base + len(self._data))
        self._data += frame
        self._flags.append(flags)
        self._reqs.append(request)
        self._cmds.append(command)
        self.meanings.append(None)
        return self._base + len(self._times) - 1

    def drop_oldest(self, n: int) -> None:
        """Forget the ``n`` oldest rows (all if ``n`` >= len)."""
        n = min(n, len(self._times))
        if n <= 0:
            return
        if n == len(self._times):
            self.clear()
            return
        cut = self._offsets[n] - self._data_base
        del self._data[:cut]
        self._data_base += cut
        for column in (self._times, self._offsets, self._reqs, self._cmds, self._flags, self.meanings):
            del column[:n]
        self._base += n

    def clear(self) -> None:
        self._base += len(self._times)
        self._data_base += len(self._data)
        for column in (self._times, self._offsets, self._reqs, self._cmds, self._flags, self.meanings):
            del column[:]
        del self._data[:]

    # --- one row, by local index (0 = oldest) --------------------------------------------
    def time(self, i: int) -> float:
        return self._times[i]

    def frame(self, i: int) -> bytes:
        start = self._offsets[i] - self._data_base
        end = self._offsets[i + 1] - self._data_base if i + 1 < len(self._offsets) else len(self._data)
        return bytes(self._data[start:end])

    def frame_size(self, i: int) -> int:
        end = self._offsets[i + 1] if i + 1 < len(self._offsets) else self._data_base + len(self._data)
        return end - self._offsets[i]

    def byte(self, i: int, k: int) -> int | None:
        """Byte ``k`` of row ``i``'s frame (None past its end)."""
        if k >= self.frame_size(i):
            return None
        return self._data[self._offsets[i] - self._data_base + k]

    def flags(self, i: int) -> int:
        return self._flags[i]

    def set_flag(self, i: int, flag: int) -> None:
        self._flags[i] |= flag

    def request(self, i: int) -> int:
        """Absolute index of the request row ``i`` answers (NO_ROW if none or already dropped)."""
        index = self._reqs[i]
        return index if index >= self._base else NO_ROW

    def command(self, i: int) -> int:
        return self._cmds[i]

    def nbytes(self) -> int:
        """Bytes held in the buffers (their used part; the meanings' strings not counted)."""
        columns = (self._times, self._offsets, self._reqs, self._cmds)
        return (
            len(self._data)
            + len(self._flags)
            + sum(c.itemsize * len(c) for c in columns)
            + 8 * len(self.meanings)
        )
