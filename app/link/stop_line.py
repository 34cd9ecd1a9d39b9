"""The stop line: a second TCP connection to the controller, kept for Stop alone.

Why. The main link carries one request at a time, owned by the worker thread. A Stop posted from
the GUI waited for the worker thread to be scheduled (measured 0.1-2.3 ms on a loaded 2-core
machine: the OS, the GIL, Qt's event delivery) and for the read in flight (one round trip). On
the stop line the thread that asks for the stop -- the GUI thread, in the Stop button's slot --
writes ``441 <- 1`` itself: no queue, no thread hand-off, no read in front of it. Bound: the
caller's own send (tens of microseconds) plus the network and the controller.

The contract is silent on how many Modbus TCP connections a controller accepts (PROTOCOL.md,
section 7). TeachPad decides per connection (``auto``):

* The worker opens the line after the main link is up (never in monitor-only mode, never on a
  serial line: one bus, one master) and checks it with one status read. A controller that
  refuses it, does not answer on it, or drops the main link within :data:`PROBATION` of it
  opening (a one-connection controller that keeps the newest) is left alone: the stop then
  goes the old way, through the worker's queue, and the log says why.
* An idle line is read every :data:`KEEPALIVE` (a controller may close idle connections); a
  failed read closes it, and it is reopened after a backoff (:data:`RETRY_DELAYS`).
* :meth:`StopLine.send_stop` (any thread) only sends; it never waits. The worker reads and
  checks the answer afterwards (:meth:`StopLine.collect`, every answer checked as on the main
  link: transaction, protocol, unit, function, echo). The worker *also* writes the stop on the
  main link after the transaction in flight: the ordering guarantee -- nothing this host wrote
  before the stop (a move command already on its way) can run after it -- stays the main
  link's. A second stop is harmless; the audit trail records both.

What a Stop writes, where and in what order, and what it ends, is :mod:`app.link.halt`'s (the one
module of the Stop); this is the line's transport.
"""

from __future__ import annotations

import logging
import socket
import threading
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING

from app.connection import ConnectionSettings
from app.errors import LinkError, MalformedResponse, ResponseTimeout
from app.link import frames
from app.link.transport import TrafficRecord
from app.protocol import registers

if TYPE_CHECKING:
    from app.link.capture import TrafficCapture
    from app.safety.audit import AuditLog

__all__ = ["KEEPALIVE", "PROBATION", "RETRY_DELAYS", "StopLine", "StopSent"]

_log = logging.getLogger(__name__)

KEEPALIVE = 2.0  # s between reads on an idle stop line
PROBATION = 2.0  # s after opening: a main link lost within this disables the line (one connection only)
RETRY_DELAYS = (1.0, 5.0, 30.0)  # s before reopening a failed line; the last one repeats
_RECV_SIZE = 256


@dataclass(frozen=True, slots=True)
class StopSent:
    """A stop the line sent, whose answer the worker has not read yet."""

    tid: int
    frame: bytes
    at: float  # time.time() of the send, for the traffic record
    sent_mono: float = 0.0  # time.monotonic() just before the send (what the main link wrote since)


