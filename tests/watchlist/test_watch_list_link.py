"""The watch list through the real link: values read after the pose match what the simulator
holds (float32 in both word orders, int16 negative, bits), freshness, the slow lane, an
engineer's write through the write guard and its refusal in monitor-only mode at the simulator."""

from __future__ import annotations

import time
from typing import Any

import pytest

from app.connection import ConnectionSettings
from app.link.client import RobotClient
from app.link.ops import SetWatchList, WriteWatched
from app.link.robot_link import RobotLink
from app.link.types import WorkerError
from app.models import CommandResult
from app.protocol.codec import WordOrder
from app.watchlist import plan as budget
from app.watchlist.entry import Source, ValueType, WatchEntry
from app.watchlist.plan import WatchReadings
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    SIGNAL_TIMEOUT_MS,
    connect,
    fast_reconnect_fixture,
    link_fixture,
)

pytestmark = pytest.mark.timeout(60)

GV10 = WatchEntry.make(Source.GV, 10, name="tool length")
GV11 = WatchEntry.make(Source.GV, 11)
REG_NEG = WatchEntry.make(Source.REGISTER, 40, ValueType.INT16)
REG_BITS = WatchEntry.make(Source.REGISTER, 41, ValueType.BITS, "flags")


def _setup(sim: Any, order: WordOrder) -> None:
    """The values the simulator holds, written by a client of the test (not the link under test)."""
    with RobotClient(ConnectionSettings(host="127.0.0.1", port=sim.port, word_order=order)) as client:
        client.write_gv(10, [12.5, -3.25])
        client.write_registers(40, [(-1234) & 0xFFFF, 0b1010_0000_0000_0101])


def _latest(link: RobotLink) -> dict[WatchEntry, Any]:
    seen: dict[WatchEntry, Any] = {}

    def keep(readings: WatchReadings) -> None:
        for value in readings.values:
            seen[value.entry] = value

    link.watchRead.connect(keep)
    return seen


@pytest.mark.parametrize("order", [WordOrder.LOW_FIRST, WordOrder.HIGH_FIRST])
def test_values_match_the_simulator(qtbot: Any, sim_factory: Any, link: RobotLink, order: WordOrder) -> None:
    sim = sim_factory(word_order=order)
    _setup(sim, order)
    seen = _latest(link)
    connect(qtbot, link, sim, word_order=order)
    link.submit(SetWatchList((GV10, GV11, REG_NEG, REG_BITS), generation=1))
    qtbot.waitUntil(lambda: len(seen) == 4, timeout=SIGNAL_TIMEOUT_MS)
    assert seen[GV10].value == 12.5
    assert seen[GV11].value == -3.25
    assert seen[REG_NEG].value == -1234
    assert seen[REG_BITS].value == 0b1010_0000_0000_0101
    assert all(v.error is None for v in seen.values())


def test_freshness_and_an_empty_list_reads_nothing(qtbot: Any, sim: Any, link: RobotLink) -> None:
    readings: list[WatchReadings] = []
    link.watchRead.connect(readings.append)
    connect(qtbot, link, sim)
    link.submit(SetWatchList((GV10,), generation=1))
    qtbot.waitUntil(lambda: len(readings) >= 3, timeout=SIGNAL_TIMEOUT_MS)
    stamps = [r.values[0].read_at for r in readings[:3]]
    assert stamps == sorted(stamps) and stamps[0] < stamps[-1]  # each poll a newer reading
    assert time.monotonic() - readings[-1].values[0].read_at < 2.0
    link.submit(SetWatchList((), generation=2))
    qtbot.waitUntil(lambda: link.state.fresh, timeout=SIGNAL_TIMEOUT_MS)
    count = len(readings)
    requests = sim.requests_count
    qtbot.waitUntil(lambda: sim.requests_count >= requests + 20, timeout=SIGNAL_TIMEOUT_MS)
    assert all(r.generation == 1 for r in readings)  # the empty list published nothing
    assert len(readings) <= count + 1  # (at most one poll under way when the empty list came)


