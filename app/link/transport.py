"""The link to the controller: connection, one request at a time, every answer checked.

:class:`Transport` sends a request framed as pymodbus frames it (:mod:`app.link.frames`) and
reads its answer itself, checking each field as it arrives (:func:`app.link.frames.frame_need`):
transaction and protocol id, unit id, function code (or its exception), byte count, exact
length, the write's echo, the RTU CRC. Why not pymodbus's own sync transaction: it decodes the answer by the
answer's function code (an 0x04 answer to an 0x03 read became registers), silently skips frames
of another unit/transaction until the timeout (a wrong answer looked like silence), ignores
byte counts and echoes, and leaves stray bytes in the socket for the next request.

Outcomes of a request: a checked answer; :class:`ModbusExceptionError` (a well-formed exception
answer); :class:`MalformedResponse` (anything else that arrived, including an answer cut short
or with bytes too many); :class:`ResponseTimeout` (silence); :class:`LinkError` (no link).
After a malformed answer or a timeout the link resynchronises: a TCP link is dropped (the next
request reopens it, so a late or garbled tail is never read as the next answer); a serial line
has its input dropped until the line has been quiet for :data:`app.timing.RTU_RESYNC_QUIET` (or
twice 3.5 characters), so the rest of a damaged answer still on the wire is dropped too. Before
every request, bytes that arrived unasked (stray bytes after a good answer) are flushed, so they
cannot poison the next answer. Modbus TCP: a whole answer that arrives first carrying the
transaction id of one of the connection's last requests (a duplicate, a gateway's late answer) is
dropped and counted as a resync; the request's own answer is read after it, and no answer is ever
taken but by its own transaction id. (RTU has no transaction id: a late answer of the same shape
cannot be told from the own one there.)

Not thread-safe: one thread owns a transport. Traffic observers are called synchronously in
that thread, inside the request: keep them short.
"""

from __future__ import annotations

import dataclasses
import logging
import time
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

from app import timing
from app.connection import ConnectionSettings
from app.errors import (
    LinkError,
    MalformedResponse,
    ModbusExceptionError,
    ResponseTimeout,
)
from app.link.stats import LinkStats
from app.protocol.exceptions import GATEWAY_EXCEPTIONS, exception_text

if TYPE_CHECKING:  # frames (pymodbus's framers) and streams (sockets) are imported when a Transport
    # is made, not before: a module that only names a Transport loads neither
    from app.link.frames import Framing, Request
    from app.link.streams import SerialStream, TcpStream

__all__ = ["TrafficObserver", "TrafficRecord", "Transport"]

_log = logging.getLogger(__name__)

_EARLIER_TIDS = 16  # earlier requests whose late answers are recognised (and dropped)
_COUNTERS = tuple(f.name for f in dataclasses.fields(LinkStats) if f.name != "last_error")


def _seconds(value: float) -> str:
    return str(round(value, 3))


@dataclass(frozen=True, slots=True)
class TrafficRecord:
    """One frame as on the wire (MBAP included for TCP, CRC included for RTU)."""

    t: float  # time.time() when the frame was sent / received
    direction: Literal["tx", "rx"]
    frame: bytes
    transport: Literal["tcp", "rtu"]


TrafficObserver = Callable[[TrafficRecord], None]


# --------------------------------------------------------------------------------------------
# The transport
# --------------------------------------------------------------------------------------------


