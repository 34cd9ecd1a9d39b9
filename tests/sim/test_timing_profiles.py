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
from app.sim.status import StatusPublisher
from tests.sim.conftest import Bus

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


def test_fast_profile_shows_the_result_at_once_and_never_the_zero(
    sim_factory: Any, make_bus: Callable[..., Bus]
) -> None:
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


def test_slow_profile_keeps_the_old_code_then_zero_with_jitter() -> None:
    """The slow profile's schedule, on the simulator's own clock: the old code for a seeded pickup
    of tens of ms, then 0 for a few ms, then the result; the pickups differ (jitter). (Timed at the
    wire from the host, a loaded test machine reads late and the check measured the host, not the
    simulator; the wire order is covered by the client tests over all nine profiles.)"""
    publisher = StatusPublisher("slow", command_latency=0.001, seed=1)
    lo, hi = timing.SIM_SLOW_PICKUP
    zlo, zhi = timing.SIM_SLOW_ZERO
    pickups = []
    for start in (10.0, 20.0, 30.0, 40.0):
        publisher.hold(start, 0xFF, pickup=0.0, latency=True, read_hold=True)
        samples = [(start + k * 0.0005, publisher.published(start + k * 0.0005, 0xFF)) for k in range(200)]
        zero = [t for t, code in samples if code == 0]
        assert samples[0][1] == 0xFF and zero, samples[:5]  # the old code first, then 0
        pickup = zero[0] - start
        assert lo - 0.0005 <= pickup <= hi + 0.0005
        assert zlo - 0.001 <= zero[-1] - zero[0] + 0.0005 <= zhi + 0.001
        assert samples[-1][1] == 0xFF  # then the result
        assert all(code in (0, 0xFF) for _, code in samples)
        pickups.append(pickup)
    assert max(pickups) - min(pickups) > 0.002, pickups  # jitter


def test_gv291_writable_keeps_the_host_value_until_the_next_result(
    sim_factory: Any, make_bus: Callable[..., Bus]
) -> None:
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
    args = build_parser().parse_args(
        [
            "--timing",
            "fast",
            "--gv291",
            "read-only",
            "--seed",
            "3",
            "--refuse-point",
            "5",
            "--refuse-point",
            "9",
        ]
    )
    assert (args.timing, args.gv291, args.seed, args.refuse_point) == ("fast", "read-only", 3, [5, 9])
