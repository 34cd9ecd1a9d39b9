"""ResultPacer: when the second status read of an instant command goes out (no wire).

Its tracker side (``CommandTracker.poll_interval``) fed with synthetic status sequences.
"""

from __future__ import annotations

import itertools

import pytest

from app import timing
from app.link.pacer import ResultPacer
from app.link.tracker import CommandTracker
from app.protocol.enums import RunCommand
from tests.link.test_tracker import DONE, HOME, st


def _paced(pacer: ResultPacer, t0: float) -> CommandTracker:
    return CommandTracker(RunCommand.CREATE_POINT, st(DONE), None, t0, unconfirmed_after=1.0, pacer=pacer)


def test_the_pacer_times_the_second_read_and_learns_a_steady_controller() -> None:
    """A 1 ms controller: the first read shows 0 (received), the result shows 1 ms after it."""
    pacer = ResultPacer()
    misses = 0
    t = 0.0
    for _ in range(200):
        tr = _paced(pacer, t)
        first = t + 0.0002
        assert tr.update(st(0), None, first) is None  # the first read: at once, sees the 0
        read_at = first + tr.poll_interval(first)
        while True:  # the host reads when it planned to; the result is there from first + 1 ms
            result = tr.update(st(DONE) if read_at >= first + 0.001 else st(0), None, read_at)
            if result is not None:
                break
            misses += 1
            read_at += tr.poll_interval(read_at)
        assert result.ok and not result.unconfirmed
        t = read_at + 0.001
    assert 0.0008 <= pacer.estimate <= 0.0016  # near the controller's latency, above it at most x1.6
    assert misses <= 40  # about one probe in ten commands, plus the first few while it learns


def test_the_pacer_reads_an_instant_controller_twice_per_command() -> None:
    pacer = ResultPacer()
    for k in range(50):
        tr = _paced(pacer, float(k))
        assert tr.update(st(0), None, k + 0.0002) is None
        assert tr.poll_interval(k + 0.0002) == 0.0  # the result is usually there: read again now
        result = tr.update(st(DONE), None, k + 0.0004)
        assert result is not None and result.ok and tr.reads == 2
    assert pacer.estimate == 0.0


def test_unconfirmed_and_move_results_teach_the_pacer_nothing() -> None:
    pacer = ResultPacer()
    pacer.estimate = 0.002
    tr = _paced(pacer, 0.0)
    tr.unconfirmed_after = 0.05
    for t in (0.001, 0.01, 0.06):  # the stale 0xFF never moves: done, unconfirmed
        result = tr.update(st(DONE), None, t)
    assert result is not None and result.unconfirmed and pacer.estimate == 0.002
    move = CommandTracker(RunCommand.MOVE_TO_POINT, st(DONE), HOME, 0.0, pacer=pacer)
    assert move.pacer is None  # moves keep their own poll


def test_reads_before_the_command_is_seen_taken_keep_the_backoff(monkeypatch: pytest.MonkeyPatch) -> None:
    """A slow controller's short 0 phase must not be skipped (the observe rule needs it)."""
    monkeypatch.setattr(timing, "ACK_BACKOFF_FIRST", 0.001)
    pacer = ResultPacer()
    pacer.estimate = 0.02
    tr = _paced(pacer, 0.0)
    assert tr.update(st(DONE), None, 0.001) is None  # the old code: not taken yet
    assert tr.poll_interval(0.001) == pytest.approx(0.001)
    assert tr.update(st(DONE), None, 0.002) is None
    assert tr.poll_interval(0.002) == pytest.approx(0.002)
    assert tr.update(st(0), None, 0.004) is None  # taken: the next read when results usually show
    assert tr.poll_interval(0.004) == pytest.approx(0.02)
    assert tr.update(st(DONE), None, 0.024) is not None
    assert pacer.estimate == pytest.approx(0.02 * ResultPacer.DECAY)


def test_a_paced_read_that_was_early_is_followed_once_soon_then_the_backoff(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A miss costs a short wait, not a whole backoff step; never a tight loop after it."""
    monkeypatch.setattr(timing, "ACK_BACKOFF_FIRST", 0.001)
    monkeypatch.setattr(timing, "ACK_BACKOFF_CAP", 0.01)
    pacer = ResultPacer()
    pacer.estimate = 0.0008
    tr = _paced(pacer, 0.0)
    assert tr.update(st(0), None, 0.0001) is None  # taken
    assert tr.poll_interval(0.0001) == pytest.approx(0.0008)
    assert tr.update(st(0), None, 0.0009) is None  # the paced read: still no result
    # once more after (GROW - 1) x the time since the taken read, at least RETRY_MIN
    assert tr.poll_interval(0.0009) == pytest.approx(ResultPacer.RETRY_MIN)
    reads = [0.0011]
    now = 0.0011
    while now < 0.05:  # the controller never answers: the reads back off from ACK_BACKOFF_FIRST
        assert tr.update(st(0), None, now) is None
        now += tr.poll_interval(now)
        reads.append(now)
    gaps = [b - a for a, b in itertools.pairwise(reads)]
    assert gaps[:4] == pytest.approx([0.001, 0.002, 0.004, 0.008])
    assert len(reads) <= 10  # 10 reads in 50 ms at most
    # a later miss, long after the taken read: the retry is capped at ACK_BACKOFF_FIRST
    assert pacer.retry_after(0.02, 0.001) == 0.001
    assert pacer.retry_after(0.005, 0.001) == pytest.approx((ResultPacer.GROW - 1.0) * 0.005)


def test_the_pacer_keeps_a_one_ms_controller_near_two_reads_per_command() -> None:
    """With the retry a miss costs one read and a fraction of a millisecond."""
    pacer = ResultPacer()
    reads = 0
    late = 0.0
    t = 0.0
    for _ in range(300):
        tr = _paced(pacer, t)
        first = t + 0.0002
        assert tr.update(st(0), None, first) is None
        read_at = first + tr.poll_interval(first)
        while (result := tr.update(st(DONE) if read_at >= first + 0.001 else st(0), None, read_at)) is None:
            read_at += tr.poll_interval(read_at)
        assert result.ok and not result.unconfirmed
        reads += tr.reads
        late += read_at - (first + 0.001)
        t = read_at + 0.001
    assert reads / 300 <= 2.2
    assert late / 300 <= 0.0002  # the result is read on average within 0.2 ms of showing