class Transport:
    """One request at a time over one link; every answer checked against its request."""

    def __init__(
        self, settings: ConnectionSettings, on_link_change: Callable[[], None] | None = None
    ) -> None:
        from app.link import frames, streams  # pymodbus, sockets: only once a link is made (see the imports)

        self._read_request = frames.read_request
        self._write_single_request = frames.write_single_request
        self._write_multiple_request = frames.write_multiple_request
        self._encode_request = frames.encode_request
        self._frame_need = frames.frame_need
        self._decode_answer = frames.decode_answer
        self._stale_answer_length = frames.stale_answer_length
        self._answer_registers = frames.answer_registers
        self.settings = settings
        self.framing: Framing = settings.transport
        self._serial = settings.serial_port is not None
        self._stream: TcpStream | SerialStream = (
            streams.SerialStream(settings) if self._serial else streams.TcpStream(settings)
        )
        self._peer_closed: type[Exception] = streams.PeerClosed  # the other end closed the stream
        self._serial_stream = streams.SerialStream
        self._on_link_change = on_link_change or (lambda: None)
        self._observers: list[TrafficObserver] = []
        self._observing = False  # checked first on the hot path
        self._tid = 0
        # the transaction ids of the last requests on this connection (not the one in flight,
        # ``_tid_sent``): a late answer to one of them is dropped, never taken (``_drop_stale``)
        self._earlier_tids: deque[int] = deque(maxlen=_EARLIER_TIDS)
        self._tid_sent = 0
        self._ever_connected = False
        # plain counters on the hot path; ``stats`` makes the LinkStats snapshot when asked
        self._counts = dict.fromkeys(_COUNTERS, 0)
        self._last_error = ""

    # -- statistics -----------------------------------------------------------------------
    @property
    def stats(self) -> LinkStats:
        return LinkStats(**self._counts, last_error=self._last_error)

    def _count(self, field: str, error: str | None = None) -> None:
        self._counts[field] += 1
        if error is not None:
            self._last_error = error

    # -- connection -----------------------------------------------------------------------
    @property
    def connected(self) -> bool:
        return self._stream.is_open

    def open(self) -> None:
        """Open the link (no-op when open); :class:`LinkError` naming the cause when it fails."""
        if self._stream.is_open:
            return
        self._on_link_change()  # a new connection may mean a restarted controller
        try:
            self._stream.open(self.settings.timeout)
        except LinkError as exc:
            endpoint = self.settings.endpoint
            message = (
                f"cannot reconnect to the controller at {endpoint} (the link was lost): {exc}"
                if self._ever_connected
                else f"cannot connect to the controller at {endpoint}: {exc}"
            )
            self._count("link_errors", message)
            raise LinkError(
                message,
                code=exc.code,
                params={**exc.params, "endpoint": endpoint, "reconnect": self._ever_connected},
            ) from None
        if self._ever_connected:
            self._count("reconnects")
        self._ever_connected = True

    def close(self) -> None:
        self._stream.close()
        self._earlier_tids.clear()  # a new connection carries no answer to these
        self._tid_sent = 0
        self._on_link_change()

    def _resync(self, why: str) -> None:
        """Get back in step after a malformed answer or a timeout."""
        self._count("resyncs")
        _log.debug("resync after %s", why)
        if isinstance(self._stream, self._serial_stream) and self._stream.is_open:
            # the rest of a damaged answer may still be on the wire: drop what arrives until the
            # line is quiet, so it is never read as the start of the next answer (line_retry.py)
            baud = max(self.settings.baudrate, 1)
            quiet = max(timing.RTU_RESYNC_QUIET, 2 * 3.5 * 11 / baud)
            self._stream.settle(quiet, self.settings.timeout)
        else:
            self.close()

    # -- observers ------------------------------------------------------------------------
    def add_observer(self, cb: TrafficObserver) -> None:
        self._observers.append(cb)
        self._observing = True

    def remove_observer(self, cb: TrafficObserver) -> None:
        if cb in self._observers:
            self._observers.remove(cb)
        self._observing = bool(self._observers)

    def _emit(self, direction: Literal["tx", "rx"], frame: bytes) -> None:
        record = TrafficRecord(time.time(), direction, bytes(frame), self.framing)
        for cb in list(self._observers):
            try:
                cb(record)
            except Exception:  # an observer must not break the link
                _log.exception("traffic observer %r failed", cb)

    # -- requests -------------------------------------------------------------------------
    def read(self, what: str, address: int, count: int, timeout: float | None = None) -> list[int]:
        """0x03: exactly ``count`` registers."""
        _, data = self.execute(what, self._read_request(address, count), timeout)
        return self._answer_registers(data, count)

    def write_single(self, what: str, address: int, value: int, timeout: float | None = None) -> None:
        self.execute(what, self._write_single_request(address, value), timeout)

    def write_multiple(
        self, what: str, address: int, values: Sequence[int], timeout: float | None = None
    ) -> None:
        self.execute(what, self._write_multiple_request(address, values), timeout)

    def execute(self, what: str, request: Request, timeout: float | None = None) -> tuple[int, bytes]:
        """Send ``request``; its checked answer as (function code, data)."""
        timeout = self.settings.timeout if timeout is None else timeout
        attempts = self.settings.retries + 1
        for attempt in range(attempts):
            try:
                return self._exchange(what, request, timeout)
            except ResponseTimeout:
                if attempt + 1 == attempts:
                    message = (
                        f"controller did not answer within {_seconds(timeout * attempts)} s "
                        f"({self.settings.endpoint})"
                    )
                    self._last_error = message
                    raise ResponseTimeout(
                        message,
                        params={
                            "seconds": round(timeout * attempts, 3),
                            "endpoint": self.settings.endpoint,
                        },
                    ) from None
        raise AssertionError("unreachable")  # pragma: no cover

    def _flush_stray(self) -> None:
        try:
            dropped = self._stream.drain()
        except (self._peer_closed, OSError):
            # The controller closed the idle link (restart, its own timeout): say so once; the
            # next request opens a fresh link.
            self.close()
            message = f"lost the connection to the controller at {self.settings.endpoint}: it closed the link"
            self._count("link_errors", message)
            raise LinkError(
                message, code="link_closed", params={"endpoint": self.settings.endpoint}
            ) from None
        if dropped:
            self._count("resyncs", f"dropped {dropped} stray bytes from {self.settings.endpoint}")

    def _need(self, request: Request, tid: int, own: bytes, buf: bytes) -> tuple[bytes, int]:
        """What is left of ``buf`` once late answers are dropped (TCP: ``own``, the request's
        transaction id, does not start it), and the length the answer must have (checked so far,
        :func:`app.link.frames.frame_need`; a late answer's while it is not whole)."""
        if own and buf[:2] != own:
            buf, awaited = self._drop_stale(buf)
            if awaited or not buf:
                return buf, awaited
        return buf, self._frame_need(self.framing, request, self.settings.unit, tid, buf)

    def _drop_stale(self, buf: bytes) -> tuple[bytes, int]:
        """Drop the whole late answers to earlier requests of this connection at the start of
        ``buf`` (:func:`app.link.frames.stale_answer_length`), each counted as a resync: an answer
        is taken only by its own transaction id, never a late one in its place, and the own answer
        is read after them. Returns what is left and the length still awaited of a late answer
        not yet whole (0: none; what is left is checked as the request's own answer)."""
        while buf:
            length = self._stale_answer_length(buf, self._earlier_tids)
            if not length or len(buf) < length:
                return buf, length
            got = int.from_bytes(buf[:2], "big")
            self._count("resyncs", f"dropped a late answer to an earlier request (transaction id {got})")
            buf = buf[length:]
        return buf, 0

    def _lost(self, what: str) -> LinkError:
        self.close()
        message = f"lost the connection to the controller at {self.settings.endpoint} during the {what}"
        self._count("link_errors", message)
        return LinkError(message, params={"endpoint": self.settings.endpoint})

    def _exchange(self, what: str, request: Request, timeout: float) -> tuple[int, bytes]:
        """One request and its checked answer: send it, wait for the answer (late answers to
        earlier requests dropped on the way), judge it."""
        tid = self._send(what, request)
        buf = self._receive(what, request, tid, timeout)
        return self._judge(what, buf)

    def _send(self, what: str, request: Request) -> int:
        """Send ``request`` on an open link with nothing stray waiting; its transaction id (RTU: 0)."""
        stream = self._stream
        if not stream.is_open:
            self.open()
        self._flush_stray()
        framing = self.framing
        self._tid = tid = self._tid % 65000 + 1 if framing == "tcp" else 0
        if self._tid_sent:  # (TCP) the transaction ids of this connection's earlier requests
            self._earlier_tids.append(self._tid_sent)
        self._tid_sent = tid
        frame = self._encode_request(framing, request, self.settings.unit, tid)
        self._counts["requests"] += 1
        try:
            stream.send(frame)
        except OSError:
            raise self._lost(what) from None
        if self._observing:
            self._emit("tx", frame)
        return tid

    def _receive(self, what: str, request: Request, tid: int, timeout: float) -> bytes:
        """The whole answer to the request sent with ``tid``, every field checked as it arrives
        (:meth:`_need`, which drops late answers first); a malformed one is reported
        (:meth:`_malformed`), silence raises :class:`ResponseTimeout`."""
        buf = b""
        need = 0  # nothing received yet: no field to check, receive first
        own = tid.to_bytes(2, "big") if self.framing == "tcp" else b""
        deadline = time.monotonic() + timeout
        try:
            while True:
                if buf:
                    buf, need = self._need(request, tid, own, buf)
                    if len(buf) >= need > 0:
                        break
                buf += self._more(what, buf, need, deadline, timeout)
            if len(buf) > need:
                raise MalformedResponse(
                    f"{len(buf) - need} bytes more than the {need}-byte answer",
                    field="length",
                    expected=need,
                    got=len(buf),
                )
        except MalformedResponse as exc:
            raise self._malformed(what, exc, buf) from None
        return buf

    def _more(self, what: str, buf: bytes, need: int, deadline: float, timeout: float) -> bytes:
        """The next bytes of the answer (``buf`` so far, ``need`` its length so far known) before
        ``deadline``: silence is a timeout, an answer begun and not finished is cut short."""
        remaining = deadline - time.monotonic()
        if remaining <= 0:
            if not buf:
                self._count("timeouts", f"no answer to the {what}")
                self._resync("a timeout")
                raise ResponseTimeout(f"no answer to the {what}")
            raise MalformedResponse(
                f"answer cut short: {len(buf)} of {need} bytes within {_seconds(timeout)} s",
                field="length",
                expected=need,
                got=len(buf),
            )
        try:
            return self._stream.recv(remaining)
        except self._peer_closed:
            if not buf:
                raise self._lost(what) from None
            raise MalformedResponse(
                f"answer cut short: the controller closed the link after {len(buf)} of {need} bytes",
                field="length",
                expected=need,
                got=len(buf),
            ) from None
        except OSError:
            raise self._lost(what) from None

    def _malformed(self, what: str, exc: MalformedResponse, buf: bytes) -> MalformedResponse:
        """A malformed answer (``buf``: what arrived of it), counted, the link resynchronised:
        the error to raise, naming the request and the endpoint."""
        if self._observing and buf:
            self._emit("rx", buf)
        message = f"malformed answer to the {what} from {self.settings.endpoint}: {str(exc)[:200]}"
        self._count("malformed", message)
        self._resync("a malformed answer")
        error = MalformedResponse(message, field=exc.field, expected=exc.expected, got=exc.got)
        error.params["endpoint"] = self.settings.endpoint
        return error

    def _judge(self, what: str, buf: bytes) -> tuple[int, bytes]:
        """A whole, checked answer: its (function code, data), or the controller's refusal raised."""
        if self._observing:
            self._emit("rx", buf)
        function, data = self._decode_answer(self.framing, buf)
        if function & 0x80:
            refused = self._exception(what, function & 0x7F, data[0])
            self._count("exceptions", str(refused))
            raise refused
        self._counts["answers"] += 1
        return function, data

    def _exception(self, what: str, function: int, code: int) -> ModbusExceptionError:
        """The answer's Modbus exception; a gateway's 10 / 11 names the unit id (most often the
        wrong one: nothing answers at it) and says to check it."""
        text = exception_text(code, f"exception code {code}")
        if code not in GATEWAY_EXCEPTIONS:
            return ModbusExceptionError(function, code, f"controller refused {what}: {text}")
        unit, endpoint = self.settings.unit, self.settings.endpoint
        message = (
            f"no device answered {what} at unit id {unit} on {endpoint} "
            f"(Modbus exception {code}, {text}): check the unit id"
        )
        error = ModbusExceptionError(function, code, message)
        error.params.update(unit=unit, endpoint=endpoint)
        return error
