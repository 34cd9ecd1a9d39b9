"""``RegisterClient.writes_settled_before``: what the stop-line-only Stop relies on (every write of
the main link answered before the line's stop went out; app/link/halt.py), against the
simulator: a write under way, answered, refused, without its answer, and Stop's own 441."""

from __future__ import annotations

import time
from typing import Any

import pytest
from pymodbus.constants import ExcCodes

from app.errors import ModbusExceptionError, ResponseTimeout
from app.protocol import registers

GV = 10  # a general-purpose GV: writing it starts nothing


def test_an_answered_write_is_settled_from_its_answer_on(sim: Any, make_client: Any) -> None:
    client = make_client(sim, timeout=1.0)
    assert client.writes_settled_before(time.monotonic())  # nothing written yet
    before = time.monotonic()
    client.write_gv(GV, [1.0])
    assert client.write_answered_at > before
    assert not client.writes_settled_before(before)  # a stop sent before its answer: not settled
    assert client.writes_settled_before(time.monotonic())


def test_a_write_without_its_answer_stays_unsettled_for_a_timeout_even_after_a_later_answer(
    sim: Any, make_client: Any
) -> None:
    """The review's case: a write times out (it may still be acted on), and a later write is
    answered on a fresh connection: the lost one is not forgotten until one link timeout after
    its failure (a controller acts on a request within the timeout or not at all)."""
    client = make_client(sim, timeout=0.3)
    sim.set_response_delay(1.0)
    with pytest.raises(ResponseTimeout):
        client.write_gv(GV, [2.0])
    failed = time.monotonic()
    sim.set_response_delay(0.0)
    assert not client.writes_settled_before(time.monotonic())
    client.write_gv(GV, [3.0])  # answered
    now = time.monotonic()
    assert not client.writes_settled_before(now)  # still within the lost write's window
    assert client.write_lost_until > failed + 0.2  # one timeout (0.3 s) after the failure
    assert client.writes_settled_before(client.write_lost_until + 0.001)


def test_a_refused_write_counts_as_not_settled_for_a_timeout(sim: Any, make_client: Any) -> None:
    client = make_client(sim, timeout=0.5)
    sim.set_exception(ExcCodes.DEVICE_BUSY, range(2 * GV, 2 * GV + 2))
    try:
        with pytest.raises(ModbusExceptionError):
            client.write_gv(GV, [4.0])
    finally:
        sim.set_exception(None)
    assert not client.writes_settled_before(time.monotonic())


def test_stops_own_write_is_not_counted(sim: Any, make_client: Any) -> None:
    """441 itself (the main link's stop, even one without its answer) leaves the others' state
    alone: it is the stop, not a write that could run after it."""
    client = make_client(sim, timeout=0.3)
    client.write_gv(GV, [5.0])
    answered = client.write_answered_at
    sim.set_response_delay(1.0, addresses=range(registers.REG_STOP, registers.REG_STOP + 1))
    try:
        with pytest.raises(ResponseTimeout):
            client.stop()
    finally:
        sim.set_response_delay(0.0)
    assert client.write_answered_at == answered
    assert client.writes_settled_before(time.monotonic())