class StopLine:
    """The second connection (see the module docstring). ``send_stop`` from any thread; the
    rest from the worker thread. One lock orders the two sides; a sender never waits for it."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._sock: socket.socket | None = None
        self._settings: ConnectionSettings | None = None
        self._tid = 0
        self._pending: StopSent | None = None
        self.enabled = True  # False once "auto" decided against a line for this connection
        self.why_not = ""  # why the line is not in use (for the log and the report)
        self.opened_at = 0.0
        self._next_keepalive = 0.0
        self._retry_at = 0.0
        self._failures = 0
        self.stops_sent = 0
        self.stops_requested = 0  # every send_stop call (any thread), whether the line took it or not

    @property
    def up(self) -> bool:
        return self._sock is not None

    # --- any thread ------------------------------------------------------------------------
    def send_stop(self) -> StopSent | None:
        """Write 441 <- 1 now, from the calling thread; None when the line cannot take it (down,
        busy with a keepalive read, an answer not yet read). One system call: no check before it
        (each would release the GIL, and the worker could take it); a line the controller closed
        since the last keepalive loses this stop, and the main link's copy of it goes out as before.
        ``stops_requested`` counts the call first (no GIL release before it): from here on the
        worker's upload writes nothing more it would not need (no staging write, no next point)."""
        self.stops_requested += 1
        if not self._lock.acquire(blocking=False):
            return None
        try:
            sock, settings = self._sock, self._settings
            if sock is None or settings is None or self._pending is not None:
                return None
            self._tid = self._tid % 65000 + 1
            request = frames.write_single_request(registers.REG_STOP, 1)
            frame = frames.encode_request("tcp", request, settings.unit, self._tid)
            sent_mono = time.monotonic()
            try:
                sent = sock.send(frame)
            except OSError:
                return None
            if sent != len(frame):  # never for 12 bytes on an idle socket; a torn frame is no stop
                self._drop("a partial send")
                return None
            self._pending = StopSent(self._tid, frame, time.time(), sent_mono)
            self.stops_sent += 1
            return self._pending
        finally:
            self._lock.release()

    # --- worker thread ---------------------------------------------------------------------
    def reset(self, settings: ConnectionSettings | None) -> None:
        """A new connection: close, forget the last decision, use ``settings`` from now on."""
        with self._lock:
            self._drop("")
            self._settings = settings
            self.enabled = settings is not None and self.usable(settings)
            self.why_not = "" if self.enabled else "monitor-only mode or a serial line"
            self._failures = 0
            self._retry_at = 0.0

    @staticmethod
    def usable(settings: ConnectionSettings) -> bool:
        return not settings.monitor_only and settings.serial_port is None and settings.transport == "tcp"

    def main_link_closed(self, now: float, *, lost: bool) -> None:
        """The main link was ``lost`` or closed: close the line too. Lost within
        :data:`PROBATION` of the line opening: this controller keeps one connection only."""
        with self._lock:
            if self._sock is None:
                return
            if lost and now - self.opened_at < PROBATION:
                self.enabled = False
                self.why_not = (
                    f"the main link was lost {now - self.opened_at:.1f} s after the stop "
                    "line opened: the controller seems to accept one connection only"
                )
                _log.warning("stop line off for this connection: %s", self.why_not)
            self._drop("")

    def maintain(self, now: float) -> None:
        """Open when due, keep alive when idle (worker thread, between polls)."""
        if not self.enabled or self._settings is None:
            return
        if self._sock is None:
            if now >= self._retry_at:
                self._open(now)
            return
        if now >= self._next_keepalive:
            with self._lock:
                if self._sock is None or self._pending is not None:
                    return  # a stop's answer waits for the stop job's report (it reads it there)
                try:
                    self._collect_locked()
                    self._exchange(frames.read_request(registers.STATUS_BLOCK_START, 1))
                except (LinkError, ResponseTimeout, MalformedResponse) as exc:
                    self._fail(f"the keepalive read failed: {exc}", now)
                    return
                self._next_keepalive = now + KEEPALIVE

    def collect(self) -> tuple[StopSent | None, bytes, str | None]:
        """Read the answer of the stop sent last: (what was sent or None, the answer's bytes,
        the problem or None)."""
        with self._lock:
            pending = self._pending
            try:
                answer = self._collect_locked()
            except (LinkError, ResponseTimeout, MalformedResponse) as exc:
                self._fail(f"the stop's answer: {exc}", time.monotonic())
                return pending, b"", str(exc)
            return pending, answer, None

    def report(self, capture: TrafficCapture, audit: AuditLog | None, expected: StopSent) -> bool:
        """:meth:`collect`, then the stop's frames to the traffic capture and its write to the
        audit trail (worker thread); a bad answer is logged (the main link's stop went out too).
        True when the controller took ``expected`` (the stop this job sent) on this line (its
        echo checked)."""
        sent, answer, problem = self.collect()
        if sent is None:
            return False
        if capture.on:
            capture.observe(TrafficRecord(sent.at, "tx", sent.frame, "tcp"))
            if answer:
                capture.observe(TrafficRecord(time.time(), "rx", answer, "tcp"))
        if audit is not None:
            audit.record_write(
                registers.REG_STOP, [1], single=True, error=LinkError(problem) if problem else None
            )
        if problem is not None:
            _log.warning("stop line: %s; the stop went out on the main link too", problem)
        return problem is None and sent is expected

    def close(self) -> None:
        with self._lock:
            self._drop("")

    # --- internals (lock held) -------------------------------------------------------------
    def _open(self, now: float) -> None:
        settings = self._settings
        assert settings is not None
        timeout = settings.effective_poll_timeout
        with self._lock:
            try:
                sock = socket.create_connection((settings.host, settings.port), timeout=timeout)
                sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            except OSError as exc:
                self._fail(f"cannot open it: {str(exc.strerror or exc).lower()}", now)
                return
            self._sock = sock
            self._pending = None
            try:
                self._exchange(frames.read_request(registers.STATUS_BLOCK_START, 1))
            except (LinkError, ResponseTimeout, MalformedResponse) as exc:
                self._fail(f"no good answer on it: {exc}", now)
                return
            self.opened_at = now
            self._next_keepalive = now + KEEPALIVE
            self._failures = 0
            self.why_not = ""
            _log.info("stop line open to %s", settings.endpoint)

    def _fail(self, why: str, now: float) -> None:
        delay = RETRY_DELAYS[min(self._failures, len(RETRY_DELAYS) - 1)]
        self._failures += 1
        self._retry_at = now + delay
        self.why_not = why
        _log.info("stop line: %s (next try in %g s)", why, delay)
        self._drop(why)

    def _drop(self, _why: str) -> None:
        sock, self._sock = self._sock, None
        self._pending = None
        if sock is not None:
            try:
                sock.close()
            except OSError:
                pass

    def _collect_locked(self) -> bytes:
        pending = self._pending
        if pending is None:
            return b""
        self._pending = None
        request = frames.write_single_request(registers.REG_STOP, 1)
        return self._read_answer(request, pending.tid)

    def _exchange(self, request: frames.Request) -> bytes:
        sock, settings = self._sock, self._settings
        assert sock is not None and settings is not None
        self._tid = self._tid % 65000 + 1
        try:
            sock.sendall(frames.encode_request("tcp", request, settings.unit, self._tid))
        except OSError as exc:
            raise LinkError(f"lost the stop line: {str(exc.strerror or exc).lower()}") from None
        return self._read_answer(request, self._tid)

    def _read_answer(self, request: frames.Request, tid: int) -> bytes:
        """The checked answer's bytes (an exception answer is an error here: nothing on this
        line expects one)."""
        sock, settings = self._sock, self._settings
        assert sock is not None and settings is not None
        timeout = settings.effective_poll_timeout
        deadline = time.monotonic() + timeout
        buf = b""
        while True:
            need = frames.frame_need("tcp", request, settings.unit, tid, buf)
            if len(buf) >= need:
                break
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise ResponseTimeout(f"no answer on the stop line within {timeout:g} s")
            sock.settimeout(max(remaining, 1e-4))
            try:
                data = sock.recv(_RECV_SIZE)
            except TimeoutError:
                continue
            except OSError as exc:
                raise LinkError(f"lost the stop line: {str(exc.strerror or exc).lower()}") from None
            if not data:
                raise LinkError("the controller closed the stop line")
            buf += data
        if len(buf) > need:
            raise MalformedResponse(
                f"{len(buf) - need} bytes more than the {need}-byte answer",
                field="length",
                expected=need,
                got=len(buf),
            )
        function, data = frames.decode_answer("tcp", buf)
        if function & 0x80:
            raise LinkError(f"the controller refused a request on the stop line (exception {data[0]})")
        return buf
