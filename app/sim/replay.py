"""Traffic replay (``teachpad-sim --replay CAPTURE``): a field capture answers at the desk.

A traffic capture -- the traffic inspector's export (``*.csv`` with a header, or tab-separated
text), or a support bundle (``*.zip``, its ``traffic.txt``: the same text) -- is read into
request/answer pairs (:func:`read_capture`): each request frame (``Tx``) and the answer that came
back for it (``Rx``: by transaction id over TCP, the next frame over RTU; a request never answered
stays unanswered).

:class:`ReplayBook` answers each request the desk's TeachPad sends with what the captured
controller answered to the same request: matched by unit, function, address (and register count
for reads and multiple writes), in order -- the n-th read of the pose block gets the n-th captured
answer of that read. Reads asked more often than the capture holds get the last captured answer
again (the desk's TeachPad polls on after the capture ends; counted as ``repeated``). A write
whose values differ from the captured one's is answered as captured and noted. What cannot be
matched -- a request the capture never had, a write asked more often than captured -- is logged
and answered with Modbus exception 4 (server device failure: the capture has no answer for it);
:attr:`ReplayBook.unmatched` keeps them. A captured request that was never answered (the field's
timeout) is not answered now either.

:class:`ReplayServer` serves the book over Modbus TCP (MBAP) on a thread of its own. The answer is
the captured answer frame with the desk request's transaction id (its protocol id, length, unit
and PDU as captured, byte for byte); an RTU capture's answers are sent as MBAP frames (unit and
PDU as captured, the CRC dropped), so a serial-line problem is replayed over TCP.
"""

from __future__ import annotations

import asyncio
import csv
import io
import logging
import struct
import threading
import zipfile
from collections import deque
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

from app.errors import InvalidInput

__all__ = [
    "EXCEPTION_UNMATCHED",
    "Exchange",
    "ReplayBook",
    "ReplayError",
    "ReplayServer",
    "Unmatched",
    "parse_capture_text",
    "read_capture",
]

log = logging.getLogger(__name__)

EXCEPTION_UNMATCHED = 0x04  # server device failure: the capture has no answer for this request
_MAX_CAPTURE_BYTES = 256 * 1024 * 1024
_MBAP = struct.Struct(">HHHB")
_READS = (0x03, 0x04)
_RANGED = (0x03, 0x04, 0x0F, 0x10)  # the request names a count: part of the match


class ReplayError(InvalidInput):
    """A capture that cannot be replayed; the message names the file and the line."""


@dataclass(frozen=True)
class Frame:
    line: int  # in the capture file, 1-based
    direction: Literal["tx", "rx"]
    data: bytes
    when: str  # as written in the capture


@dataclass(frozen=True)
class Exchange:
    """One captured request (its unit and PDU) and the answer frame that came back (None: none).
    ``answer`` is the rest of the MBAP frame after the transaction id (protocol id, length, unit,
    PDU), ready to follow the desk request's transaction id."""

    line: int
    unit: int
    pdu: bytes
    answer: bytes | None

    @property
    def key(self) -> tuple[object, ...]:
        return request_key(self.unit, self.pdu)


def request_key(unit: int, pdu: bytes) -> tuple[object, ...]:
    """What a request is matched by: unit, function, address, and the count of a ranged one."""
    fc = pdu[0] if pdu else -1
    if len(pdu) >= 5 and fc in _RANGED:
        address, count = struct.unpack(">HH", pdu[1:5])
        return (unit, fc, address, count)
    if len(pdu) >= 3 and fc in (0x05, 0x06):
        return (unit, fc, struct.unpack(">H", pdu[1:3])[0])
    return (unit, fc, pdu)


def describe(unit: int, pdu: bytes) -> str:
    """``read 412..511 (unit 1)``, ``write 440 (unit 1)`` ... for the log and the report."""
    key = request_key(unit, pdu)
    if len(key) == 4:
        _, fc, address, count = key
        verb = "read" if fc in _READS else f"write (fc 0x{fc:02X})" if fc != 0x10 else "write"
        return f"{verb} {address}..{int(str(address)) + int(str(count)) - 1} (unit {unit})"
    if len(key) == 3 and isinstance(key[2], int):
        return f"write {key[2]} (fc 0x{int(str(key[1])):02X}, unit {unit})"
    return f"request {pdu.hex(' ').upper()} (unit {unit})"


# --- reading a capture ---------------------------------------------------------------------------


def _hex_bytes(text: str, where: str) -> bytes:
    try:
        return bytes.fromhex(text.replace(" ", "").replace("…", ""))
    except ValueError:
        raise ReplayError(f"{where}: the bytes column is not hex: {text[:40]!r}") from None


def _rows(text: str) -> Iterable[tuple[int, list[str]]]:
    """The capture's rows: the CSV export (header ``time,direction,bytes,meaning``) or the
    tab-separated text (the .txt export, a support bundle's traffic.txt)."""
    lines = text.lstrip("\ufeff").splitlines()
    first = lines[0] if lines else ""
    if first.startswith("time,direction,bytes"):
        for number, row in enumerate(csv.reader(io.StringIO("\n".join(lines[1:]))), start=2):
            yield number, row
        return
    for number, line in enumerate(lines, start=1):
        if line.strip():
            yield number, line.split("\t")


