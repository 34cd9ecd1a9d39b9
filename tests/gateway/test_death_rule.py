"""The gateway's death rule (app/gateway/poller.py): a controller is dead once it has been silent the
death window since its last answer, not when one request outlived the poll timeout. Against real
simulators (one in its own process, stopped by SIGSTOP) and a real Mosquitto, read by an
independent subscriber."""

from __future__ import annotations

import os
import signal
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from app import timing
from benchmarks.gateway import SimProcess

from .conftest import Subscriber
from .test_sparkplug import wait_until

DDEATH_BOUND = 0.25  # s from silence to the subscriber's DDEATH (issue 23)
DEATH_WINDOW = 0.6  # s: the late answers' test (its subject is the rule, not the product's window)


@pytest.fixture
def sim_process() -> Iterator[SimProcess]:
    sim = SimProcess(1, idle=True, tick_hz=None)  # a plain teachpad-sim: no program, its own ticker
    try:
        yield sim
    finally:
        sim.stop()


def test_answers_later_than_the_poll_timeout_within_the_death_window_are_no_death(
    sim_factory: Any,
    subscriber: Subscriber,
    gateway_factory: Any,
    caplog: pytest.LogCaptureFixture,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Every answer 0.15 s late: 3 x the poll timeout, well within the death window. The window is
    roomier than the product's 0.2 s (a loaded test machine holds the in-process simulator's answers
    longer now and then; timing.GATEWAY_DEATH_AFTER, read when the gateway is made); the old rule (a
    DDEATH at the first poll past the poll timeout) DDEATHed it at once whatever the window."""
    monkeypatch.setattr(timing, "GATEWAY_DEATH_AFTER", DEATH_WINDOW, raising=False)
    sims = {"R1": sim_factory()}
    node = gateway_factory(sims, poll_timeout=0.05)
    subscriber.kind("DBIRTH", "R1")
    start = subscriber.count()
    sims["R1"].set_response_delay(0.15)
    answers = node.answers
    # 20 answered polls, or a death (the old rule's, at once)
    wait_until(
        lambda: node.answers >= answers + 20 or _dies_since(subscriber, start, "R1"),
        "20 more answered polls",
        timeout=30.0,
    )
    late = [
        m.kind for m in subscriber.snapshot()[start:] if m.device == "R1" and m.kind in ("DDEATH", "DBIRTH")
    ]
    said = [r.getMessage() for r in caplog.records if "stopped answering" in r.getMessage()]
    assert late == [], f"R1 answered late but within the death window, yet the subscriber saw {late}: {said}"
    # it is still polled and published (its RTT shows the delay), and a silence is still a death
    silent_at = time.monotonic()
    sims["R1"].set_silent(True)
    death = subscriber.kind("DDEATH", "R1", start=start)
    assert death.at - silent_at <= DEATH_WINDOW + 1.0


def test_a_sigstopped_controller_is_dead_within_250_ms(
    sim_process: SimProcess, sim_factory: Any, subscriber: Subscriber, gateway_factory: Any, tmp_path: Path
) -> None:
    """The product's clocks (its poll rate, the TCP poll timeout, the death window): SIGSTOP of the
    simulator's process, DDEATH at the subscriber within 250 ms; SIGCONT, DBIRTH again."""
    from app.gateway.poller import GatewayTiming

    defaults = GatewayTiming()
    product = {"poll_hz": defaults.poll_hz, "poll_timeout": None, "backoff": (0.05,)}
    sims = {"R1": sim_factory(), "R2": _Port(sim_process.port)}
    gateway_factory(sims, **product)
    subscriber.kind("DBIRTH", "R2")
    took = []
    for _round in range(3):
        start = subscriber.count()
        wait_until(lambda: _data_since(subscriber, start, "R2"), "a DDATA of R2 (it answers)")  # noqa: B023
        stopped_at = time.monotonic()
        os.kill(sim_process.pid, signal.SIGSTOP)
        death = subscriber.kind("DDEATH", "R2", start=start)
        took.append(death.at - stopped_at)
        os.kill(sim_process.pid, signal.SIGCONT)
        subscriber.kind("DBIRTH", "R2", start=subscriber.messages.index(death))
    assert max(took) <= DDEATH_BOUND, f"DDEATH {[round(t * 1000) for t in took]} ms after SIGSTOP"
    assert not [m for m in subscriber.snapshot() if m.kind == "DDEATH" and m.device == "R1"]


class _Port:
    """A simulator in another process, as write_cell needs it (its port)."""

    def __init__(self, port: int) -> None:
        self.port = port


def _data_since(subscriber: Subscriber, start: int, device: str) -> bool:
    return any(m.kind == "DDATA" and m.device == device for m in subscriber.snapshot()[start:])


def _dies_since(subscriber: Subscriber, start: int, device: str) -> bool:
    return any(m.kind == "DDEATH" and m.device == device for m in subscriber.snapshot()[start:])
