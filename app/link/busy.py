"""Backing off a controller that answers *busy* (Modbus exception 6, "try again later").

Only for what is safe to send again: an upload's point (its pose, its parameters, its 440 and the
status reads that follow: re-creating the same point at the same pose is idempotent). A move,
a jog or a mode change is never retried here: a refused move is reported refused.

:class:`BusyBackoff` is one point's budget: :meth:`~BusyBackoff.may_retry` says whether the
error is *busy* and the budget (:data:`app.timing.BUSY_RETRY_BUDGET` from the first busy answer)
leaves room for another try; :meth:`~BusyBackoff.pause` waits the next delay
(:data:`~app.timing.BUSY_BACKOFF_FIRST`, doubling up to :data:`~app.timing.BUSY_BACKOFF_CAP`),
running ``between`` (the worker's urgent jobs: a Stop never waits for the back-off) and giving up
when ``halted`` says a stop or a cancel is on its way.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from typing import TypeVar

from app import timing
from app.errors import ModbusExceptionError

__all__ = ["MODBUS_BUSY", "BusyBackoff", "is_busy", "retry_busy"]

MODBUS_BUSY = 6  # Modbus exception code "server device busy"

_log = logging.getLogger(__name__)
_T = TypeVar("_T")


def is_busy(exc: BaseException) -> bool:
    """The controller answered *server device busy* (Modbus exception 6)."""
    return isinstance(exc, ModbusExceptionError) and exc.exception_code == MODBUS_BUSY


class BusyBackoff:
    """One write's (one upload point's) bounded back-off from *busy* answers."""

    def __init__(
        self, halted: Callable[[], bool] | None = None, between: Callable[[], None] | None = None
    ) -> None:
        self._halted = halted
        self._between = between
        self._first: float | None = None  # monotonic time of the first busy answer
        self._delay = timing.BUSY_BACKOFF_FIRST
        self.retries = 0

    def may_retry(self, exc: BaseException) -> bool:
        """``exc`` is *busy*, nothing halts the work, and the budget has room for one more try."""
        if not is_busy(exc) or self._is_halted():
            return False
        now = time.monotonic()
        if self._first is None:
            self._first = now
        return now + self._delay <= self._first + timing.BUSY_RETRY_BUDGET

    def pause(self) -> bool:
        """Wait the next delay (``between`` in its slices); False when halted meanwhile (no retry)."""
        end = time.monotonic() + self._delay
        self._delay = min(2 * self._delay, timing.BUSY_BACKOFF_CAP)
        self.retries += 1
        _log.info("controller busy: trying again in %.3f s (retry %d)", end - time.monotonic(), self.retries)
        while (left := end - time.monotonic()) > 0:
            if self._between is not None:
                self._between()
            if self._is_halted():
                return False
            time.sleep(min(left, timing.BUSY_BACKOFF_SLICE))
        return not self._is_halted()

    def _is_halted(self) -> bool:
        return self._halted is not None and self._halted()


def retry_busy(action: Callable[[], _T], backoff: BusyBackoff) -> _T:
    """``action()``, tried again after ``backoff``'s pause while it is answered *busy* and the
    budget lasts. Only for an action that is safe to repeat (a read, an idempotent write)."""
    while True:
        try:
            return action()
        except ModbusExceptionError as exc:
            if not backoff.may_retry(exc):
                raise
            busy = exc
        if not backoff.pause():
            raise busy
