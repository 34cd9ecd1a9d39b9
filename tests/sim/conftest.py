"""A bare pymodbus client speaking to the simulator (the project's RobotClient is not used here)."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from typing import Any

import pytest
from pymodbus.client import ModbusTcpClient
from pymodbus.framer import FramerType

from app.protocol.codec import WordOrder, decode_floats, encode_floats
from app.protocol.enums import decode_status_registers
from app.protocol.registers import GV_COMMAND_STATUS, GV_JOINTS, GV_POSE, gv_reg


class Bus:
    """Raw register access plus the few helpers the tests need."""

    def __init__(
        self,
        port: int,
        *,
        order: WordOrder = WordOrder.LOW_FIRST,
        rtu: bool = False,
        timeout: float = 1.0,
        unit: int = 1,
    ) -> None:
        self.order = order
        self.unit = unit
        self.client = ModbusTcpClient(
            "127.0.0.1",
            port=port,
            timeout=timeout,
            retries=0,
            framer=FramerType.RTU if rtu else FramerType.SOCKET,
        )
        assert self.client.connect()

    def close(self) -> None:
        self.client.close()

    def read(self, address: int, count: int = 1) -> list[int]:
        rr = self.client.read_holding_registers(address, count=count, device_id=self.unit)
        assert not rr.isError(), rr
        return list(rr.registers)

    def write(self, address: int, value: int) -> None:
        rr = self.client.write_register(address, value, device_id=self.unit)
        assert not rr.isError(), rr

    def write_regs(self, address: int, values: list[int]) -> None:
        rr = self.client.write_registers(address, values, device_id=self.unit)
        assert not rr.isError(), rr

    def gv(self, n: int, count: int = 1) -> list[float]:
        return decode_floats(self.read(gv_reg(n), 2 * count), self.order)

    def set_gv(self, n: int, values: list[float]) -> None:
        self.write_regs(gv_reg(n), encode_floats(values, self.order))

    def status(self) -> int:
        return decode_status_registers(self.read(gv_reg(GV_COMMAND_STATUS), 2), self.order)

    def pose(self) -> list[float]:
        return self.gv(GV_POSE, 6)

    def joints(self) -> list[float]:
        return self.gv(GV_JOINTS, 6)

    def mode(self) -> int:
        return self.read(560)[0]

    def program_state(self) -> int:
        return self.read(561)[0]

    def alarms(self) -> int:
        return self.read(562)[0]


def poll(read: Callable[[], Any], pred: Callable[[Any], bool], timeout: float = 5.0) -> Any:
    """Call ``read`` until ``pred`` holds on its value; fail after ``timeout`` seconds."""
    deadline = time.monotonic() + timeout
    while True:
        value = read()
        if pred(value):
            return value
        assert time.monotonic() < deadline, f"timed out; last value {value!r}"
        time.sleep(0.002)


@pytest.fixture
def bus(sim: Any) -> Iterator[Bus]:
    b = Bus(sim.port)
    try:
        yield b
    finally:
        b.close()


@pytest.fixture
def make_bus() -> Iterator[Callable[..., Bus]]:
    made: list[Bus] = []

    def make(port: int, **kwargs: Any) -> Bus:
        b = Bus(port, **kwargs)
        made.append(b)
        return b

    try:
        yield make
    finally:
        for b in made:
            b.close()


@pytest.fixture(autouse=True)
def _collect_garbage() -> Iterator[None]:
    """Collect after each test so a leaked socket or transport is blamed on its own test."""
    yield
    import gc

    gc.collect()
