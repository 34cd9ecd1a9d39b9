"""ResultPacer: when to read again after an instant command was seen taken (one per link).

Used by :class:`~app.link.tracker.CommandTracker.poll_interval` (see "Polling while waiting"
in app/link/tracker.py); :class:`~app.link.command_client.CommandClient` keeps one per connection.
"""

from __future__ import annotations

__all__ = ["ResultPacer"]


class ResultPacer:
    """When, after an instant command (create point, teach), its result usually shows (per link).

    ``estimate`` (s after the read that first showed the command *taken* -- GV291 left its old
    code, e.g. the classic controller's 0, "received" -- with no result yet) times the next read.
    Reads before that keep the plain backoff (a slow controller's short 0 phase must not be
    skipped: the observe rule needs to see it). A fixed 1 ms backoff after the 0 overshot on a
    loaded host and still read a 1 ms controller a third time now and then. Here the read after
    it is due at ``estimate``, learned from each confirmed result: found in time -> it shrinks by
    :data:`DECAY` (it probes a little earlier next time); missed -> it grows to :data:`GROW`
    times the time of the read that missed, and one read follows a little later
    (:meth:`retry_after`; the reads after that back off as before). A steady
    controller is read twice per command, with an extra read in about one command of ten (the
    probe); a jittery one is read later rather than more often. Never a tight loop.
    """

    DECAY = 0.99
    GROW = 1.1
    MAX_ESTIMATE = 0.1  # s: a read at least every 0.1 s while a command is under way
    FLOOR = 1e-4  # s: a miss raises the estimate to at least GROW x this
    RETRY_MIN = 2e-4  # s: the read after a paced read that was early comes at least this much later

    def __init__(self) -> None:
        # Optimistic at first: the second read follows the first at once (an instant controller's
        # result is there), and a slower controller's first misses raise it geometrically.
        self.estimate = 0.0

    def retry_after(self, elapsed: float, backoff_first: float) -> float:
        """The pause before the one read that follows a paced read that came too early.

        ``elapsed``: s since the read that showed the command taken. The result is then most
        likely just late, as the learned estimate will be (GROW x the time of the miss): read
        again after (GROW - 1) x ``elapsed``, at least :data:`RETRY_MIN`, at most
        ``backoff_first`` (a miss used to cost a whole ``backoff_first``). One such read per
        command; the reads after it back off as before, so this is never a loop.
        """
        return min(backoff_first, max(self.RETRY_MIN, (self.GROW - 1.0) * elapsed))

    def learn(self, missed: float | None, found: float) -> None:
        """A confirmed result: ``found`` = when the read that saw it was sent, ``missed`` = when
        the last read before it was sent (None: no read after the first missed), in s after the
        first read."""
        if missed is None:
            value = min(self.estimate, found) * self.DECAY
        else:
            value = max(self.estimate, missed, self.FLOOR) * self.GROW
        self.estimate = min(max(value, 0.0), self.MAX_ESTIMATE)
