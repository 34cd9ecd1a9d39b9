"""Preallocated multi-channel numpy ring buffer (Qt-free) for rolling plots.

The storage is twice the capacity long and every sample is written twice (at ``i`` and at
``i + capacity``), so the newest ``n`` samples of a channel are always one contiguous slice:
``view()`` returns a numpy view, never a copy, and ``append()`` allocates nothing per sample
beyond numpy's scalar conversion. Layout is channel-major, so a channel's view is
C-contiguous, which is what ``PlotCurveItem.setData(..., skipFiniteCheck=True)`` likes best.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import numpy as np
    import numpy.typing as npt
else:  # numpy: by the first sample, not when the monitor is built (app/lazy_numpy.py)
    from app.lazy_numpy import np


class RingBuffer:
    """Fixed-capacity FIFO of samples, each sample being one value per channel."""

    __slots__ = ("_buf", "_capacity", "_channels", "_count", "_dtype", "_pos", "_total")

    def __init__(self, capacity: int, channels: int = 1, dtype: npt.DTypeLike = "float64") -> None:
        if capacity < 1:
            raise ValueError(f"capacity must be >= 1, got {capacity}")
        if channels < 1:
            raise ValueError(f"channels must be >= 1, got {channels}")
        self._capacity = int(capacity)
        self._channels = int(channels)
        self._dtype = dtype
        self._buf: np.ndarray | None = None  # allocated by the first use (see _storage)
        self._pos = 0  # next write index in [0, capacity)
        self._count = 0  # valid samples, <= capacity
        self._total = 0  # samples ever appended; never reset, so it works as a change stamp

    def _storage(self) -> np.ndarray:
        """The storage, allocated the first time it is needed: building the monitor (before the
        window's first paint) allocates nothing and imports no numpy."""
        buf = self._buf
        if buf is None:
            buf = self._buf = np.zeros((self._channels, 2 * self._capacity), dtype=self._dtype)
        return buf

    @property
    def capacity(self) -> int:
        return self._capacity

    @property
    def channels(self) -> int:
        return self._channels

    @property
    def total(self) -> int:
        """Samples ever appended (not reset by ``clear()``): a cheap "anything new?" stamp."""
        return self._total

    def __len__(self) -> int:
        return self._count

    def append(self, values: Sequence[float] | np.ndarray) -> None:
        """Add one sample: exactly one value per channel."""
        if len(values) != self._channels:
            raise ValueError(f"expected {self._channels} values, got {len(values)}")
        pos = self._pos
        buf = self._buf
        if buf is None:
            buf = self._storage()
        buf[:, pos] = values
        buf[:, pos + self._capacity] = buf[:, pos]
        self._pos = pos + 1 if pos + 1 < self._capacity else 0
        if self._count < self._capacity:
            self._count += 1
        self._total += 1

    def extend(self, block: np.ndarray) -> None:
        """Add many samples at once; ``block`` has shape ``(channels, n)``."""
        block = np.asarray(block)
        if block.ndim != 2 or block.shape[0] != self._channels:
            raise ValueError(f"block must have shape ({self._channels}, n), got {block.shape}")
        n = block.shape[1]
        if n == 0:
            return
        cap = self._capacity
        buf = self._storage()
        self._total += n
        if n >= cap:  # only the newest `cap` samples survive
            block = block[:, n - cap :]
            buf[:, :cap] = block
            buf[:, cap:] = block
            self._pos = 0
            self._count = cap
            return
        first = min(n, cap - self._pos)
        for start, chunk in ((self._pos, block[:, :first]), (0, block[:, first:])):
            k = chunk.shape[1]
            if k:
                buf[:, start : start + k] = chunk
                buf[:, start + cap : start + cap + k] = chunk
        self._pos = (self._pos + n) % cap
        self._count = min(cap, self._count + n)

    def view(self, channel: int, last: int | None = None) -> np.ndarray:
        """The newest ``last`` (default: all) samples of ``channel``, oldest first, as a view.

        The view aliases the storage: it stays valid until ``capacity - len(view)`` more
        samples are appended. Copy it if you keep it longer.
        """
        n = self._count if last is None else max(0, min(int(last), self._count))
        end = self._pos + self._capacity
        return self._storage()[channel, end - n : end]

    def views(self, last: int | None = None) -> np.ndarray:
        """All channels, shape ``(channels, n)``, as one view (each row contiguous)."""
        n = self._count if last is None else max(0, min(int(last), self._count))
        end = self._pos + self._capacity
        return self._storage()[:, end - n : end]

    def latest(self, channel: int) -> float:
        """Newest value of ``channel``; raises ``IndexError`` when empty."""
        if not self._count:
            raise IndexError("ring buffer is empty")
        return float(self._storage()[channel, self._pos + self._capacity - 1])

    def clear(self) -> None:
        """Forget all samples (the storage is kept; ``total`` is not reset)."""
        self._pos = 0
        self._count = 0
