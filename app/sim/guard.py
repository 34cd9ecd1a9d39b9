"""What the simulated controller does with bad input, and its communication watchdog.

* :class:`BadFrames` counts rejected frames by reason and logs them rate-limited: the first
  one of a period with a short hex sample, then at most one summary line per period (counts
  and one sample), never one line per frame.
* :class:`ScreeningDecoder` checks every request before pymodbus decodes it: the controller
  knows only 0x03, 0x06 and 0x10, so any other function (coils 0x01/0x05/0x0F, discrete inputs
  0x02, input registers 0x04, diagnostics, ...) gets exception 1 (illegal function); an illegal
  quantity (0x03 count 0 or > 125, 0x10 count 0 or > 123, byte count not 2 x count, a frame
  whose length does not match) gets exception 3 (illegal data value). pymodbus 3.16 itself
  answers such 0x03 requests with ``80 01`` (no function code) and serves coils and input
  registers from the holding registers.
* :class:`ScreenedSocketFramer` skips an MBAP frame with a protocol id other than 0 (pymodbus
  would wait on it for ever and the connection would never answer again) and drops the buffer
  when the MBAP length is impossible; :class:`ScreenedRtuFramer` counts CRC failures.
* :class:`CommWatchdog`: during a teach jog (ratio > 0), stop the jog when the connection that
  last wrote the ratio closes, or when no request from that connection has arrived for
  ``timeout`` seconds -- another master polling meanwhile does not keep a silent host's jog
  going (the strictest plausible controller). A jog no connection is known to own (started
  before any ratio write was seen) counts requests from any connection. See the README's
  protocol decision "communication watchdog".
"""

from __future__ import annotations

import contextvars
import logging
import struct
import threading
import time
from collections import Counter
from collections.abc import Callable

from pymodbus.constants import ExcCodes
from pymodbus.framer.rtu import FramerRTU
from pymodbus.framer.socket import FramerSocket
from pymodbus.pdu import DecodePDU, ExceptionResponse, ModbusPDU

log = logging.getLogger(__name__)

WATCHDOG_TIMEOUT = 0.3  # s without any request before a running jog is stopped (default)
WATCHDOG_PERIOD = 0.01  # s between two silence checks (the simulator's ticker)
BAD_FRAME_LOG_PERIOD = 5.0  # s: at most one sample line and one summary line per period
SAMPLE_BYTES = 16  # bytes of a bad frame quoted in the log

FC_READ_HOLDING = 0x03
FC_WRITE_SINGLE = 0x06
FC_WRITE_MULTIPLE = 0x10
SUPPORTED_FUNCTIONS = frozenset({FC_READ_HOLDING, FC_WRITE_SINGLE, FC_WRITE_MULTIPLE})
MAX_READ_COUNT = 125
MAX_WRITE_COUNT = 123
MBAP_LENGTH_MIN = 2  # unit + function code
# Modbus allows a 253-byte PDU (MBAP length 254); longer is still framed, so an oversized
# write gets exception 3 rather than silence. Beyond this the stream cannot be trusted.
MBAP_LENGTH_MAX = 512

# The simulator's connection id of the request being served (set per connection task).
CURRENT_CONNECTION: contextvars.ContextVar[int | None] = contextvars.ContextVar(
    "sim_connection", default=None
)


def hex_sample(data: bytes) -> str:
    """The first :data:`SAMPLE_BYTES` bytes as hex, marked when cut."""
    head = data[:SAMPLE_BYTES].hex(" ")
    return head + (f" ... ({len(data)} bytes)" if len(data) > SAMPLE_BYTES else "")


class BadFrames:
    """Counters of rejected frames by reason, and a rate-limited log of them."""

    def __init__(
        self, period: float = BAD_FRAME_LOG_PERIOD, clock: Callable[[], float] = time.monotonic
    ) -> None:
        self.period = period
        self._clock = clock
        self._lock = threading.Lock()
        self._totals: Counter[str] = Counter()
        self._window_end = float("-inf")
        self._held: Counter[str] = Counter()  # counted, not logged yet (this window)
        self._held_sample: tuple[str, bytes] | None = None

    def record(self, reason: str, frame: bytes) -> None:
        now = self._clock()
        with self._lock:
            self._totals[reason] += 1
            if now < self._window_end:
                self._held[reason] += 1
                if self._held_sample is None:
                    self._held_sample = (reason, frame[: SAMPLE_BYTES + 1])
                return
            self._flush_locked()
            self._window_end = now + self.period
        log.warning(
            "bad frame rejected (%s): %s; more are counted and summarised every %g s",
            reason,
            hex_sample(frame),
            self.period,
        )

    def flush(self) -> None:
        """Log the summary of a finished period (the ticker calls this)."""
        with self._lock:
            if self._clock() >= self._window_end:
                self._flush_locked()

    def _flush_locked(self) -> None:
        if not self._held:
            return
        total = sum(self._held.values())
        reasons = ", ".join(f"{n} {reason}" for reason, n in self._held.most_common())
        sample = (
            ""
            if self._held_sample is None
            else f"; sample ({self._held_sample[0]}): {hex_sample(self._held_sample[1])}"
        )
        log.warning("%d more bad frame(s) rejected within %g s: %s%s", total, self.period, reasons, sample)
        self._held.clear()
        self._held_sample = None

    def counts(self) -> dict[str, int]:
        with self._lock:
            return dict(self._totals)


class RejectedRequest(ModbusPDU):  # type: ignore[misc]  # pymodbus is untyped here
    """A request that is answered with a Modbus exception and never reaches the datastore."""

    def __init__(self, function_code: int, exception: ExcCodes) -> None:
        super().__init__()
        self.function_code = function_code & 0x7F
        self.exception = exception

    async def datastore_update(self, _context: object, _device_id: int) -> ModbusPDU:
        return ExceptionResponse(self.function_code, self.exception)


