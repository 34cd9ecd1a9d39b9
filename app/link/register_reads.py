"""Reads of whole register blocks, write-free: the worker's part that runs
:class:`~app.link.ops.ReadRegisters`, and the same reads for a plain client (teachpad-cli).

A block the controller refuses (a Modbus exception: a register it does not serve) is kept as
refused, with its exception code, and the other blocks are still read: whoever asked decides what
a missing block means (the register-map self-test says "not checked"). A link failure (no
answer, a malformed one) ends the reads and is raised, as every read of the link does.
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Protocol

from app.errors import ModbusExceptionError
from app.link.ops import Handlers, ReadRegisters
from app.protocol.exceptions import GATEWAY_EXCEPTIONS

__all__ = ["BlockReader", "RegisterBlocks", "RegisterReads", "RegistersHost", "read_blocks"]


@dataclass(frozen=True)
class RegisterBlocks:
    """What a :class:`~app.link.ops.ReadRegisters` read: ``values`` register -> value of every
    block read, ``refused`` first register of a refused block -> its Modbus exception code,
    ``read_at`` the PC's clock (``time.time()``) when the first block was asked for."""

    blocks: tuple[tuple[int, int], ...]
    values: Mapping[int, int] = field(default_factory=dict)
    refused: Mapping[int, int] = field(default_factory=dict)
    read_at: float = 0.0
    request_id: int | None = None

    def block(self, start: int, count: int) -> list[int] | None:
        """The registers ``start .. start+count-1``, or None when any of them was not read."""
        try:
            return [self.values[start + i] for i in range(count)]
        except KeyError:
            return None

    def refusal(self, start: int, count: int) -> int | None:
        """The exception code of a refused block that overlaps ``start .. start+count-1``."""
        for (first, n), code in ((b, self.refused[b[0]]) for b in self.blocks if b[0] in self.refused):
            if first < start + count and start < first + n:
                return code
        return None


class BlockReader(Protocol):
    """What :func:`read_blocks` uses of a client (:class:`~app.link.client.RobotClient`)."""

    def read_registers(self, addr: int, count: int) -> list[int]: ...


def read_blocks(client: BlockReader, blocks: Sequence[tuple[int, int]]) -> RegisterBlocks:
    """Read every block with 0x03 (nothing is written); see the module docstring."""
    read_at = time.time()
    values: dict[int, int] = {}
    refused: dict[int, int] = {}
    for start, count in blocks:
        try:
            regs = client.read_registers(start, count)
        except ModbusExceptionError as exc:
            if exc.exception_code in GATEWAY_EXCEPTIONS:
                raise  # nothing answers at this unit id: the link, not the block
            refused[start] = exc.exception_code
            continue
        values.update((start + i, int(v) & 0xFFFF) for i, v in enumerate(regs))
    return RegisterBlocks(tuple(blocks), values, refused, read_at)


class RegistersHost(Protocol):
    """What the part uses of the worker (worker thread)."""

    @property
    def request_id(self) -> int | None: ...

    def client_or_raise(self) -> BlockReader: ...

    def publish_registers(self, blocks: RegisterBlocks) -> None: ...


class RegisterReads:
    """The worker's part that runs :class:`~app.link.ops.ReadRegisters` (worker thread only)."""

    def __init__(self, host: RegistersHost) -> None:
        self._host = host

    def register(self, handlers: Handlers) -> None:
        handlers.add(ReadRegisters, self.read)

    def read(self, op: ReadRegisters) -> None:
        got = read_blocks(self._host.client_or_raise(), op.blocks)
        self._host.publish_registers(
            RegisterBlocks(got.blocks, got.values, got.refused, got.read_at, self._host.request_id)
        )
