"""How to reach the controller and the host-side limits of the link: :class:`ConnectionSettings`.

Plain data, read by the window at start-up, the register profile (:mod:`app.safety.register_profile`)
and the CLI long before a link is opened; the link (:mod:`app.link.transport`) takes it to open one.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from app import timing
from app.protocol import registers
from app.protocol.codec import WordOrder
from app.protocol.datetime_regs import DateTimeLayout

__all__ = ["ConnectionSettings"]


@dataclass
class ConnectionSettings:
    """How to reach the controller, and the host-side limits."""

    host: str = "127.0.0.1"
    port: int = 502
    unit: int = 1
    serial_port: str | None = None  # RTU over a serial line when set
    baudrate: int = 115200
    parity: str = "N"
    stopbits: int = 1
    bytesize: int = 8
    framer: Literal["socket", "rtu"] = "socket"  # "rtu" over TCP is for tests
    word_order: WordOrder = WordOrder.LOW_FIRST
    timeout: float = timing.REQUEST_TIMEOUT  # commands and one-off reads
    retries: int = timing.REQUEST_RETRIES
    poll_timeout: float | None = None  # monitoring reads; None: follows the transport (below)
    monitor_only: bool = False
    datetime_layout: DateTimeLayout = DateTimeLayout.SPLIT_WORDS
    point_id_min: int = registers.TEMP_POINT_ID_MIN
    point_id_max: int = registers.TEMP_POINT_ID_MAX
    # How command completion is proven (app/link/tracker.py): "sentinel" writes a sentinel into
    # GV291 before each command, "observe" only reads it, "auto" probes GV291 once before the
    # first command (never in monitor-only mode, which sends no command).
    completion: Literal["auto", "sentinel", "observe"] = "auto"
    unconfirmed_after: float | None = None  # s; None: timing.UNCONFIRMED_AFTER (observe rule)

    @property
    def transport(self) -> Literal["tcp", "rtu"]:
        """What the frames look like on the wire."""
        return "rtu" if self.serial_port is not None or self.framer == "rtu" else "tcp"

    @property
    def effective_poll_timeout(self) -> float:
        """The timeout of a monitoring read: short, so a silent controller is seen at once.

        TCP: :data:`timing.POLL_TIMEOUT_TCP`. RTU: the time the largest poll answer takes on the
        wire at the configured baud rate (11 bits a byte), twice, plus
        :data:`timing.POLL_TIMEOUT_RTU_MARGIN` (9600 baud: about 0.57 s; 115200: about 0.14 s).
        """
        if self.poll_timeout is not None:
            return self.poll_timeout
        if self.transport == "tcp" and self.serial_port is None:
            return timing.POLL_TIMEOUT_TCP
        frame_bytes = 5 + 2 * registers.POSE_BLOCK_COUNT  # unit, fc, count, data, CRC
        return timing.POLL_TIMEOUT_RTU_MARGIN + 2 * frame_bytes * 11 / max(self.baudrate, 1)

    @property
    def endpoint(self) -> str:
        """``host:port`` or the serial device, for messages."""
        return self.serial_port if self.serial_port is not None else f"{self.host}:{self.port}"
