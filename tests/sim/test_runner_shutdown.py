"""The simulator's server thread never outlives a start that gave up, nor a stop."""

from __future__ import annotations

import asyncio
import threading
from typing import Any

import pytest

from app.sim.config import SimConfig
from app.sim.server import SimController
from app.sim.transport import ServerRunner


def _sim_threads() -> list[threading.Thread]:
    return [t for t in threading.enumerate() if t.name in ("sim-modbus", "sim-ticker")]


def test_a_start_that_times_out_leaves_no_server_running(monkeypatch: pytest.MonkeyPatch) -> None:
    before = set(_sim_threads())
    monkeypatch.setattr(ServerRunner, "START_TIMEOUT", 0.05)
    release = threading.Event()
    sim = SimController(SimConfig(host="127.0.0.1", port=0))
    real_serve = sim._serve

    async def slow_serve() -> Any:
        while not release.is_set():  # a starved machine: listening takes longer than allowed
            await asyncio.sleep(0.01)
        return await real_serve()

    monkeypatch.setattr(sim, "_serve", slow_serve)
    with pytest.raises(OSError, match=r"could not listen on 127.0.0.1:0: timeout \(0.05 s\)"):
        sim.start()
    release.set()
    left = [t for t in _sim_threads() if t not in before]
    for thread in left:
        thread.join(5.0)
    assert not [t for t in left if t.is_alive()], "the server's loop kept running after the start gave up"
    assert not sim.running
    sim.stop()  # harmless


def test_stop_twice_and_after_the_loop_closed(sim_factory: Any) -> None:
    sim = sim_factory()
    sim.stop()
    sim.stop()
    assert not sim.running
    server_thread = sim._runner._thread
    assert server_thread is not None and not server_thread.is_alive()
