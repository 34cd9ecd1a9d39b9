"""RobotClient: one method per controller operation, typed results, typed errors.

The client owns one synchronous pymodbus client (TCP, RTU over serial, or RTU framing over
TCP for tests) and is not thread-safe: one thread owns it (the GUI worker, or the CLI).

Decisions on the open questions of PROTOCOL.md section 7 that live here:

* **Work mode**: before a motion/create/teach command the client reads the status (it needs
  it as the tracker's "before" anyway) and writes 444 <- auto only when the mode reads manual
  (or an unknown value); Modbus-teach (2) counts as auto.
* **Cached parameters**: GV245 (tool), GV241 (user frame) and the external-axis offsets
  GV236-240 are written only when they differ from what this client last wrote; the cache is
  dropped whenever the connection is (re)made or fails, and by :meth:`invalidate_cache`.
* **Completion rule** (``ConnectionSettings.completion``, see app/link/tracker.py): "sentinel"
  writes GV291 <- 0xA5 before each create/teach/move command (one extra 0x10) so the
  controller's own write proves the result; "observe" never writes GV291 and may end an
  instant command *done, unconfirmed*; "auto" (default) probes once, before the first such
  command: write the sentinel, wait ``SENTINEL_PROBE_SETTLE``, read it back -- kept: sentinel;
  Modbus exception or overwritten: observe. Never in monitor-only mode (no command is sent).
* Control registers 440-445 are written with 0x06 only; raw multi-register writes that touch
  them are refused (:class:`InvalidInput`).
* A request that timed out closes the link (the next request reconnects), so a late answer
  is never read as the next request's.
* Traffic observers are called synchronously in the client's thread, inside the request:
  keep them short (the GUI should only queue the record).
"""

from __future__ import annotations

import dataclasses
import enum
import logging
import math
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Any, Literal

from pymodbus.client import ModbusSerialClient, ModbusTcpClient
from pymodbus.exceptions import ConnectionException, ModbusException, ModbusIOException
from pymodbus.framer import FramerType

from app import timing
from app.errors import (
    InvalidInput,
    LinkError,
    ModbusExceptionError,
    ResponseTimeout,
    WriteBlocked,
)
from app.link.stats import LinkStats
from app.link.tracker import CommandTracker, CompletionRule, command_text
from app.models import CommandResult, ControllerStatus, Pose
from app.protocol import registers
from app.protocol.codec import WordOrder, check_float32, decode_floats, encode_floats
from app.protocol.datetime_regs import ControllerClock, DateTimeLayout, decode_clock
from app.protocol.enums import (
    STATUS_SENTINEL,
    Alarm,
    CommandKind,
    CommandStatus,
    ControllerMode,
    ProgramMotionMode,
    ProgramState,
    RunCommand,
    TeachFrame,
    WorkMode,
    decode_command_status,
    decode_status_registers,
)

__all__ = [
    "ConnectionSettings",
    "RobotClient",
    "StepFrame",
    "TrafficRecord",
]

_log = logging.getLogger(__name__)


_CONTROL_REGISTERS = range(registers.REG_RUN_COMMAND, registers.REG_GO_ZERO + 1)  # 440..445: 0x06 only
_MAX_REGISTER = 0xFFFF
_GENERAL_POSE_LAST_START = registers.GV_GENERAL_LAST - 5  # six GVs must fit in GV0..GV99

_MODBUS_EXCEPTION_TEXT: dict[int, str] = {
    0x01: "illegal function",
    0x02: "illegal data address",
    0x03: "illegal data value",
    0x04: "server device failure",
    0x05: "acknowledge",
    0x06: "server device busy",
    0x07: "negative acknowledge",
    0x08: "memory parity error",
    0x0A: "gateway path unavailable",
    0x0B: "gateway target device failed to respond",
}


def _seconds(value: float) -> str:
    return str(round(value, 3))


class StepFrame(enum.Enum):
    """Frame of an incremental move (function 1)."""

    JOINT = "joint"
    BASE = "base"

    @property
    def command(self) -> RunCommand:
        return RunCommand.STEP_JOINT if self is StepFrame.JOINT else RunCommand.STEP_BASE


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


@dataclass(frozen=True, slots=True)
class TrafficRecord:
    """One frame as on the wire (MBAP included for TCP, CRC included for RTU)."""

    t: float  # time.time() when the frame was sent / decoded
    direction: Literal["tx", "rx"]
    frame: bytes
    transport: Literal["tcp", "rtu"]


# --------------------------------------------------------------------------------------------
# Input validation (before the wire)
# --------------------------------------------------------------------------------------------


