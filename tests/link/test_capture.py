"""Traffic capture, the RTT meter and the link-statistics reporter."""

from __future__ import annotations

from typing import Any

from app.link.capture import LinkStatsReporter, RttMeter, TrafficCapture
from app.link.stats import LinkStats
from app.link.transport import TrafficRecord


def test_rtt_is_the_mean_per_period_and_reported_on_change() -> None:
    meter = RttMeter(0.5)
    meter.reset(0.0)
    assert meter.note(0.002, 2, 0.1) is None  # the period is not over
    assert meter.note(0.002, 2, 0.5) == 1.0  # 4 ms over 4 transactions
    assert meter.note(0.002, 2, 1.0) is None  # same value: not reported again
    assert meter.note(0.004, 2, 1.5) == 2.0
    meter.forget()
    assert meter.note(0.004, 2, 2.0) == 2.0  # a new link reports even an equal value


def test_link_stats_at_most_once_a_period_and_only_on_change() -> None:
    reporter = LinkStatsReporter(0.5)
    a, b = LinkStats(requests=1), LinkStats(requests=2)
    assert reporter.due(a, 0.0) == a
    assert reporter.due(b, 0.2) is None  # too soon
    assert reporter.due(a, 0.6) is None  # unchanged
    assert reporter.due(b, 0.7) == b
    reporter.forget()
    assert reporter.due(b, 0.8) == b


def test_capture_batches_frames_of_the_client_only_while_on(sim: Any, make_client: Any) -> None:
    capture = TrafficCapture()
    client = make_client(sim)
    capture.attach(client)  # off: not observing
    client.read_status()
    assert capture.flush() is None
    assert capture.set(True, client) and not capture.set(True, client)
    client.read_status()
    batch = capture.flush()
    assert batch is not None and [r.direction for r in batch] == ["tx", "rx"]
    assert all(isinstance(r, TrafficRecord) for r in batch)
    assert capture.flush() is None
    capture.set(False, client)
    client.read_status()
    assert capture.flush() is None