def test_a_long_list_reads_its_rest_on_the_slow_clock(
    qtbot: Any, sim: Any, link: RobotLink, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(budget, "SLOW_PERIOD", 0.2)
    entries = tuple(WatchEntry.make(Source.GV, n) for n in range(0, 400, 20))  # 20 far-apart GVs
    stamps: dict[WatchEntry, list[float]] = {}

    def keep(readings: WatchReadings) -> None:
        for value in readings.values:
            stamps.setdefault(value.entry, []).append(value.read_at)

    link.watchRead.connect(keep)
    connect(qtbot, link, sim)
    link.submit(SetWatchList(entries, generation=1))
    qtbot.waitUntil(lambda: len(stamps) == len(entries), timeout=SIGNAL_TIMEOUT_MS)
    first, last = entries[0], entries[-1]
    qtbot.waitUntil(lambda: len(stamps[last]) >= 2, timeout=SIGNAL_TIMEOUT_MS)
    assert len(stamps[first]) > 3 * len(stamps[last])  # the fast lane every poll, the rest slower
    gaps = [b - a for a, b in zip(stamps[last], stamps[last][1:], strict=False)]
    assert min(gaps) >= 0.2 - 0.02


def test_a_register_the_controller_lacks_is_an_error_not_a_failed_poll(
    qtbot: Any, sim: Any, link: RobotLink
) -> None:
    seen = _latest(link)
    errors: list[WorkerError] = []
    link.errorOccurred.connect(errors.append)
    connect(qtbot, link, sim)
    missing = WatchEntry.make(Source.REGISTER, 60000)
    link.submit(SetWatchList((GV10, missing), generation=1))
    qtbot.waitUntil(lambda: len(seen) == 2, timeout=SIGNAL_TIMEOUT_MS)
    assert seen[missing].value is None and seen[missing].error
    assert seen[GV10].error is None
    assert link.state.fresh and not errors


def test_monitor_only_refuses_the_write_before_the_wire(qtbot: Any, sim: Any, link: RobotLink) -> None:
    errors: list[WorkerError] = []
    link.errorOccurred.connect(errors.append)
    connect(qtbot, link, sim, monitor_only=True)
    with qtbot.waitSignal(link.errorOccurred, timeout=SIGNAL_TIMEOUT_MS):
        link.submit(WriteWatched(GV10, 7.5))
    assert "monitor-only" in errors[-1].message
    assert sim.writes == []  # at the simulator: nothing written


def test_a_write_reaches_the_simulator_and_is_read_back(qtbot: Any, sim: Any, link: RobotLink) -> None:
    seen = _latest(link)
    results: list[CommandResult] = []
    link.commandFinished.connect(results.append)
    connect(qtbot, link, sim)
    link.submit(SetWatchList((GV10, REG_NEG), generation=1))
    with qtbot.waitSignal(link.commandFinished, timeout=SIGNAL_TIMEOUT_MS):
        link.submit(WriteWatched(GV10, 7.5))
    assert results[-1].ok
    with qtbot.waitSignal(link.commandFinished, timeout=SIGNAL_TIMEOUT_MS):
        link.submit(WriteWatched(REG_NEG, -2))
    qtbot.waitUntil(lambda: REG_NEG in seen and seen[REG_NEG].value == -2, timeout=SIGNAL_TIMEOUT_MS)
    assert seen[GV10].value == 7.5
    writes = [(w.function_code, w.address, w.values) for w in sim.writes]
    assert writes == [(0x10, 20, (0, 0x40F0)), (0x06, 40, (0xFFFE,))]


def test_control_registers_are_not_written_from_the_watch_list(qtbot: Any, sim: Any, link: RobotLink) -> None:
    connect(qtbot, link, sim)
    with qtbot.waitSignal(link.errorOccurred, timeout=SIGNAL_TIMEOUT_MS) as blocker:
        link.submit(WriteWatched(WatchEntry.make(Source.REGISTER, 440), 1))
    assert "440..445" in blocker.args[0].message
    assert sim.writes == []


def test_values_inside_the_polls_own_reads_cost_no_read(sim: Any, make_client: Any) -> None:
    """The mode and alarm registers (status block) and the live X (pose block) are decoded from the
    poll's own reads: the watch list sends nothing more for them."""
    from typing import cast

    from app.link.watch_list import WatchListReader

    mode = WatchEntry.make(Source.REGISTER, 560)
    alarms = WatchEntry.make(Source.REGISTER, 562, ValueType.BITS)
    x = WatchEntry.make(Source.GV, 206)
    reader = WatchListReader(cast(Any, None), lambda _readings: None)
    reader.set_list(SetWatchList((mode, x, alarms, GV10)))
    assert set(reader.plan.served) == {mode, x, alarms}
    client = make_client(sim)
    client.read_status(timeout=1.0)
    client.read_pose(timeout=1.0)
    before = sim.requests_count
    readings = reader.read(client, 1.0)
    assert readings is not None
    assert sim.requests_count == before + 1  # GV10's read only
    got = {v.entry: v.value for v in readings.values}
    state = sim.state()
    assert got[mode] == int(state.mode) and got[alarms] == int(state.alarms)
    assert got[x] == pytest.approx(state.pose[0], abs=1e-3)
