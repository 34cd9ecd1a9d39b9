"""How a watch list is read: its registers merged into blocks, a fast lane and a slow one.

The poll budget (named here, read at use time, so tests and benchmarks may change them):

* the **fast lane** -- entries in list order, as long as their blocks fit
  :data:`FAST_READS` reads of :data:`FAST_REGISTERS` registers in all -- is read in every poll,
  right after the pose block (the same cycle as the pose);
* the **slow lane** -- the rest -- one block per poll at most (:data:`SLOW_READS_PER_POLL`), each
  block again once :data:`SLOW_PERIOD` has passed since its last read.

An empty list costs nothing: no read, no publish. Registers closer than :data:`MERGE_GAP` are
read in one request (a few registers more cost less than a second round trip; the slow lane,
read rarely, merges over :data:`SLOW_MERGE_GAP`); a block never exceeds
:data:`~app.protocol.registers.MAX_READ_REGISTERS`. Qt-free.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from app.errors import ModbusExceptionError
from app.protocol.codec import WordOrder
from app.protocol.registers import (
    MAX_READ_REGISTERS,
    POSE_BLOCK_COUNT,
    POSE_BLOCK_START,
    STATUS_BLOCK_COUNT,
    STATUS_BLOCK_START,
)
from app.watchlist.entry import WatchEntry, WatchValue

__all__ = [
    "FAST_READS",
    "FAST_REGISTERS",
    "MERGE_GAP",
    "POLL_BLOCKS",
    "SLOW_MERGE_GAP",
    "SLOW_PERIOD",
    "SLOW_READS_PER_POLL",
    "Block",
    "ReadPlan",
    "WatchReadings",
    "decode_block",
    "merge_blocks",
    "read_blocks",
]

FAST_READS = 1  # reads per poll for the fast lane
FAST_REGISTERS = 64  # registers per poll for the fast lane
SLOW_PERIOD = 0.5  # s between two reads of one slow block
SLOW_READS_PER_POLL = 1
MERGE_GAP = 8  # registers between two spans read in one request rather than two (fast lane)
SLOW_MERGE_GAP = 32  # the same for the slow lane: read rarely, fewer and longer requests


@dataclass(frozen=True, slots=True)
class Block:
    """One read: ``count`` registers from ``address``."""

    address: int
    count: int

    @property
    def end(self) -> int:
        return self.address + self.count


#: The poll's own reads (status 560..583, pose 412..511): an entry inside them costs no read.
POLL_BLOCKS = (Block(STATUS_BLOCK_START, STATUS_BLOCK_COUNT), Block(POSE_BLOCK_START, POSE_BLOCK_COUNT))


def merge_blocks(entries: Sequence[WatchEntry], gap: int | None = None) -> tuple[Block, ...]:
    """The reads that cover ``entries``: spans sorted, merged when closer than ``gap``."""
    gap = MERGE_GAP if gap is None else gap
    spans = sorted({(e.address, e.address + e.count) for e in entries})
    blocks: list[Block] = []
    for start, end in spans:
        last = blocks[-1] if blocks else None
        if (
            last is not None
            and start - last.end <= gap
            and max(end, last.end) - last.address <= MAX_READ_REGISTERS
        ):
            blocks[-1] = Block(last.address, max(end, last.end) - last.address)
        else:
            blocks.append(Block(start, end - start))
    return tuple(blocks)


def _fits(blocks: Sequence[Block]) -> bool:
    return len(blocks) <= FAST_READS and sum(b.count for b in blocks) <= FAST_REGISTERS


@dataclass(frozen=True)
class ReadPlan:
    """A watch list's reads: ``served`` by the poll's own status and pose reads (no read of its
    own), ``fast`` every poll, ``slow`` on the slow clock."""

    entries: tuple[WatchEntry, ...]
    fast: tuple[Block, ...]
    slow: tuple[Block, ...]
    served: tuple[WatchEntry, ...] = ()

    @classmethod
    def of(cls, entries: Sequence[WatchEntry]) -> ReadPlan:
        served: list[WatchEntry] = []
        fast: list[WatchEntry] = []
        rest: list[WatchEntry] = []
        for entry in entries:  # list order: the first entries get the fast lane
            if any(_inside(entry, b) for b in POLL_BLOCKS):
                served.append(entry)
            elif not rest and _fits(merge_blocks([*fast, entry])):
                fast.append(entry)
            else:
                rest.append(entry)
        return cls(tuple(entries), merge_blocks(fast), merge_blocks(rest, SLOW_MERGE_GAP), tuple(served))

    @property
    def empty(self) -> bool:
        return not self.entries

    def fast_entries(self) -> tuple[WatchEntry, ...]:
        """The entries read in every poll (the served ones included)."""
        return tuple(e for e in self.entries if e in self.served or any(_inside(e, b) for b in self.fast))


def _inside(entry: WatchEntry, block: Block) -> bool:
    return block.address <= entry.address and entry.address + entry.count <= block.end


@dataclass(frozen=True, slots=True)
class WatchReadings:
    """What one poll read of the watch list whose ``generation`` it carries."""

    generation: int
    values: tuple[WatchValue, ...]


#: ``read(address, count)`` -> registers (raises on a failed read)
ReadFn = Callable[[int, int], list[int]]


def read_blocks(
    read: ReadFn, blocks: Sequence[Block], entries: Sequence[WatchEntry], order: WordOrder
) -> list[WatchValue]:
    """Read ``blocks`` and decode every entry inside them. A block the controller refuses (a
    Modbus exception: no such register) gives its entries an error, the others are read; any
    other failure (the link) is raised."""
    values: list[WatchValue] = []
    for block in blocks:
        try:
            regs = read(block.address, block.count)
        except ModbusExceptionError as exc:
            now = time.monotonic()
            values.extend(WatchValue(e, None, (), now, str(exc)) for e in entries if _inside(e, block))
            continue
        values.extend(decode_block(block, regs, entries, order, time.monotonic()))
    return values


def decode_block(
    block: Block, regs: Sequence[int], entries: Sequence[WatchEntry], order: WordOrder, read_at: float
) -> list[WatchValue]:
    """The values of the ``entries`` inside ``block``, from its registers ``regs``."""
    values: list[WatchValue] = []
    for entry in entries:
        if _inside(entry, block):
            start = entry.address - block.address
            raw = tuple(regs[start : start + entry.count])
            values.append(WatchValue(entry, entry.decode(raw, order), raw, read_at))
    return values
