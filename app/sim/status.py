"""GV291 publication of the simulated controller: what a host reads while a command is taken up.

On a 440 command with a status (0x40/0x41/0x42/0xE0/0x80/0x81) the old value stays for
``status_delay`` seconds, then 0 (INITIAL) shows for ``command_latency`` seconds — and, for the
instant commands (create point, teach enable/disable), until a host has read GV291 at least once
(at most :data:`ZERO_HOLD_MAX` seconds) — then the robot's value (6 while moving, 0xFF done, or
the error). The read rule emulates a controller whose cycle is slower than the host's poll, and
makes the fresh-versus-stale question deterministic in tests: a host that polls always sees the
0 between two 0xFF. A stop (441) keeps the old value for ``status_delay`` and then shows 0.

That is the ``"classic"`` timing profile (``SimConfig.timing``), the one a polling host
handles best. The others model controllers we may meet: ``"fast"`` -- the result replaces the
old code within one scan (the next request sees it; the 0 is never visible, no read-hold);
``"slow"`` -- the old code stays for a seeded random pickup time (``timing.SIM_SLOW_PICKUP``),
then 0 shows for ``timing.SIM_SLOW_ZERO``, then the result, nothing held for a reader.

Not thread-safe: the server calls it under its lock.
"""

from __future__ import annotations

import random
from typing import Final

from app import timing

# Longest time the 0 ("received") phase of GV291 waits for a host to read it.
ZERO_HOLD_MAX: Final = 0.25


class StatusPublisher:
    """The hold of GV291 after a command: the old code, then 0, then the robot's code."""

    def __init__(self, profile: str, command_latency: float, seed: int) -> None:
        self.profile = profile
        self.command_latency = command_latency
        self._rng = random.Random(seed)  # the "slow" profile's jitter
        self._hold_old_until = 0.0
        self._hold_old_value = 0
        self._hold_zero_until = 0.0
        self._zero_unread = False  # the 0 phase has not been seen by a host read yet

    def published(self, now: float, current: int) -> int:
        """GV291 as a host reads it at ``now``; ``current`` is the robot's own value."""
        if now < self._hold_old_until:
            return self._hold_old_value
        if now < self._hold_zero_until:
            return 0
        if self._zero_unread and now < self._hold_old_until + ZERO_HOLD_MAX:
            return 0
        return current

    def hold(self, now: float, current: int, *, pickup: float, latency: bool, read_hold: bool) -> None:
        """A command was taken up at ``now``: publish the old GV291 a while, then 0, then the
        robot's value. ``latency``: the command shows a 0 phase (not a stop); ``read_hold``: the
        0 waits for a host's read (the instant commands, classic profile)."""
        old = self.published(now, current)
        zero = self.command_latency if latency else 0.0
        if self.profile == "fast":
            zero = 0.0
        elif self.profile == "slow":
            pickup += self._rng.uniform(*timing.SIM_SLOW_PICKUP)
            zero = self._rng.uniform(*timing.SIM_SLOW_ZERO) if latency else 0.0
        self._hold_old_value = old
        self._hold_old_until = now + pickup
        self._hold_zero_until = self._hold_old_until + zero
        self._zero_unread = latency and read_hold and self.profile == "classic"

    def release(self) -> None:
        """Show the robot's value at once (a host wrote GV291, or the controller restarted)."""
        self._hold_old_until = self._hold_zero_until = 0.0
        self._zero_unread = False

    def seen(self, now: float) -> None:
        """A host read GV291 at ``now``: once the old code is gone, the 0 has been seen."""
        if self._zero_unread and now >= self._hold_old_until:
            self._zero_unread = False
