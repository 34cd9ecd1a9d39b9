"""RingBuffer: wrap-around order, views without copies, no growth while appending."""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest

from ui.models.ring_buffer import RingBuffer


def _fill(rb: RingBuffer, start: int, stop: int) -> None:
    for i in range(start, stop):
        rb.append((float(i), float(-i)))


def test_empty_buffer() -> None:
    rb = RingBuffer(4, 2)
    assert len(rb) == 0
    assert rb.view(0).size == 0
    assert rb.views().shape == (2, 0)
    with pytest.raises(IndexError):
        rb.latest(0)


def test_partial_fill_keeps_order() -> None:
    rb = RingBuffer(5, 2)
    _fill(rb, 0, 3)
    assert len(rb) == 3
    assert rb.view(0).tolist() == [0.0, 1.0, 2.0]
    assert rb.view(1).tolist() == [0.0, -1.0, -2.0]
    assert rb.latest(0) == 2.0


@pytest.mark.parametrize("appended", [5, 6, 7, 9, 10, 11, 23])
def test_wraps_and_keeps_the_newest_in_order(appended: int) -> None:
    rb = RingBuffer(5, 2)
    _fill(rb, 0, appended)
    expected = [float(i) for i in range(appended - 5, appended)]
    assert len(rb) == 5
    assert rb.view(0).tolist() == expected
    assert rb.view(1).tolist() == [-v for v in expected]
    assert rb.view(0, last=2).tolist() == expected[-2:]
    assert rb.view(0, last=99).tolist() == expected
    assert rb.latest(0) == float(appended - 1)
    assert rb.total == appended


def test_views_are_contiguous_and_share_the_storage() -> None:
    rb = RingBuffer(8, 3)
    for i in range(13):  # wrapped
        rb.append((i, i * 10, i * 100))
    view = rb.view(1)
    assert view.flags.c_contiguous
    assert not view.flags.owndata
    assert np.shares_memory(view, rb._buf)
    # A later append shows through the old view's storage: it really is a view, not a copy.
    block = rb.views()
    assert block.shape == (3, 8)
    assert all(block[k].flags.c_contiguous for k in range(3))
    assert block[2].tolist() == [i * 100.0 for i in range(5, 13)]


def test_view_stays_valid_until_capacity_minus_length_appends() -> None:
    rb = RingBuffer(10, 1)
    for i in range(15):
        rb.append((i,))
    view = rb.view(0, last=4)  # 11..14
    snapshot = view.copy()
    for i in range(15, 21):  # 6 = capacity - 4 more samples
        rb.append((i,))
    assert view.tolist() == snapshot.tolist()


def test_extend_matches_repeated_append() -> None:
    rng = np.random.default_rng(1)
    a, b = RingBuffer(7, 2), RingBuffer(7, 2)
    for n in (3, 5, 1, 9, 0, 7, 2, 20, 4):
        block = rng.normal(size=(2, n))
        a.extend(block)
        for k in range(n):
            b.append(block[:, k])
        assert len(a) == len(b)
        assert a.total == b.total
        np.testing.assert_array_equal(a.views(), b.views())


def test_clear_forgets_samples_but_total_keeps_counting() -> None:
    rb = RingBuffer(4, 1)
    for i in range(6):
        rb.append((i,))
    rb.clear()
    assert len(rb) == 0
    assert rb.total == 6
    rb.append((42,))
    assert rb.view(0).tolist() == [42.0]
    assert rb.total == 7


def test_bad_arguments() -> None:
    with pytest.raises(ValueError):
        RingBuffer(0)
    with pytest.raises(ValueError):
        RingBuffer(4, 0)
    rb = RingBuffer(4, 2)
    with pytest.raises(ValueError):
        rb.append((1.0,))
    with pytest.raises(ValueError):
        rb.extend(np.zeros((3, 2)))


def test_appending_allocates_nothing_that_stays() -> None:
    rb = RingBuffer(1000, 7)
    assert rb._buf is None  # allocated by the first sample, not when the monitor is built
    sample = (1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0)
    for _ in range(10):
        rb.append(sample)
    storage = rb._buf
    assert storage is not None
    tracemalloc.start()
    try:
        before, _ = tracemalloc.get_traced_memory()
        for _ in range(20_000):
            rb.append(sample)
        after, _ = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert rb._buf is storage
    assert after - before < 4096
