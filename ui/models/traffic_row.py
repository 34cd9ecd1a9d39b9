"""One row of the traffic inspector as the table shows it (:class:`TrafficRow`), made on demand
from :class:`ui.models.traffic_store.TrafficStore` by :class:`ui.models.traffic_model.TrafficModel`;
its decoding and formatted texts are cached in it."""

from __future__ import annotations

import time

from app.protocol import registers as regs
from app.protocol.codec import WordOrder
from app.protocol.datetime_regs import DateTimeLayout
from app.protocol.enums import RunCommand
from app.protocol.frames import DecodedFrame, decode_frame
from ui.models.traffic_store import NO_ROW

__all__ = ["HEX_DISPLAY_BYTES", "TrafficRow", "is_poll_read", "wrap_hex"]

HEX_DISPLAY_BYTES = 40  # bytes shown in the table cell; a 412.. read answer has 209

# Reads inside these register blocks are the monitor's polls ("hide polls").
_POLL_BLOCKS: tuple[range, ...] = (
    range(regs.POSE_BLOCK_START, regs.POSE_BLOCK_START + regs.POSE_BLOCK_COUNT),
    range(regs.STATUS_BLOCK_START, regs.STATUS_BLOCK_START + regs.STATUS_BLOCK_COUNT),
)


def is_poll_read(address: int, count: int) -> bool:
    """An FC03 read that lies wholly in the pose block (412..) or the status block (560..)."""
    last = address + count - 1
    return count > 0 and any(address in block and last in block for block in _POLL_BLOCKS)


class TrafficRow:
    """One captured frame plus what was learnt cheaply at insertion; decoding is cached.

    Made by the model on demand (a view of a stored row, ``index`` its absolute row number)."""

    __slots__ = (
        "_decoded",
        "_hex",
        "_summary",
        "_time",
        "bad",
        "direction",
        "frame",
        "index",
        "last_command",
        "poll",
        "request",
        "t",
        "transport",
    )

    def __init__(self, t: float, direction: str, frame: bytes, transport: str, index: int = NO_ROW) -> None:
        self.index = index
        self.t = t
        self.direction = direction
        self.frame = frame
        self.transport = transport
        self.poll = False  # a read of the pose/status block, or its answer
        self.bad = False  # exception response (or, once decoded, malformed)
        self.request: TrafficRow | None = None  # for a response: the request it answers
        self.last_command: RunCommand | None = None  # decides the GV291 table
        self._hex: str | None = None
        self._summary: str | None = None
        self._time: str | None = None
        self._decoded: DecodedFrame | None = None  # kept for requests only (they are small)

    @property
    def hex(self) -> str:
        """All bytes, spaced uppercase hex as in the seed (not cached: cheap, and long)."""
        return self.frame.hex(" ").upper()

    @property
    def hex_display(self) -> str:
        """The hex cut after ``HEX_DISPLAY_BYTES`` (cached): eliding a 600-character string on
        every repaint made the table slow. The tooltip and exports carry all bytes."""
        if self._hex is None:
            if len(self.frame) <= HEX_DISPLAY_BYTES:
                self._hex = self.hex
            else:
                self._hex = self.frame[:HEX_DISPLAY_BYTES].hex(" ").upper() + " …"
        return self._hex

    def decode(self, word_order: WordOrder, clock_layout: DateTimeLayout) -> DecodedFrame:
        """Full decoding (not cached for responses: use ``summary`` for the cached text)."""
        if self._decoded is not None:
            return self._decoded
        request = self.request.decode(word_order, clock_layout) if self.request is not None else None
        decoded = decode_frame(
            self.frame,
            transport="rtu" if self.transport == "rtu" else "tcp",
            direction="rx" if self.direction == "rx" else "tx",
            word_order=word_order,
            last_command=self.last_command,
            clock_layout=clock_layout,
            request=request,
        )
        if self.direction == "tx":
            self._decoded = decoded
        return decoded

    def summary(self, word_order: WordOrder, clock_layout: DateTimeLayout) -> str:
        if self._summary is None:
            decoded = self.decode(word_order, clock_layout)
            text = decoded.summary
            if decoded.errors:
                text = f"{text} [{'; '.join(decoded.errors)}]"
                self.bad = True
            self._summary = text
        return self._summary

    @property
    def time_display(self) -> str:
        if self._time is None:
            self._time = self.time_text()
        return self._time

    def time_text(self, with_date: bool = False) -> str:
        stamp = time.localtime(self.t)
        ms = int(self.t * 1000) % 1000
        return time.strftime("%Y-%m-%d %H:%M:%S" if with_date else "%H:%M:%S", stamp) + f".{ms:03d}"


def wrap_hex(text: str, per_line: int = 16) -> str:
    step = 3 * per_line
    return "\n".join(text[i : i + step].rstrip() for i in range(0, len(text), step))