def screen_request(frame: bytes) -> tuple[str, ExcCodes] | None:
    """Why a request PDU (function code + data) is refused, or None when it is acceptable."""
    fc = frame[0]
    if fc not in SUPPORTED_FUNCTIONS:
        return "illegal function", ExcCodes.ILLEGAL_FUNCTION
    data = frame[1:]
    if fc in (FC_READ_HOLDING, FC_WRITE_SINGLE):
        if len(data) != 4:
            return "bad length", ExcCodes.ILLEGAL_VALUE
        if fc == FC_READ_HOLDING and not 1 <= struct.unpack(">H", data[2:4])[0] <= MAX_READ_COUNT:
            return "illegal quantity", ExcCodes.ILLEGAL_VALUE
        return None
    if len(data) < 5:
        return "bad length", ExcCodes.ILLEGAL_VALUE
    count, byte_count = struct.unpack(">HB", data[2:5])
    if not 1 <= count <= MAX_WRITE_COUNT or byte_count != 2 * count:
        return "illegal quantity", ExcCodes.ILLEGAL_VALUE
    if len(data) != 5 + byte_count:
        return "bad length", ExcCodes.ILLEGAL_VALUE
    return None


class ScreeningDecoder(DecodePDU):  # type: ignore[misc]
    """pymodbus's request decoder behind :func:`screen_request`; counts what it refuses."""

    def __init__(self, bad_frames: BadFrames) -> None:
        super().__init__(True)
        self.bad_frames = bad_frames

    def decode(self, frame: bytes) -> ModbusPDU | None:
        if not frame:
            return None
        refusal = screen_request(frame)
        if refusal is None:
            pdu = super().decode(frame)
            if pdu is not None:
                return pdu
            refusal = ("undecodable", ExcCodes.ILLEGAL_VALUE)
        self.bad_frames.record(refusal[0], frame)
        return RejectedRequest(frame[0], refusal[1])


class ScreenedSocketFramer(FramerSocket):  # type: ignore[misc]
    """MBAP framing that never jams on a bad header."""

    def __init__(self, decoder: ScreeningDecoder) -> None:
        super().__init__(decoder)
        self.bad_frames = decoder.bad_frames

    def decode(self, data: bytes) -> tuple[int, int, int, bytes]:
        if len(data) >= 6:
            pid, length = struct.unpack(">HH", data[2:6])
            if not MBAP_LENGTH_MIN <= length <= MBAP_LENGTH_MAX:
                # no way to find the next frame boundary: drop what we have
                self.bad_frames.record("bad MBAP length", data)
                return len(data), 0, 0, b""
            if pid != 0:
                if len(data) < 6 + length:
                    return 0, 0, 0, b""  # wait for the whole frame, then skip it
                self.bad_frames.record("bad protocol id", data[: 6 + length])
                return 6 + length, 0, 0, b""
        result: tuple[int, int, int, bytes] = super().decode(data)
        return result


class ScreenedRtuFramer(FramerRTU):  # type: ignore[misc]
    """RTU framing that counts CRC failures (pymodbus drops them silently)."""

    def __init__(self, decoder: ScreeningDecoder) -> None:
        super().__init__(decoder)
        self.bad_frames = decoder.bad_frames

    def decode(self, data: bytes) -> tuple[int, int, int, bytes]:
        result: tuple[int, int, int, bytes] = super().decode(data)
        if result[0] and not result[3]:
            self.bad_frames.record("bad CRC", data)
        return result


class CommWatchdog:
    """Stops a teach jog whose host went away (see the module docstring).

    ``stop_jog(reason)`` is called from the server's loop thread (closed connection) or the
    ticker (silence); it returns True when it stopped a jog.
    """

    def __init__(
        self,
        timeout: float | None,
        stop_jog: Callable[[str], bool],
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.timeout = timeout if timeout and timeout > 0 else None
        self._stop_jog = stop_jog
        self._clock = clock
        self._last_request = clock()  # from any connection
        self._last_by_connection: dict[int, float] = {}
        self._owner: int | None = None
        # added to the timeout on a slow serial line: the longest answer's time on the wire,
        # during which the host cannot send its next request
        self.allowance = 0.0

    @property
    def enabled(self) -> bool:
        return self.timeout is not None

    def set_timeout(self, timeout: float | None) -> None:
        """None or 0: off (a controller without a watchdog)."""
        self.timeout = timeout if timeout and timeout > 0 else None
        self._last_request = self._clock()

    def request(self, connection: int | None = None) -> None:
        """A request arrived from ``connection`` (None: not known)."""
        now = self._clock()
        self._last_request = now
        if connection is not None:
            self._last_by_connection[connection] = now

    def jog_written(self, connection: int | None) -> None:
        """``connection`` wrote the ratio and the arm is jogging: it now owns the jog."""
        self._owner = connection
        if connection is not None:
            self._last_by_connection[connection] = self._clock()

    def closed(self, connection: int) -> None:
        self._last_by_connection.pop(connection, None)
        if self.timeout is None or connection != self._owner:
            return
        self._owner = None
        self._stop_jog(f"connection {connection} that started the jog closed")

    def check(self, jogging: bool) -> None:
        """The silence check (the ticker calls this every tick)."""
        if self.timeout is None or not jogging:
            return
        owner = self._owner
        last = self._last_by_connection.get(owner) if owner is not None else None
        silent = self._clock() - (self._last_request if last is None else last)
        source = "" if last is None else f" from connection {owner}, which jogs,"
        if silent > self.timeout + self.allowance and self._stop_jog(
            f"no request{source} for {silent:.3f} s (watchdog {self.timeout:g} s)"
        ):
            self._owner = None
