"""One display clock for the live views: poll rate and paint rate are different clocks.

Views that show live values (the monitor's readouts and plots, the pose strip, the traffic
table) do not redraw when a datum arrives. They note it and ask the clock for a frame
(:meth:`DisplayClock.request`); the clock runs every requested callback together, at most once
per ``DISPLAY_INTERVAL_MS``. Their repaints then land in one window update: one paint and one
flush of the backing store per frame instead of one per view and datum, which is where a
GUI thread streaming at 100 Hz spent most of its time (``python -m benchmarks.streaming``).

The clock has no free-running timer: with nothing requested it is idle (a robot standing
still costs no frames). The first request after a quiet spell runs at the next turn of the
event loop; later ones wait for the next frame. A view that animates (the monitor's time
axis) requests the next frame from its frame callback, and cancels when it is hidden.

Views use :meth:`DisplayClock.shared`, one clock per application, unless given their own.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable

import shiboken6
from PySide6.QtCore import QCoreApplication, QObject, QTimer, Slot

__all__ = ["DISPLAY_HZ", "DISPLAY_INTERVAL_MS", "DisplayClock"]

# Frames a second at most: numbers that change smoothly and can still be read. 20, not 25: every
# live view's repaint follows this rate, and the eye does not tell 20 numbers a second from 25
# (the monitor's plots take every other frame: 10 Hz).
DISPLAY_HZ = 20
DISPLAY_INTERVAL_MS = math.ceil(1000 / DISPLAY_HZ)  # 50 ms

FrameCallback = Callable[[], None]


class DisplayClock(QObject):
    """Runs the requested frame callbacks together, at most once per ``interval_ms``."""

    def __init__(self, parent: QObject | None = None, *, interval_ms: int = DISPLAY_INTERVAL_MS) -> None:
        super().__init__(parent)
        if interval_ms < 1:
            raise ValueError(f"the display interval must be >= 1 ms, got {interval_ms}")
        self._interval_ms = int(interval_ms)
        self._pending: dict[FrameCallback, None] = {}  # an ordered set: views run in request order
        self._last_frame = -math.inf  # time.monotonic() of the last frame
        self._frames = 0
        self._timer = QTimer(self)
        self._timer.setSingleShot(True)
        self._timer.timeout.connect(self._frame)

    @staticmethod
    def shared() -> DisplayClock:
        """The application's clock (made on first use, owned by the QCoreApplication)."""
        global _shared
        if _shared is None or not shiboken6.isValid(_shared):
            _shared = DisplayClock(QCoreApplication.instance())
        return _shared

    @property
    def interval_ms(self) -> int:
        return self._interval_ms

    @property
    def frames(self) -> int:
        """Frames run so far (each ran every callback requested before it)."""
        return self._frames

    @property
    def active(self) -> bool:
        """A frame is due (some view asked for one)."""
        return self._timer.isActive()

    def is_requested(self, callback: FrameCallback) -> bool:
        return callback in self._pending

    def request(self, callback: FrameCallback) -> None:
        """Run ``callback`` in the next frame (once, however often it is asked for)."""
        self._pending[callback] = None
        if not self._timer.isActive():
            wait_ms = (self._last_frame - time.monotonic()) * 1000.0 + self._interval_ms
            self._timer.start(max(0, math.ceil(wait_ms)) if wait_ms > 0 else 0)

    def run_or_request(self, callback: FrameCallback) -> None:
        """Run ``callback`` now if the clock is idle (no frame due, none within the last interval),
        as a frame of its own; else in the next frame. The first value after a quiet spell shows
        at once, a stream of them at the frame rate."""
        if self._pending or (time.monotonic() - self._last_frame) * 1000.0 < self._interval_ms:
            self.request(callback)
            return
        self._last_frame = time.monotonic()
        self._frames += 1
        callback()

    def cancel(self, callback: FrameCallback) -> None:
        """Forget a request (a view being hidden); the timer stops when nothing is left."""
        self._pending.pop(callback, None)
        if not self._pending:
            self._timer.stop()

    @Slot()
    def _frame(self) -> None:
        self._last_frame = time.monotonic()
        self._frames += 1
        callbacks, self._pending = list(self._pending), {}
        for callback in callbacks:
            owner = getattr(callback, "__self__", None)
            if isinstance(owner, QObject) and not shiboken6.isValid(owner):
                continue  # its view was deleted since it asked
            callback()


_shared: DisplayClock | None = None
