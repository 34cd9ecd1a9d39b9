"""What the worker measures about the wire: traffic capture, mean round trip, link statistics.

Qt-free; the worker feeds them from its polls and emits what they return.
"""

from __future__ import annotations

from app.link.client import RobotClient
from app.link.stats import LinkStats
from app.link.transport import TrafficRecord

__all__ = ["LinkStatsReporter", "RttMeter", "TrafficCapture"]


class TrafficCapture:
    """Frames seen by the client while capturing, handed out in batches (the worker's
    ``flush_traffic``: every ``TRAFFIC_DELIVERY_PERIOD`` and before any outcome or state change)."""

    def __init__(self) -> None:
        self.on = False
        self._records: list[TrafficRecord] = []

    def set(self, on: bool, client: RobotClient | None) -> bool:
        """Start / stop capturing; False if nothing changed."""
        if on == self.on:
            return False
        self.on = on
        self._records.clear()
        if client is not None:
            if on:
                client.add_observer(self.observe)
            else:
                client.remove_observer(self.observe)
        return True

    def attach(self, client: RobotClient) -> None:
        """A new client: observe it if capturing."""
        if self.on:
            client.add_observer(self.observe)

    def detach(self, client: RobotClient) -> None:
        client.remove_observer(self.observe)

    def observe(self, record: TrafficRecord) -> None:
        if self.on:
            self._records.append(record)

    def flush(self) -> tuple[TrafficRecord, ...] | None:
        """The frames since the last flush (None when not capturing or nothing new): a tuple of
        frozen records, so the batch that crosses into the GUI thread can change in neither."""
        if not (self.on and self._records):
            return None
        batch = tuple(self._records)
        self._records.clear()
        return batch


class RttMeter:
    """Mean time per transaction over a period; reported only when the rounded value changed."""

    def __init__(self, period: float) -> None:
        self.period = period
        self._sum = 0.0
        self._count = 0
        self._since = 0.0
        self._last: float | None = None

    def reset(self, now: float) -> None:
        self._sum, self._count, self._since = 0.0, 0, now

    def forget(self) -> None:
        """A new link: the next value is reported even if equal to the last one."""
        self._last = None

    def note(self, seconds: float, transactions: int, now: float) -> float | None:
        """Add ``transactions`` that took ``seconds``; the mean in ms when a period ended with a new value."""
        self._sum += seconds
        self._count += transactions
        if now - self._since < self.period or not self._count:
            return None
        rtt = round(1000.0 * self._sum / self._count, 2)
        self.reset(now)
        if rtt == self._last:
            return None
        self._last = rtt
        return rtt


class LinkStatsReporter:
    """The client's :class:`LinkStats` at most once a period, and only when they changed."""

    def __init__(self, period: float) -> None:
        self.period = period
        self._at = float("-inf")
        self._last: LinkStats | None = None

    def forget(self) -> None:
        self._at = float("-inf")
        self._last = None

    def due(self, stats: LinkStats, now: float) -> LinkStats | None:
        if now - self._at < self.period or stats == self._last:
            return None
        self._at = now
        self._last = stats
        return stats