def _check_int(value: object, lo: int, hi: int, name: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        if isinstance(value, float) and value.is_integer():
            value = int(value)
        else:
            raise InvalidInput(f"{name} must be an integer, got {value!r}")
    if not lo <= value <= hi:
        raise InvalidInput(f"{name} must be in {lo}..{hi}, got {value}")
    return value


def _check_float(value: object, name: str, lo: float | None = None, hi: float | None = None,
                 *, lo_open: bool = False) -> float:
    try:
        number = check_float32(value, name)  # type: ignore[arg-type]
    except ValueError as exc:
        raise InvalidInput(str(exc)) from None
    if lo is not None and (number < lo or (lo_open and number == lo)):
        bound = f"> {lo:g}" if lo_open else f">= {lo:g}"
        raise InvalidInput(f"{name} must be {bound}, got {number:g}")
    if hi is not None and number > hi:
        raise InvalidInput(f"{name} must be <= {hi:g}, got {number:g}")
    return number


def _check_floats(values: Sequence[float], count: int, name: str) -> list[float]:
    if isinstance(values, (str, bytes)):
        raise InvalidInput(f"{name} must be {count} numbers")
    items = list(values)
    if len(items) != count:
        raise InvalidInput(f"{name} needs {count} values, got {len(items)}")
    return [_check_float(v, f"{name}[{i}]") for i, v in enumerate(items)]


def _check_enum(value: Any, enum_type: type[enum.IntEnum], name: str) -> Any:
    try:
        return enum_type(value)
    except (ValueError, TypeError):
        allowed = ", ".join(f"{m.name.lower()} ({m.value})" for m in enum_type)
        raise InvalidInput(f"{name} must be one of {allowed}, got {value!r}") from None


def _check_tool(tool: int) -> int:
    # GV245: 200 = no tool frame, N = tool N+1.
    return _check_int(tool, 0, registers.TOOL_NONE, "tool frame")


def _gv_name(register: int) -> str:
    n, half = registers.reg_to_gv(register)
    return f"GV{n}_{half}"


def _range_name(address: int, count: int) -> str:
    last = address + count - 1
    if count == 1:
        return f"register {address} ({_gv_name(address)})"
    if address % 2 == 0 and last % 2 == 1:
        first_gv, last_gv = address // 2, last // 2
        gvs = f"GV{first_gv}" if first_gv == last_gv else f"GV{first_gv}..GV{last_gv}"
    else:
        gvs = f"{_gv_name(address)}..{_gv_name(last)}"
    return f"registers {address}..{last} ({gvs})"


def _check_settings(s: ConnectionSettings) -> None:
    _check_int(s.port, 1, 0xFFFF, "port")
    _check_int(s.unit, 0, 247, "unit id")
    _check_float(s.timeout, "timeout", 0.0, lo_open=True)
    _check_int(s.retries, 0, 100, "retries")
    if not isinstance(s.word_order, WordOrder):
        raise InvalidInput(f"word order must be a WordOrder, got {s.word_order!r}")
    if s.framer not in ("socket", "rtu"):
        raise InvalidInput(f"framer must be socket or rtu, got {s.framer!r}")
    if s.parity not in ("N", "E", "O"):
        raise InvalidInput(f"parity must be N, E or O, got {s.parity!r}")
    if not s.point_id_min <= s.point_id_max:
        raise InvalidInput("point_id_min must not exceed point_id_max")
    if s.completion not in ("auto", "sentinel", "observe"):
        raise InvalidInput(f"completion must be auto, sentinel or observe, got {s.completion!r}")
    if s.unconfirmed_after is not None:
        _check_float(s.unconfirmed_after, "unconfirmed_after", 0.0, lo_open=True)


# --------------------------------------------------------------------------------------------
# The client
# --------------------------------------------------------------------------------------------

TrafficObserver = Callable[[TrafficRecord], None]
ProgressCallback = Callable[[int, int], bool]


class RobotClient:
    """One method per controller operation. Blocking; owned by one thread."""

    def __init__(self, settings: ConnectionSettings) -> None:
        _check_settings(settings)
        self.settings = settings
        self._observers: list[TrafficObserver] = []
        self._observing = False  # checked first on the hot path
        self._rx_buffer = b""
        self._mb: Any = self._make_modbus_client()
        self._tool_cache: int | None = None
        self._user_frame_cache: int | None = None
        self._ext_cache: tuple[float, ...] | None = None
        self._last_kind: CommandKind | None = None
        self._teach_frame: TeachFrame | None = None
        self.last_status: ControllerStatus | None = None
        self.last_tracker: CommandTracker | None = None
        self.write_count = 0  # writes handed to the link (the CLI uses it to know what to undo)
        self._stats = LinkStats()
        self._gv291_writable: bool | None = None  # completion "auto": None until probed
        self._ack_latency = 0.0  # s, decaying maximum of the acknowledgement times seen

    # -- connection ----------------------------------------------------------------------
    def _make_modbus_client(self) -> Any:
        s = self.settings
        common: dict[str, Any] = {
            "timeout": s.timeout,
            "retries": s.retries,
            "trace_packet": self._trace_packet,
            "trace_pdu": self._trace_pdu,
        }
        if s.serial_port is not None:
            return ModbusSerialClient(
                s.serial_port, framer=FramerType.RTU, baudrate=s.baudrate, parity=s.parity,
                stopbits=s.stopbits, bytesize=s.bytesize, **common,
            )
        framer = FramerType.RTU if s.framer == "rtu" else FramerType.SOCKET
        return ModbusTcpClient(s.host, port=s.port, framer=framer, **common)

    def connect(self) -> None:
        """Open the link; raises :class:`LinkError` when the controller cannot be reached."""
        self.invalidate_cache()
        if not self._mb.connect():
            raise LinkError(f"cannot connect to the controller at {self.settings.endpoint}")

    def close(self) -> None:
        self._mb.close()
        self.invalidate_cache()

    @property
    def connected(self) -> bool:
        return bool(self._mb.connected)

    def __enter__(self) -> RobotClient:
        self.connect()
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def invalidate_cache(self) -> None:
        """Forget which tool / user frame / external offsets were written last."""
        self._tool_cache = None
        self._user_frame_cache = None
        self._ext_cache = None

    @property
    def stats(self) -> LinkStats:
        """The link's counters so far (a snapshot)."""
        return self._stats

    def _count(self, field: str, error: str | None = None) -> None:
        changes: dict[str, int | str] = {field: getattr(self._stats, field) + 1}
        if error is not None:
            changes["last_error"] = error
        self._stats = dataclasses.replace(self._stats, **changes)  # type: ignore[arg-type]

    # -- observers -----------------------------------------------------------------------
    def add_observer(self, cb: TrafficObserver) -> None:
        self._observers.append(cb)
        self._observing = True

    def remove_observer(self, cb: TrafficObserver) -> None:
        if cb in self._observers:
            self._observers.remove(cb)
        self._observing = bool(self._observers)

    def _emit(self, direction: Literal["tx", "rx"], frame: bytes) -> None:
        record = TrafficRecord(time.time(), direction, bytes(frame), self.settings.transport)
        for cb in list(self._observers):
            try:
                cb(record)
            except Exception:  # an observer must not break the link
                _log.exception("traffic observer %r failed", cb)

    def _trace_packet(self, sending: bool, data: bytes) -> bytes:
        if not self._observing:
            return data
        if sending:
            self._emit("tx", data)
        else:
            self._rx_buffer = data  # may be partial; emitted once a PDU is decoded from it
        return data

    def _trace_pdu(self, sending: bool, pdu: Any) -> Any:
        if not self._observing or sending:
            return pdu
        buffer, self._rx_buffer = self._rx_buffer, b""
        if buffer:
            # The buffer may start with a late frame of an earlier request: keep the tail that
            # is this PDU's frame (MBAP 7 + fc + data for TCP; unit + fc + data + CRC for RTU).
            body = 1 + len(pdu.encode())
            size = body + (7 if self.settings.transport == "tcp" else 3)
            self._emit("rx", buffer[-size:] if len(buffer) > size else buffer)
        return pdu

    # -- the one place that talks to pymodbus --------------------------------------------
    def _call(self, what: str, method: Callable[..., Any], *args: Any, timeout: float | None = None,
              **kwargs: Any) -> Any:
        was_connected = bool(self._mb.connected)
        if not was_connected:
            self.invalidate_cache()  # a new connection may mean a restarted controller
        params = self._mb.comm_params
        saved_timeout = params.timeout_connect
        if timeout is not None:
            params.timeout_connect = timeout  # pymodbus reads it per receive
        self._count("requests")
        try:
            response = method(*args, device_id=self.settings.unit, **kwargs)
        except ConnectionException as exc:
            self.invalidate_cache()
            self._mb.close()
            verb = "lost the connection to" if was_connected else "cannot connect to"
            message = f"{verb} the controller at {self.settings.endpoint}"
            self._count("link_errors", message)
            raise LinkError(message) from exc
        except ModbusIOException as exc:
            # A late answer would be read as the next request's: start again on a fresh link.
            self.invalidate_cache()
            self._mb.close()
            total = (timeout or self.settings.timeout) * (self.settings.retries + 1)
            message = f"controller did not answer within {_seconds(total)} s ({self.settings.endpoint})"
            self._count("timeouts", message)
            self._count("resyncs")
            raise ResponseTimeout(message) from exc
        except ModbusException as exc:
            self.invalidate_cache()
            raise LinkError(f"Modbus link error with {self.settings.endpoint}: {exc}") from exc
        except OSError as exc:
            self.invalidate_cache()
            self._mb.close()
            raise LinkError(f"link error with {self.settings.endpoint}: {exc}") from exc
        finally:
            params.timeout_connect = saved_timeout
        if response is None:
            raise ResponseTimeout(f"controller did not answer ({self.settings.endpoint})")
        if response.isError():
            code = int(getattr(response, "exception_code", 0))
            text = _MODBUS_EXCEPTION_TEXT.get(code, f"exception code {code}")
            message = f"controller refused {what}: {text}"
            self._count("exceptions", message)
            raise ModbusExceptionError(int(response.function_code) & 0x7F, code, message)
        self._count("answers")
        return response

    def _read(self, address: int, count: int, timeout: float | None = None) -> list[int]:
        response = self._call(
            f"read of {_range_name(address, count)}", self._mb.read_holding_registers,
            address, count=count, timeout=timeout,
        )
        regs = [int(r) & 0xFFFF for r in response.registers]
        if len(regs) < count:
            raise ResponseTimeout(
                f"controller answered {len(regs)} of {count} registers from {address} "
                f"({self.settings.endpoint})"
            )
        return regs[:count]

    def _require_writable(self, what: str) -> None:
        if self.settings.monitor_only:
            raise WriteBlocked(f"monitor-only mode: {what} was not sent")

    def _write(self, address: int, values: Sequence[int], *, single: bool = False) -> None:
        """The write guard: every write to the controller passes here."""
        name = _range_name(address, len(values))
        self._require_writable(f"write to {name}")
        if not values:
            raise InvalidInput("nothing to write")
        if single:
            if len(values) != 1:
                raise InvalidInput("a single-register write takes one value")
            _log.debug("write 0x06 %s <- %d", name, values[0])
            self.write_count += 1
            self._call(f"write to {name}", self._mb.write_register, address, int(values[0]))
        else:
            _log.debug("write 0x10 %s <- %s", name, " ".join(f"{v:04X}" for v in values))
            self.write_count += 1
            self._call(f"write to {name}", self._mb.write_registers, address, [int(v) for v in values])

    def _write_floats(self, gv: int, values: Sequence[float]) -> None:
        self._write(registers.gv_reg(gv), encode_floats(values, self.settings.word_order))

    def _write_control(self, register: int, value: int) -> None:
        self._write(register, [value], single=True)

    # -- raw access ----------------------------------------------------------------------
    def read_registers(self, addr: int, count: int) -> list[int]:
        addr = _check_int(addr, 0, _MAX_REGISTER, "register address")
        count = _check_int(count, 1, _MAX_REGISTER + 1 - addr, "register count")
        out: list[int] = []
        while count > 0:
            n = min(count, registers.MAX_READ_REGISTERS)
            out.extend(self._read(addr, n))
            addr += n
            count -= n
        return out

    def write_register(self, addr: int, value: int) -> None:
        """0x06 write of one register (the way 440..445 must be written)."""
        addr = _check_int(addr, 0, _MAX_REGISTER, "register address")
        value = _check_int(value, 0, 0xFFFF, "register value")
        self._write(addr, [value], single=True)

    def write_registers(self, addr: int, values: Sequence[int]) -> None:
        """0x10 write (split every 123 registers); refuses the control registers 440..445."""
        addr = _check_int(addr, 0, _MAX_REGISTER, "register address")
        regs = [_check_int(v, 0, 0xFFFF, "register value") for v in values]
        if not regs:
            raise InvalidInput("nothing to write")
        if addr + len(regs) - 1 > _MAX_REGISTER:
            raise InvalidInput("write goes past register 65535")
        end = addr + len(regs)
        if addr < _CONTROL_REGISTERS.stop and end > _CONTROL_REGISTERS.start:
            raise InvalidInput(
                "registers 440..445 (GV220..GV222) are control registers written one at a time "
                "with 0x06; use write_register or the command methods"
            )
        for i in range(0, len(regs), registers.MAX_WRITE_REGISTERS):
            self._write(addr + i, regs[i : i + registers.MAX_WRITE_REGISTERS])

    def read_gv(self, n: int, count: int = 1) -> list[float]:
        n = _check_int(n, 0, _MAX_REGISTER // 2, "GV index")
        count = _check_int(count, 1, (_MAX_REGISTER + 1) // 2 - n, "GV count")
        return decode_floats(self.read_registers(registers.gv_reg(n), 2 * count), self.settings.word_order)

    def write_gv(self, n: int, values: Sequence[float]) -> None:
        n = _check_int(n, 0, _MAX_REGISTER // 2, "GV index")
        floats = [_check_float(v, f"GV{n + i}") for i, v in enumerate(values)]
        self.write_registers(registers.gv_reg(n), encode_floats(floats, self.settings.word_order))

    # -- reads ---------------------------------------------------------------------------
    def read_pose(self, *, timeout: float | None = None) -> Pose:
        """Pose, external axes and joints (GV206..GV255) in one FC03 of 100 registers.

        ``timeout`` overrides the request timeout (the poller passes the poll timeout).
        """
        regs = self._read(registers.POSE_BLOCK_START, registers.POSE_BLOCK_COUNT, timeout)
        order = self.settings.word_order

        def gvs(gv: int, count: int) -> list[float]:
            start = registers.gv_reg(gv) - registers.POSE_BLOCK_START
            return decode_floats(regs[start : start + 2 * count], order)

        x, y, z, a, b, c = gvs(registers.GV_POSE, 6)
        e = gvs(registers.GV_EXT_AXES, registers.NUM_EXTERNAL_AXES)
        joints = tuple(gvs(registers.GV_JOINTS, registers.NUM_ROBOT_AXES))
        return Pose(x, y, z, a, b, c, ext=(e[0], e[1], e[2], e[3], e[4]), joints=joints)

    def read_status(self, with_clock: bool = False, *, timeout: float | None = None) -> ControllerStatus:
        """Table 2 (560..583) in one FC03; the clock (576..579) comes from the same block."""
        regs = self._read(registers.STATUS_BLOCK_START, registers.STATUS_BLOCK_COUNT, timeout)
        status = self._decode_status(regs, with_clock)
        self.last_status = status
        return status

    def _decode_status(self, regs: Sequence[int], with_clock: bool) -> ControllerStatus:
        base = registers.STATUS_BLOCK_START
        mode_raw = regs[registers.REG_CONTROLLER_MODE - base]
        state_raw = regs[registers.REG_PROGRAM_STATE - base]
        mode: ControllerMode | int
        state: ProgramState | int
        try:
            mode = ControllerMode(mode_raw)
        except ValueError:
            mode = mode_raw
        try:
            state = ProgramState(state_raw)
        except ValueError:
            state = state_raw
        st = registers.gv_reg(registers.GV_COMMAND_STATUS) - base
        code = decode_status_registers(regs[st : st + 2], self.settings.word_order)
        clock = None
        if with_clock:
            cs = registers.gv_reg(registers.GV_DATE) - base
            clock = decode_clock(regs[cs : cs + 4], self.settings.datetime_layout)
        return ControllerStatus(mode, state, Alarm(regs[registers.REG_ALARMS - base]), code, clock)

    def read_clock(self) -> ControllerClock:
        return decode_clock(self._read(registers.gv_reg(registers.GV_DATE), 4), self.settings.datetime_layout)

    def command_status(self) -> CommandStatus:
        """GV291 decoded with the table of the last command this client sent."""
        regs = self._read(registers.gv_reg(registers.GV_COMMAND_STATUS), 2)
        return decode_command_status(self._last_kind, decode_status_registers(regs, self.settings.word_order))

    # -- plain commands (no GV291) -------------------------------------------------------
    def set_work_mode(self, mode: WorkMode) -> None:
        mode = _check_enum(mode, WorkMode, "work mode")
        self._write_control(registers.REG_WORK_MODE, int(mode))

    def stop(self) -> None:
        self._write_control(registers.REG_STOP, 1)
        tracker = self.last_tracker
        if tracker is not None and not tracker.finished:
            tracker.stopped(time.monotonic())

    def pause(self) -> None:
        self._write_control(registers.REG_PAUSE, 1)

    def resume(self) -> None:
        self._write_control(registers.REG_RESUME, 1)

    def go_zero(self, axis: int | None) -> None:
        """Send one axis (0..10 = J1..J11) or all axes (None) to zero."""
        last_axis = registers.NUM_AXES_TOTAL - 1
        value = registers.GO_ZERO_ALL if axis is None else _check_int(axis, 0, last_axis, "axis")
        self._require_writable("go to zero")
        self._ensure_auto(self.read_status())
        self._write_control(registers.REG_GO_ZERO, value)

    def run_program(self, program_id: int, mode: ProgramMotionMode = ProgramMotionMode.SINGLE_RUN,
                    cycles: int = 1, speed_ratio: int = 100) -> None:
        """446..449 in one 0x10, then 440 <- 0x01."""
        program_id = _check_int(program_id, 0, 0xFFFF, "program id")
        motion = _check_enum(mode, ProgramMotionMode, "program motion mode")
        cycles = _check_int(cycles, 0, 0xFFFF, "cycle count")
        speed_ratio = _check_int(speed_ratio, 1, 100, "program speed ratio")
        self._require_writable("run program")
        self._ensure_auto(self.read_status())
        self._write(registers.REG_PROGRAM_ID, [program_id, int(motion), cycles, speed_ratio])
        self._write_control(registers.REG_RUN_COMMAND, int(RunCommand.RUN_PROGRAM))

    # -- helpers of the four functions ---------------------------------------------------
    def _ensure_auto(self, status: ControllerStatus) -> None:
        """444 <- auto unless the (fresh) status already says auto or Modbus teach."""
        if status.mode not in (ControllerMode.AUTO, ControllerMode.MODBUS_TEACH):
            self.set_work_mode(WorkMode.AUTO)

    def ensure_auto(self) -> None:
        self._require_writable("set work mode")
        self._ensure_auto(self.read_status())

    def _prepare(self, command: RunCommand, *, auto: bool = True) -> tuple[ControllerStatus, Pose | None]:
        self._require_writable(command_text(command))
        before = self.read_status()
        before_pose = self.read_pose() if CommandKind.of(command) is CommandKind.MOVE else None
        if auto:
            self._ensure_auto(before)
        return before, before_pose

    def _write_tool(self, tool: int) -> None:
        if self._tool_cache != tool:
            self._write_floats(registers.GV_TOOL_FRAME, [float(tool)])
            self._tool_cache = tool

    def _write_user_frame(self, user: int) -> None:
        if self._user_frame_cache != user:
            self._write_floats(registers.GV_USER_FRAME, [float(user)])
            self._user_frame_cache = user

    # -- completion rule (see app/link/tracker.py) ---------------------------------------
    @property
    def completion_rule(self) -> CompletionRule | None:
        """The rule in force; None while "auto" has not probed GV291 yet."""
        mode = self.settings.completion
        if mode != "auto":
            return mode
        if self._gv291_writable is None:
            return None
        return "sentinel" if self._gv291_writable else "observe"

    def probe_gv291(self) -> bool:
        """Does the controller keep what the host writes into GV291? (Completion "auto".)

        Writes the sentinel, waits ``timing.SENTINEL_PROBE_SETTLE`` (a controller that
        re-publishes its status every scan has overwritten it by then) and reads it back. A
        Modbus exception (a read-only GV291) means no. Safe: GV291 only reports the last
        command's result, which the next command overwrites; the probe runs just before a
        command, never in monitor-only mode. The answer is kept for this client's lifetime.
        """
        self._require_writable("GV291 probe")
        try:
            self._write_floats(registers.GV_COMMAND_STATUS, [float(STATUS_SENTINEL)])
        except ModbusExceptionError as exc:
            _log.info("GV291 is read-only (%s): completion rule observe", exc)
            writable = False
        else:
            time.sleep(timing.SENTINEL_PROBE_SETTLE)
            writable = self.read_status().command_status_code == STATUS_SENTINEL
            _log.info("GV291 %s: completion rule %s", "keeps the host's value" if writable
                      else "ignores the host's writes", "sentinel" if writable else "observe")
        self._gv291_writable = writable
        return writable

    def _unconfirmed_window(self) -> float:
        """How long an unchanged 0xFF waits before "done, unconfirmed" (observe rule)."""
        base = self.settings.unconfirmed_after
        base = timing.UNCONFIRMED_AFTER if base is None else base
        learned = timing.UNCONFIRMED_LATENCY_FACTOR * self._ack_latency
        return min(max(base, learned), timing.ACK_TIMEOUT / 2)

    def _learn_latency(self) -> None:
        """Decay the learned latency by 5 % a command; take in the previous command's
        acknowledgement time (an instant command that was seen to change GV291)."""
        self._ack_latency *= 0.95
        last = self.last_tracker
        if last is None or last.result is None or last.ack_time is None or last.is_move:
            return
        self._ack_latency = max(last.ack_time - last.started, self._ack_latency)

    def begin_command(self, command: RunCommand, before: ControllerStatus, before_pose: Pose | None,
                      *, timeout: float | None = None) -> CommandTracker:
        """Write 440 <- ``command`` (parameters already written) and return its tracker.

        With the sentinel rule GV291 <- sentinel goes out first (completion "auto" probes
        GV291 before the first command).
        """
        rule: CompletionRule = "observe"
        pre_code: int | None = None
        if CommandKind.of(command) is not None:
            self._learn_latency()
            probe = self.settings.completion == "auto" and self._gv291_writable is None
            if probe and not self.probe_gv291() and self.last_status is not None:
                pre_code = self.last_status.command_status_code  # the freshest read
            rule = self.completion_rule or "observe"
            if rule == "sentinel":
                self._write_floats(registers.GV_COMMAND_STATUS, [float(STATUS_SENTINEL)])
                pre_code = STATUS_SENTINEL
        tracker = CommandTracker(command, before, before_pose, time.monotonic(), timeout=timeout,
                                 rule=rule, pre_code=pre_code,
                                 unconfirmed_after=self._unconfirmed_window())
        self._last_kind = tracker.kind
        self.last_tracker = tracker
        self._write_control(registers.REG_RUN_COMMAND, int(command))
        return tracker

    def poll(self, tracker: CommandTracker) -> CommandResult | None:
        """One status read (plus the pose for moves) fed to ``tracker``."""
        status = self.read_status()
        pose = self.read_pose() if tracker.is_move else None
        return tracker.update(status, pose, time.monotonic())

    def wait(self, tracker: CommandTracker, *, raise_errors: bool = True) -> CommandResult:
        """Poll until ``tracker`` ends; raise its typed error when it failed (by default)."""
        while True:
            result = self.poll(tracker)  # the first poll is immediate: keep the ack window small
            if result is not None:
                if raise_errors and tracker.error is not None:
                    raise tracker.error
                return result
            interval = tracker.poll_interval(time.monotonic())
            if interval > 0:
                time.sleep(interval)

    def _finish(self, tracker: CommandTracker, wait: bool) -> CommandResult:
        if wait:
            return self.wait(tracker)
        return CommandResult(tracker.command, tracker.kind, None, True, f"{tracker.text}: sent")

    def _check_point_id(self, point_id: int, name: str = "point id") -> int:
        return _check_int(point_id, self.settings.point_id_min, self.settings.point_id_max, name)

    # -- function 1: incremental move ----------------------------------------------------
    def step(self, frame: StepFrame, offsets: Sequence[float],
             ext_offsets: Sequence[float] = (0.0,) * registers.NUM_EXTERNAL_AXES, speed: float = 10.0,
             *, wait: bool = True, timeout: float | None = None) -> CommandResult:
        """Incremental move: GV200-205 (one 0x10), GV236-240 when needed, GV225, 440 <- 0x40/0x41.

        ``offsets`` are J1..J6 (degrees, joint frame) or X Y Z A B C (mm, degrees, base
        frame); ``ext_offsets`` are J7..J11. ``speed`` is rpm (joint) or mm/s (base).
        """
        if not isinstance(frame, StepFrame):
            raise InvalidInput(f"step frame must be joint or base, got {frame!r}")
        offs = _check_floats(offsets, registers.NUM_ROBOT_AXES, "offsets")
        ext = tuple(_check_floats(ext_offsets, registers.NUM_EXTERNAL_AXES, "external offsets"))
        speed = _check_float(speed, "speed", 0.0, lo_open=True)
        if timeout is not None:
            timeout = _check_float(timeout, "timeout", 0.0, lo_open=True)
        if not any(offs) and not any(ext):
            raise InvalidInput("step: every offset is zero, nothing to move")
        if timeout is None:
            timeout = self._step_timeout(frame, offs, ext, speed)
        command = frame.command
        before, before_pose = self._prepare(command)
        self._write_floats(registers.GV_PARAM0, offs)
        if self._ext_cache != ext:
            self._write_floats(registers.GV_EXT_OFFSET0, ext)
            self._ext_cache = ext
        self._write_floats(registers.GV_EXPECTED_SPEED, [speed])
        tracker = self.begin_command(command, before, before_pose, timeout=timeout)
        return self._finish(tracker, wait)

    @staticmethod
    def _step_timeout(frame: StepFrame, offs: Sequence[float], ext: Sequence[float],
                      speed: float) -> float | None:
        """max(MOVE_TIMEOUT_MIN, 3 x the estimated duration) when that exceeds the minimum."""
        if frame is StepFrame.JOINT:
            duration = max(abs(v) for v in (*offs, *ext)) / (speed * 6.0)  # rpm -> deg/s
        else:
            duration = math.dist((0.0, 0.0, 0.0), offs[:3]) / speed
        estimate = 3.0 * duration
        return estimate if estimate > timing.MOVE_TIMEOUT_MIN else None

    # -- function 2: create temp point ---------------------------------------------------
    def create_point(self, point_id: int, *, pose: Sequence[float] | None = None, gv_start: int = 0,
                     tool: int = registers.TOOL_NONE, wait: bool = True,
                     timeout: float | None = None) -> CommandResult:
        """Create (or overwrite) a temp point from the current pose, or from ``pose`` via GVs."""
        point_id = self._check_point_id(point_id)
        tool = _check_tool(tool)
        values = None if pose is None else _check_floats(pose, 6, "pose")
        gv_start = _check_int(gv_start, registers.GV_GENERAL_FIRST, _GENERAL_POSE_LAST_START, "first pose GV")
        if timeout is not None:
            timeout = _check_float(timeout, "timeout", 0.0, lo_open=True)
        before, _ = self._prepare(RunCommand.CREATE_POINT)
        if values is None:
            self._write_floats(registers.GV_PARAM0, [float(point_id), 0.0])
        else:
            self._write_floats(gv_start, values)
            self._write_floats(registers.GV_PARAM0, [float(point_id), 1.0, float(gv_start)])
        self._write_tool(tool)
        tracker = self.begin_command(RunCommand.CREATE_POINT, before, None, timeout=timeout)
        return self._finish(tracker, wait)

    def upload_points(self, points: Iterable[tuple[int, Sequence[float]]], tool: int = registers.TOOL_NONE,
                      progress: ProgressCallback | None = None, *,
                      gv_start: int = 0) -> list[CommandResult]:
        """Batched case 2.2: per point GV0-5 (one 0x10), GV200-202 (one 0x10), 440 <- 0xE0, polls.

        Every point is validated before the first write. Returns one result per point tried,
        in order (``details["point_id"]``); a refused point does not stop the others. A link
        error or timeout ends the batch after a failed result for that point; ``progress``
        (done, total) returning False cancels after the current point.
        """
        items = [(self._check_point_id(pid), _check_floats(pose, 6, f"pose of point {pid}"))
                 for pid, pose in points]
        tool = _check_tool(tool)
        gv_start = _check_int(gv_start, registers.GV_GENERAL_FIRST, _GENERAL_POSE_LAST_START, "first pose GV")
        results: list[CommandResult] = []
        if not items:
            return results
        status, _ = self._prepare(RunCommand.CREATE_POINT)
        self._write_tool(tool)
        kind = CommandKind.CREATE_POINT
        total = len(items)
        for index, (point_id, values) in enumerate(items, start=1):
            try:
                self._write_floats(gv_start, values)
                self._write_floats(registers.GV_PARAM0, [float(point_id), 1.0, float(gv_start)])
                tracker = self.begin_command(RunCommand.CREATE_POINT, status, None)
                result = self.wait(tracker, raise_errors=False)
                status = tracker.last_status or status
            except (LinkError, ResponseTimeout, ModbusExceptionError) as exc:
                results.append(CommandResult(RunCommand.CREATE_POINT, kind, None, False, str(exc),
                                             {"point_id": float(point_id)}))
                break
            details = dict(result.details, point_id=float(point_id))
            results.append(dataclasses.replace(result, message=f"point {point_id}: {result.message}",
                                               details=details))
            if progress is not None and progress(index, total) is False:
                break
        return results

    # -- function 3: move to temp point --------------------------------------------------
    def move_to_point(self, end_id: int, *, via_id: int | None = None, orientation_changes: bool = True,
                      ignore_middle: bool = False, speed: float = 50.0, tool: int = registers.TOOL_NONE,
                      wait: bool = True, timeout: float | None = None) -> CommandResult:
        """Line (``via_id`` None) or arc through ``via_id``: GV200-203 one 0x10, GV225, GV245, 0x42."""
        end_id = self._check_point_id(end_id, "end point id")
        motion = -1.0
        if via_id is not None:
            via_id = self._check_point_id(via_id, "middle point id")
            if via_id == end_id:
                raise InvalidInput("the arc's middle point must differ from its end point")
            motion = float(via_id)
        speed = _check_float(speed, "speed", 0.0, lo_open=True)
        tool = _check_tool(tool)
        if timeout is not None:
            timeout = _check_float(timeout, "timeout", 0.0, lo_open=True)
        before, before_pose = self._prepare(RunCommand.MOVE_TO_POINT)
        self._write_floats(registers.GV_PARAM0, [motion, float(end_id), 1.0 if orientation_changes else 0.0,
                                         1.0 if ignore_middle else 0.0])
        self._write_floats(registers.GV_EXPECTED_SPEED, [speed])
        self._write_tool(tool)
        tracker = self.begin_command(RunCommand.MOVE_TO_POINT, before, before_pose, timeout=timeout)
        return self._finish(tracker, wait)

    # -- function 4: teach (jog) ---------------------------------------------------------
    def _check_axis(self, frame: TeachFrame | None, axis: int) -> int:
        joint = frame in (TeachFrame.JOINT, None)
        top = (registers.NUM_AXES_TOTAL if joint else registers.NUM_ROBOT_AXES) - 1
        return _check_int(axis, 0, top, "axis")

    @staticmethod
    def _check_direction(direction: int) -> int:
        return _check_int(direction, 0, 1, "direction (0 negative, 1 positive)")

    def teach_enable(self, frame: TeachFrame, axis: int, direction: int, *, user_frame: int = 0,
                     tool_frame: int = 0, wait: bool = True,
                     timeout: float | None = None) -> CommandResult:
        """GV200-203 = (frame, axis, direction, 0) in one 0x10, GV241/GV245 if needed, 440 <- 0x80."""
        frame = _check_enum(frame, TeachFrame, "teach frame")
        axis = self._check_axis(frame, axis)
        direction = self._check_direction(direction)
        user_frame = _check_int(user_frame, 0, 0xFFFF, "user frame")
        tool_frame = _check_tool(tool_frame)
        before, _ = self._prepare(RunCommand.TEACH_ENABLE)
        self._write_floats(registers.GV_PARAM0, [float(frame), float(axis), float(direction), 0.0])
        if frame is TeachFrame.USER:
            self._write_user_frame(user_frame)
        elif frame is TeachFrame.TOOL:
            self._write_tool(tool_frame)
        tracker = self.begin_command(RunCommand.TEACH_ENABLE, before, None, timeout=timeout)
        self._teach_frame = frame
        return self._finish(tracker, wait)

    def teach_set_ratio(self, ratio: float) -> None:
        """GV203 <- ratio: > 0 moves, 0 stops the jog (teach stays enabled)."""
        ratio = _check_float(ratio, "speed ratio", 0.0, 100.0)
        self._write_floats(registers.GV_PARAM3, [ratio])

    def teach_set_axis(self, axis: int, direction: int) -> None:
        """Ratio 0 first, then GV201-202 (same frame); start again with :meth:`teach_set_ratio`."""
        axis = self._check_axis(self._teach_frame, axis)
        direction = self._check_direction(direction)
        self._write_floats(registers.GV_PARAM3, [0.0])
        self._write_floats(registers.GV_PARAM1, [float(axis), float(direction)])

    def teach_disable(self, *, wait: bool = True, timeout: float | None = None) -> CommandResult:
        """GV203 <- 0 (the controller refuses to disable while the ratio is not 0), 440 <- 0x81."""
        before, _ = self._prepare(RunCommand.TEACH_DISABLE, auto=False)
        self._write_floats(registers.GV_PARAM3, [0.0])
        tracker = self.begin_command(RunCommand.TEACH_DISABLE, before, None, timeout=timeout)
        self._teach_frame = None
        return self._finish(tracker, wait)
