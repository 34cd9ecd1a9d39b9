"""The stop line (app/link/stop_line.py): a second connection kept for Stop, asserted at the simulator."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any, ClassVar

import pytest

from app.connection import ConnectionSettings
from app.link import stop_line as stop_line_module
from app.link.ops import LinkOp, Stop
from app.link.robot_link import RobotLink
from app.link.stop_line import StopLine
from app.models import CommandResult
from app.protocol import registers
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    SIGNAL_TIMEOUT_MS,
    connect,
    fast_reconnect_fixture,
    link_fixture,
    register_writes,
)
from tests.waits import join

pytestmark = pytest.mark.timeout(60)


def _settings(sim: Any, **overrides: Any) -> ConnectionSettings:
    # the line reads its answers with the poll timeout: roomy (1 s, as the link harness), since a
    # loaded test process can hold the simulator's answer past the product's 0.15 s and the line
    # would rightly be judged dead; the silence test passes its own short one
    values = {"host": "127.0.0.1", "port": sim.port, "unit": sim.config.unit, "poll_timeout": 1.0}
    return ConnectionSettings(**{**values, **overrides})


@pytest.fixture(name="line")
def line_fixture() -> Iterator[StopLine]:
    line = StopLine()
    yield line
    line.close()


def _stops(sim: Any) -> int:
    return len(register_writes(sim, registers.REG_STOP))


def test_a_stop_sent_from_another_thread_reaches_the_simulator(sim: Any, line: StopLine) -> None:
    line.reset(_settings(sim))
    line.maintain(time.monotonic())
    assert line.up and line.why_not == ""
    sent: list[Any] = []
    thread = threading.Thread(target=lambda: sent.append(line.send_stop()))
    thread.start()
    join(thread, "the thread sending the stop")
    assert sent[0] is not None
    assert sim.wait_for(lambda _s: _stops(sim) == 1, 2.0)
    assert line.send_stop() is None  # the first one's answer is not read yet: no second one
    got, answer, problem = line.collect()
    assert got == sent[0] and problem is None
    assert answer[7] == 0x06 and int.from_bytes(answer[8:10], "big") == registers.REG_STOP
    assert line.up


def test_no_line_in_monitor_only_mode_or_on_a_serial_line(sim: Any, line: StopLine) -> None:
    for settings in (_settings(sim, monitor_only=True), _settings(sim, serial_port="/dev/null")):
        line.reset(settings)
        line.maintain(time.monotonic())
        assert not line.up and line.send_stop() is None
    assert sim.writes == []


def test_a_silent_controller_gets_no_line_and_is_tried_again_later(sim: Any, line: StopLine) -> None:
    sim.set_silent(True)
    line.reset(_settings(sim, poll_timeout=0.05))
    now = time.monotonic()
    line.maintain(now)
    assert not line.up and "no good answer" in line.why_not
    assert line.send_stop() is None
    sim.set_silent(False)
    line.maintain(now + 0.5)  # before the retry delay: not tried
    assert not line.up
    line.maintain(now + stop_line_module.RETRY_DELAYS[0] + 0.01)
    assert line.up


def test_a_main_link_lost_right_after_the_line_opened_turns_it_off(sim: Any, line: StopLine) -> None:
    """A controller that keeps one connection (the newest) would drop the main link: no line then."""
    line.reset(_settings(sim))
    now = time.monotonic()
    line.maintain(now)
    assert line.up
    line.main_link_closed(now + 0.1, lost=False)  # closed on purpose: not a verdict
    assert not line.up and line.enabled
    line.maintain(now + 0.2)
    assert line.up
    line.main_link_closed(now + 0.3, lost=True)
    assert not line.up and not line.enabled and "one connection" in line.why_not
    line.maintain(now + 100.0)
    assert not line.up
    line.reset(_settings(sim))  # a new connection decides again
    assert line.enabled


def test_the_keepalive_notices_a_closed_line(sim: Any, line: StopLine) -> None:
    line.reset(_settings(sim))
    now = time.monotonic()
    line.maintain(now)
    assert line.up
    sim.drop_connections()
    assert sim.wait_for(lambda _s: True, 0.05)
    line.maintain(now + stop_line_module.KEEPALIVE + 0.01)
    assert not line.up and "keepalive" in line.why_not


@dataclass(frozen=True)
class _Hold(LinkOp):
    """A test's own operation: runs ``run`` in the worker thread (needs no link)."""

    needs_link: ClassVar[bool] = False
    run: Callable[[], None]


def _hold_worker(link: RobotLink) -> threading.Event:
    """Keep the worker thread busy inside a job until the returned event is set."""
    gate = threading.Event()
    entered = threading.Event()

    def hold() -> None:
        entered.set()
        gate.wait(10.0)

    worker = link._worker
    if _Hold not in worker.handlers:
        worker.handlers.add(_Hold, lambda op: op.run())
    worker.submit(_Hold(hold))
    assert entered.wait(5.0)
    return gate


def _wait_line_open(qtbot: Any, link: RobotLink) -> None:
    qtbot.waitUntil(lambda: link._worker.stop_line.up, timeout=SIGNAL_TIMEOUT_MS)


def test_a_gui_stop_does_not_wait_for_a_busy_worker(qtbot: Any, sim: Any, link: RobotLink) -> None:
    connect(qtbot, link, sim)
    _wait_line_open(qtbot, link)
    results: list[CommandResult] = []
    link.commandFinished.connect(results.append)
    gate = _hold_worker(link)
    try:
        stop_id = link.submit(Stop())
        # written while the worker thread is still inside its job
        assert sim.wait_for(lambda _s: _stops(sim) == 1, 2.0)
        assert not any(r.request_id == stop_id for r in results)
    finally:
        gate.set()
    # then the worker's own copy on the main link, and the stop's result
    qtbot.waitUntil(lambda: any(r.request_id == stop_id for r in results), timeout=SIGNAL_TIMEOUT_MS)
    assert _stops(sim) == 2
    assert [r.message for r in results if r.request_id == stop_id] == ["stop: sent"]


def test_without_the_line_a_stop_waits_for_the_worker(qtbot: Any, sim: Any) -> None:
    link = RobotLink(canary_gv=None, stop_line=False)
    try:
        connect(qtbot, link, sim)
        gate = _hold_worker(link)
        try:
            link.submit(Stop())
            assert not sim.wait_for(lambda _s: _stops(sim) > 0, 0.2)
        finally:
            gate.set()
        assert sim.wait_for(lambda _s: _stops(sim) == 1, 2.0)
        assert not link._worker.stop_line.up
    finally:
        link.shutdown()