def parse_capture_text(text: str, source: str = "the capture") -> list[Frame]:
    """The frames of a capture's text (see :func:`_rows`); :class:`ReplayError` names a bad line."""
    frames: list[Frame] = []
    for number, row in _rows(text):
        where = f"{source}, line {number}"
        if len(row) < 3:
            raise ReplayError(f"{where}: expected time, direction and bytes, got {len(row)} field(s)")
        direction = row[1].strip().lower()
        if direction not in ("tx", "rx"):
            raise ReplayError(f"{where}: the direction must be Tx or Rx, got {row[1][:10]!r}")
        if "…" in row[2]:
            raise ReplayError(
                f"{where}: the frame is cut short (…): export the capture, not a copy of the table"
            )
        frames.append(Frame(number, "tx" if direction == "tx" else "rx", _hex_bytes(row[2], where), row[0]))
    return frames


def _capture_text(path: Path) -> str:
    try:
        if path.stat().st_size > _MAX_CAPTURE_BYTES:
            raise ReplayError(f"{path.name}: larger than {_MAX_CAPTURE_BYTES // (1024 * 1024)} MB")
        if zipfile.is_zipfile(path):
            with zipfile.ZipFile(path) as bundle:
                if "traffic.txt" not in bundle.namelist():
                    raise ReplayError(
                        f"{path.name}: a zip without traffic.txt (no Modbus traffic in this bundle)"
                    )
                return bundle.read("traffic.txt").decode("utf-8-sig")
        return path.read_bytes().decode("utf-8-sig")
    except OSError as exc:
        raise ReplayError(f"{path}: cannot read the capture ({exc.strerror or exc})") from None
    except (UnicodeDecodeError, zipfile.BadZipFile) as exc:
        raise ReplayError(f"{path.name}: not a traffic capture ({exc})") from None


def read_capture(path: str | Path) -> list[Exchange]:
    """The request/answer pairs of a capture file (see the module docstring)."""
    p = Path(path)
    frames = parse_capture_text(_capture_text(p), p.name)
    exchanges = pair_frames(frames)
    if not exchanges:
        raise ReplayError(f"{p.name}: no request in the capture")
    return exchanges


def _is_mbap(data: bytes) -> bool:
    return len(data) >= 8 and data[2:4] == b"\x00\x00" and _MBAP.unpack(data[:7])[2] == len(data) - 6


def pair_frames(frames: Sequence[Frame]) -> list[Exchange]:
    """Requests in order, each with its answer (MBAP: by transaction id; RTU: the next frame)."""
    out: list[Exchange | None] = []
    waiting: dict[int, int] = {}  # transaction id (RTU: 0) -> index in out of its request
    pending: dict[int, tuple[Frame, int, bytes]] = {}
    for frame in frames:
        tcp = _is_mbap(frame.data)
        if not tcp and len(frame.data) < 4:
            raise ReplayError(f"line {frame.line}: a frame of {len(frame.data)} bytes is no Modbus frame")
        tid = _MBAP.unpack(frame.data[:7])[0] if tcp else 0
        unit = frame.data[6] if tcp else frame.data[0]
        pdu = frame.data[7:] if tcp else frame.data[1:-2]
        if frame.direction == "tx":
            waiting[tid] = len(out)
            pending[tid] = (frame, unit, pdu)
            out.append(Exchange(frame.line, unit, pdu, None))
            continue
        index = waiting.pop(tid, None)
        if index is None:
            log.info("capture line %d: an answer without its request: left out", frame.line)
            continue
        request, req_unit, req_pdu = pending.pop(tid)
        answer = frame.data[2:] if tcp else _MBAP.pack(0, 0, len(pdu) + 1, unit)[2:] + pdu
        out[index] = Exchange(request.line, req_unit, req_pdu, answer)
    return [e for e in out if e is not None]


# --- answering -----------------------------------------------------------------------------------


@dataclass(frozen=True)
class Unmatched:
    """A request the capture has no answer for: what it was and why."""

    unit: int
    pdu: bytes
    why: str

    @property
    def text(self) -> str:
        return f"{describe(self.unit, self.pdu)}: {self.why}"


@dataclass
class _Queue:
    answers: deque[Exchange]
    last: Exchange | None = None


