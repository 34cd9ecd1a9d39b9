"""The simulator's GV291 timing profiles and GV291 write modes, seen by a bare Modbus client."""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

import pytest
from pymodbus.constants import ExcCodes

from app import timing
from app.protocol.codec import encode_floats
from app.protocol.enums import STATUS_SENTINEL
from app.protocol.registers import GV_COMMAND_STATUS, GV_PARAM0, gv_reg
from app.sim.cli import build_parser
from app.sim.config import SimConfig
from tests.sim.conftest import Bus, poll

CREATE = 0xE0
GV291 = gv_reg(GV_COMMAND_STATUS)


def create(bus: Bus, point_id: int) -> None:
    bus.set_gv(GV_PARAM0, [float(point_id), 0.0])  # from the current pose
    bus.write(440, CREATE)


def codes_until_done(bus: Bus, timeout: float = 2.0) -> list[int]:
    """Every GV291 value read back to back until a terminal code other than the sentinel."""
    seen = [bus.status()]
    deadline = time.monotonic() + timeout
    while seen[-1] in (0, STATUS_SENTINEL) and time.monotonic() < deadline:
        seen.append(bus.status())
    return seen


def test_fast_profile_shows_the_result_at_once_and_never_the_zero(sim_factory: Any,
                                                                    make_bus: Callable[..., Bus]) -> None:
    sim = sim_factory(timing="fast")
    bus = make_bus(sim.port)
    for pid in range(1, 6):
        create(bus, pid)
        assert bus.status() == 0xFF  # the very next read: one scan, no 0, no read-hold
    create(bus, 20000)  # out of range: the error replaces 0xFF at once
    assert bus.status() == 1


def test_classic_profile_holds_the_zero_until_read(sim_factory: Any, make_bus: Callable[..., Bus]) -> None:
    sim = sim_factory(timing="classic", command_latency=0.0)
    bus = make_bus(sim.port)
    create(bus, 1)
    time.sleep(0.02)  # a slow reader still sees the 0 (the classic read-hold)
    assert codes_until_done(bus)[0] == 0


def test_slow_profile_keeps_the_old_code_then_zero_with_jitter(sim_factory: Any,
                                                              make_bus: Callable[..., Bus]) -> None:
    sim = sim_factory(timing="slow", seed=1)
    bus = make_bus(sim.port)
    create(bus, 1)
    poll(bus.status, lambda code: code == 0xFF)
    pickups = []
    for pid in (2, 3, 4, 5):
        create(bus, pid)
        t0 = time.monotonic()
        seen = [bus.status()]
        while seen[-1] != 0:  # the old 0xFF first (nothing taken yet), then 0
            seen.append(bus.status())
            assert time.monotonic() - t0 < 1.0, seen
        pickups.append(time.monotonic() - t0)
        assert seen[0] == 0xFF
        assert poll(bus.status, lambda code: code != 0) == 0xFF
    lo, hi = timing.SIM_SLOW_PICKUP
    assert all(lo * 0.8 <= t <= hi + 0.05 for t in pickups), pickups  # tens of ms
    assert max(pickups) - min(pickups) > 0.002, pickups  # jitter


def test_gv291_writable_keeps_the_host_value_until_the_next_result(sim_factory: Any,
                                                                     make_bus: Callable[..., Bus]) -> None:
    sim = sim_factory(timing="fast", gv291="writable")
    bus = make_bus(sim.port)
    bus.write_regs(GV291, encode_floats([float(STATUS_SENTINEL)], bus.order))
    assert bus.status() == STATUS_SENTINEL and sim.state().command_status == STATUS_SENTINEL
    time.sleep(0.03)
    assert bus.status() == STATUS_SENTINEL  # scans go by: the host's value stays
    create(bus, 1)
    assert bus.status() == 0xFF  # the controller's own write


def test_gv291_ignored_acknowledges_and_overwrites(sim_factory: Any, make_bus: Callable[..., Bus]) -> None:
    sim = sim_factory(gv291="ignored")
    bus = make_bus(sim.port)
    bus.write_regs(GV291, encode_floats([float(STATUS_SENTINEL)], bus.order))  # no exception
    assert bus.status() == 0


def test_gv291_read_only_answers_exception_2(sim_factory: Any, make_bus: Callable[..., Bus]) -> None:
    sim = sim_factory(gv291="read-only")
    bus = make_bus(sim.port)
    rr = bus.client.write_registers(GV291, encode_floats([165.0], bus.order), device_id=1)
    assert rr.isError() and rr.exception_code == ExcCodes.ILLEGAL_ADDRESS
    rr = bus.client.write_register(GV291 + 1, 1, device_id=1)
    assert rr.isError() and rr.exception_code == ExcCodes.ILLEGAL_ADDRESS
    assert bus.status() == 0 and sim.writes_to(GV291)  # refused, and logged as received


def test_bad_profile_names_are_refused_and_the_cli_takes_them() -> None:
    with pytest.raises(ValueError, match="timing must be one of"):
        SimConfig(timing="turbo")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="gv291 must be one of"):
        SimConfig(gv291="maybe")  # type: ignore[arg-type]
    args = build_parser().parse_args(["--timing", "fast", "--gv291", "read-only", "--seed", "3",
                                      "--refuse-point", "5", "--refuse-point", "9"])
    assert (args.timing, args.gv291, args.seed, args.refuse_point) == ("fast", "read-only", 3, [5, 9])
