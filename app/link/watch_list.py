"""The watch list's part of the worker: its reads after the pose, and an engineer's write.

:class:`WatchListReader` holds the list the GUI last submitted (:class:`~app.link.ops.SetWatchList`)
as a :class:`~app.watchlist.plan.ReadPlan`. The poller asks it, after the pose block of every
poll, for :meth:`WatchListReader.read` (the fast lane every poll, one slow block when due; nothing
at all for an empty list) and hands what it read to :meth:`WatchListReader.publish` with the
poll's other data. :class:`~app.link.ops.WriteWatched` goes through the client's one write guard
(``RegisterClient._write``: monitor-only refuses it before the wire, the audit records it), then
the value is read back and published. Worker thread only; Qt-free.
"""

from __future__ import annotations

import time
from collections.abc import Callable

from app.errors import InvalidInput, Reason
from app.link.client import RobotClient
from app.link.host import PartLink
from app.link.ops import Handlers, SetWatchList, WriteWatched
from app.models import CommandResult
from app.protocol import registers
from app.watchlist import plan as budget
from app.watchlist.entry import WatchEntry, WatchValue, format_value
from app.watchlist.plan import POLL_BLOCKS, Block, ReadPlan, WatchReadings, decode_block, read_blocks

__all__ = ["WatchListReader"]

_CONTROL = range(registers.REG_RUN_COMMAND, registers.REG_GO_ZERO + 1)  # 440..445: the commands


class WatchListReader:
    """See the module docstring. ``publish`` gets each poll's :class:`WatchReadings`."""

    def __init__(self, host: PartLink, publish: Callable[[WatchReadings], None]) -> None:
        self._host = host
        self._publish = publish
        self.plan = ReadPlan.of(())
        self.generation = 0
        self._slow_read_at: dict[Block, float] = {}

    def register(self, handlers: Handlers) -> None:
        handlers.add(SetWatchList, self.set_list)
        handlers.add(WriteWatched, self.write)

    @property
    def active(self) -> bool:
        return not self.plan.empty

    def set_list(self, op: SetWatchList) -> None:
        self.plan = ReadPlan.of(op.entries)
        self.generation = op.generation
        self._slow_read_at = {}

    def read(self, client: RobotClient, timeout: float) -> WatchReadings | None:
        """The entries inside the poll's own reads (decoded from them: no read), the fast lane and
        at most :data:`~app.watchlist.plan.SLOW_READS_PER_POLL` slow blocks that are due (the least
        recently read first); None for an empty list."""
        plan = self.plan
        if plan.empty:
            return None
        served = self._served(client) if plan.served else []
        blocks = list(plan.fast)
        now = time.monotonic()
        due = sorted(
            (b for b in plan.slow if now - self._slow_read_at.get(b, -1e9) >= budget.SLOW_PERIOD),
            key=lambda b: self._slow_read_at.get(b, -1e9),
        )[: budget.SLOW_READS_PER_POLL]
        for block in due:
            self._slow_read_at[block] = now
        blocks.extend(due)
        if not blocks and not served:
            return None
        with client.io_timeout(timeout):  # the poll's timeout, not the command's
            values = read_blocks(client.read_registers, blocks, plan.entries, client.settings.word_order)
        return WatchReadings(self.generation, (*served, *values))

    def _served(self, client: RobotClient) -> list[WatchValue]:
        """The entries inside the status and pose blocks this poll has just read."""
        now = time.monotonic()
        order = client.settings.word_order
        values: list[WatchValue] = []
        for block, regs in zip(POLL_BLOCKS, (client.status_registers, client.pose_registers), strict=True):
            if regs is not None:
                values.extend(decode_block(block, regs, self.plan.served, order, now))
        return values

    def publish(self, readings: WatchReadings) -> None:
        self._publish(readings)

    def write(self, op: WriteWatched) -> None:
        """The engineer's write (see the module docstring); a success is a result naming the value."""
        entry = op.entry
        if entry.address in _CONTROL or entry.address + entry.count - 1 in _CONTROL:
            raise InvalidInput(
                f"{entry.label}: registers 440..445 are the controller's commands; use the motion controls",
                code="watch_write_control",
                params={"what": entry.label},
            )
        client = self._host.client_or_raise()
        order = client.settings.word_order
        regs = entry.encode(op.value, order)
        if entry.count == 1:
            client.write_register(entry.address, regs[0])
        else:
            client.write_registers(entry.address, regs)
        shown = format_value(entry, entry.decode(regs, order))
        text = f"{entry.title} ({entry.label}) = {shown}: written"
        self._host.emit_result(
            CommandResult(
                None,
                None,
                None,
                True,
                text,
                reason=Reason("watch_written", {"what": entry.title, "value": shown}),
            )
        )
        self._read_back(client, entry)

    def _read_back(self, client: RobotClient, entry: WatchEntry) -> None:
        """The written value as the controller holds it now, published at once."""
        block = Block(entry.address, entry.count)
        values = read_blocks(client.read_registers, [block], [entry], client.settings.word_order)
        self._publish(WatchReadings(self.generation, tuple(values)))