@dataclass
class ReplayBook:
    """The captured answers by request (see the module docstring); thread-safe."""

    exchanges: Sequence[Exchange]
    answered: int = 0
    repeated: int = 0
    differing: list[str] = field(default_factory=list)
    unmatched: list[Unmatched] = field(default_factory=list)

    def __post_init__(self) -> None:
        self._lock = threading.Lock()
        self._queues: dict[tuple[object, ...], _Queue] = {}
        for exchange in self.exchanges:
            self._queues.setdefault(exchange.key, _Queue(deque())).answers.append(exchange)

    def answer(self, unit: int, pdu: bytes) -> bytes | None:
        """The captured answer (after the transaction id) to this request; an exception answer
        when there is none (:attr:`unmatched`); None when the captured one was never answered."""
        with self._lock:
            queue = self._queues.get(request_key(unit, pdu))
            exchange = self._next(queue, unit, pdu)
            if exchange is None:
                return _exception(unit, pdu)
            if exchange.pdu != pdu:
                note = f"{describe(unit, pdu)}: values differ from the capture's (line {exchange.line})"
                self.differing.append(note)
                log.info("replay: %s", note)
            self.answered += 1
            return exchange.answer

    def _next(self, queue: _Queue | None, unit: int, pdu: bytes) -> Exchange | None:
        if queue is None:
            self._unmatched(unit, pdu, "not in the capture")
            return None
        if queue.answers:
            queue.last = queue.answers.popleft()
            return queue.last
        if queue.last is not None and pdu[:1] and pdu[0] in _READS:
            self.repeated += 1
            return queue.last
        self._unmatched(unit, pdu, "asked more often than the capture holds")
        return None

    def _unmatched(self, unit: int, pdu: bytes, why: str) -> None:
        item = Unmatched(unit, pdu, why)
        self.unmatched.append(item)
        log.warning("replay: %s: answered with Modbus exception %d", item.text, EXCEPTION_UNMATCHED)
        return None

    def summary(self) -> str:
        with self._lock:
            left = sum(len(q.answers) for q in self._queues.values())
            return (
                f"{self.answered} requests answered from the capture ({self.repeated} by repeating its last "
                f"answer), {len(self.unmatched)} unmatched, {len(self.differing)} with other values, "
                f"{left} captured answers not asked for"
            )


def _exception(unit: int, pdu: bytes) -> bytes:
    fc = (pdu[0] if pdu else 0) | 0x80
    body = bytes((unit, fc & 0xFF, EXCEPTION_UNMATCHED))
    return struct.pack(">HH", 0, len(body)) + body


class ReplayServer:
    """The book served over Modbus TCP on ``host:port`` (0: a free port), on its own thread."""

    START_TIMEOUT = 5.0

    def __init__(self, book: ReplayBook, host: str = "127.0.0.1", port: int = 0) -> None:
        self.book = book
        self.host = host
        self._port = port
        self._loop: asyncio.AbstractEventLoop | None = None
        self._server: asyncio.Server | None = None
        self._thread: threading.Thread | None = None
        self._writers: set[asyncio.StreamWriter] = set()
        self.requests = 0

    @property
    def port(self) -> int:
        return self._port

    @property
    def endpoint(self) -> str:
        return f"{self.host}:{self._port}"

    def start(self) -> None:
        """Listen; returns once bound (OSError when it cannot)."""
        ready = threading.Event()
        errors: list[BaseException] = []
        loop = self._loop = asyncio.new_event_loop()

        def run() -> None:
            asyncio.set_event_loop(loop)
            try:
                self._server = loop.run_until_complete(
                    asyncio.start_server(self._serve, self.host, self._port)
                )
            except OSError as exc:
                errors.append(exc)
                ready.set()
                loop.close()
                return
            ready.set()
            loop.run_forever()
            loop.close()

        self._thread = threading.Thread(target=run, name="sim-replay", daemon=True)
        self._thread.start()
        if not ready.wait(self.START_TIMEOUT) or errors:
            raise OSError(f"replay could not listen on {self.endpoint}: {errors[0] if errors else 'timeout'}")
        assert self._server is not None
        self._port = int(self._server.sockets[0].getsockname()[1])

    def stop(self) -> None:
        loop, server = self._loop, self._server
        if loop is None or server is None or loop.is_closed():
            return

        async def close() -> None:
            server.close()
            for writer in list(self._writers):
                writer.close()
            await server.wait_closed()

        try:
            asyncio.run_coroutine_threadsafe(close(), loop).result(2.0)
        except Exception as exc:  # the loop goes away anyway
            log.warning("replay shutdown: %s", exc)
        loop.call_soon_threadsafe(loop.stop)
        if self._thread is not None:
            self._thread.join(2.0)

    def __enter__(self) -> ReplayServer:
        self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()

    async def _serve(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        self._writers.add(writer)
        try:
            while True:
                header = await reader.readexactly(7)
                tid, protocol, length, unit = _MBAP.unpack(header)
                if protocol != 0 or not 2 <= length <= 254:
                    log.warning("replay: not an MBAP frame (%s): connection closed", header.hex(" ").upper())
                    return
                pdu = await reader.readexactly(length - 1)
                self.requests += 1
                answer = self.book.answer(unit, pdu)
                if answer is not None:  # None: the captured controller never answered it either
                    writer.write(struct.pack(">H", tid) + answer)
                    await writer.drain()
        except (asyncio.IncompleteReadError, ConnectionError):
            pass
        finally:
            self._writers.discard(writer)
            writer.close()
