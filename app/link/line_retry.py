"""Sending again what a noisy serial line damaged, where that is safe.

On an RTU serial line a byte in a few hundred may be damaged: an answer fails its CRC or its
length, or arrives garbled (:class:`~app.errors.MalformedResponse`), or a damaged request is not
answered at all (:class:`~app.errors.ResponseTimeout`). The transport has resynchronised by then
(its input dropped until the line was quiet, :meth:`~app.link.transport.Transport._resync`). What
is sent again, within a bounded budget (:mod:`app.timing` ``LINE_*``; no answer at all is retried fewer times,
``LINE_TIMEOUT_RETRIES``, so a silent controller is still seen soon):

* every read (status polls, pose reads, GV291, the shared registers): it changes nothing;
* a write of registers that only hold values (an upload's pose GVs, GV200-202 of a create point,
  the tool frame GV245): read back first -- the values there: it took (only its answer was
  damaged), recorded so; else written again at once. Nothing else is written in between, so a
  repeated write never lands after a newer one;
* an upload's point, sent whole again (its pose, GV200-202, 440): re-creating the same point at
  the same pose is idempotent (:meth:`app.link.client.RobotClient.upload_points`).

Never a motion command (step, move, jog, run program, go to zero) nor a mode change: a damaged
answer to one of those leaves its outcome *unknown* (:mod:`app.link.outcome`). Stop and the jog's
ratio 0 have their own repeat (:mod:`app.link.halt`). Only on a serial line: over TCP a malformed
answer is a broken or hostile server, not line noise, and is reported as it is.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import TypeVar

from app import timing
from app.connection import ConnectionSettings
from app.errors import MalformedResponse, ResponseTimeout

__all__ = ["LINE_ERRORS", "LineRetry", "on_noisy_line", "retry_line"]

#: What a damaged frame looks like to the host.
LINE_ERRORS = (MalformedResponse, ResponseTimeout)

_log = logging.getLogger(__name__)
_T = TypeVar("_T")


def on_noisy_line(settings: ConnectionSettings) -> bool:
    """A serial line, where damaged frames are line noise worth a retry."""
    return settings.serial_port is not None


class LineRetry:
    """One request's (or one upload point's) budget of retries after damaged frames."""

    def __init__(
        self,
        settings: ConnectionSettings,
        budget: int,
        halted: Callable[[], bool] | None = None,
        *,
        timeouts: int | None = None,
    ) -> None:
        """``budget`` retries, of which at most ``timeouts`` (default
        :data:`app.timing.LINE_TIMEOUT_RETRIES`) after no answer at all: a damaged request is rare
        twice in a row, a silent controller is not to be waited for much longer than before.
        ``halted``: True once a stop or a cancel is on its way (then nothing is sent again)."""
        self._left = budget if on_noisy_line(settings) else 0
        self._timeouts_left = timing.LINE_TIMEOUT_RETRIES if timeouts is None else timeouts
        self._halted = halted
        self.retries = 0

    def halted(self) -> bool:
        """A stop or a cancel is on its way: nothing is sent again."""
        return self._halted is not None and self._halted()

    def may_retry(self, exc: BaseException) -> bool:
        """``exc`` is a damaged frame, the budget has a retry left and nothing halts the work
        (takes that retry)."""
        if self._left <= 0 or not isinstance(exc, LINE_ERRORS):
            return False
        if self.halted():
            return False
        if isinstance(exc, ResponseTimeout):
            if self._timeouts_left <= 0:
                return False
            self._timeouts_left -= 1
        self._left -= 1
        self.retries += 1
        _log.info("damaged frame on the serial line (%s): sending it again (retry %d)", exc, self.retries)
        return True


def retry_line(action: Callable[[], _T], retry: LineRetry) -> _T:
    """``action()``, run again while it fails on a damaged frame and ``retry`` allows. Only for an
    action that is safe to repeat (reads, and writes whose effect it reads back first)."""
    while True:
        try:
            return action()
        except LINE_ERRORS as exc:
            if not retry.may_retry(exc):
                raise
