"""Reads of whole register blocks, write-free: the worker's part that runs
:class:`~app.link.ops.ReadRegisters`, and the same reads for a plain client (teachpad-cli).

A block the controller refuses (a Modbus exception: a register it does not serve) is kept as
refused, with its exception code, and the other blocks are still read: whoever asked decides what
a missing block means (the register-map self-test says "not checked"). A link failure (no
answer, a malformed one) ends the reads and is raised, as every read of the link does.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from typing import Protocol

from app.errors import ModbusExceptionError
from app.link.ops import Handlers, ReadRegisters
from app.link.progress import Progress, RegisterBlocks
from app.protocol.exceptions import GATEWAY_EXCEPTIONS

__all__ = ["BlockReader", "RegisterReads", "RegistersHost", "read_blocks"]


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

    def publish_progress(self, ticket: int | None, progress: Progress) -> None: ...


class RegisterReads:
    """The worker's part that runs :class:`~app.link.ops.ReadRegisters` (worker thread only)."""

    def __init__(self, host: RegistersHost) -> None:
        self._host = host

    def register(self, handlers: Handlers) -> None:
        handlers.add(ReadRegisters, self.read)

    def read(self, op: ReadRegisters) -> None:
        got = read_blocks(self._host.client_or_raise(), op.blocks)
        ticket = self._host.request_id
        self._host.publish_progress(
            ticket, RegisterBlocks(got.blocks, got.values, got.refused, got.read_at, ticket)
        )
