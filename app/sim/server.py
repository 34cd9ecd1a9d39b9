"""The simulated controller as a real Modbus server (pymodbus 3.16 ``SimDevice`` API).

:class:`SimController` runs a Modbus TCP server (or RTU on a serial line, ``serial_port``) in
its own asyncio loop on a daemon thread (:mod:`app.sim.transport`; request screening, the
bad-frame log and the communication watchdog are in :mod:`app.sim.guard`) and a ticker thread
that advances :class:`~app.sim.robot.SimRobot` at ``SimConfig.tick_hz``. Every request passes
:meth:`SimController._action` (the SimDevice action), which, under :attr:`SimController.lock`,
applies writes (commands, teach ratio) and refreshes the live registers (pose, joints, status,
clock, GV291) so reads always see the current state.

GV291 publication: on a 440 command with a status (0x40/0x41/0x42/0xE0/0x80/0x81) the old
value stays for ``status_delay`` seconds, then 0 (INITIAL) shows for ``command_latency``
seconds — and, for the instant commands (create point, teach enable/disable), until a host has
read GV291 at least once (at most ``ZERO_HOLD_MAX`` seconds) —
then the robot's value (6 while moving, 0xFF done, or the error). The read rule emulates a
controller whose cycle is slower than the host's poll, and makes the fresh-versus-stale
question deterministic in tests: a host that polls always sees the 0 between two 0xFF. A stop (441) keeps
the old value for ``status_delay`` and then shows 0. Float32 by default, or the integer in
register 582 (583 = 0) with ``status_encoding="int"``.

That is the ``"classic"`` timing profile (``SimConfig.timing``), the one a polling host
handles best. The others model controllers we may meet: ``"fast"`` -- the result replaces the
old code within one scan (the next request sees it; the 0 is never visible, no read-hold);
``"slow"`` -- the old code stays for a seeded random pickup time (``timing.SIM_SLOW_PICKUP``),
then 0 shows for ``timing.SIM_SLOW_ZERO``, then the result, nothing held for a reader.
``SimConfig.gv291`` says what a host's write to GV291 (registers 582/583) does: ``"ignored"``
(acknowledged, overwritten by the next scan: the classic simulator), ``"writable"`` (the value
stays until the controller writes its next result) or ``"read-only"`` (Modbus exception 2,
illegal data address: what a controller that protects its status registers answers).

Project extension: joints J1..J6 in GV250..GV255 (registers 500..511).
"""

from __future__ import annotations

import asyncio
import datetime as dt
import logging
import random
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Literal

from pymodbus.constants import ExcCodes
from pymodbus.framer import FramerType
from pymodbus.simulator import DataType, SimData, SimDevice

from app import timing
from app.protocol.codec import WordOrder, encode_floats, float_to_registers, registers_to_float
from app.protocol.datetime_regs import DateTimeLayout, encode_clock
from app.protocol.enums import (
    Alarm,
    CommandKind,
    ControllerMode,
    ProgramState,
    RunCommand,
    WorkMode,
    decode_status_registers,
)
from app.protocol.registers import (
    GV_COMMAND_STATUS,
    GV_DATE,
    GV_EXPECTED_SPEED,
    GV_EXT_AXES,
    GV_EXT_OFFSET0,
    GV_JOINTS,
    GV_PARAM0,
    GV_PARAM1,
    GV_PARAM2,
    GV_PARAM3,
    GV_POSE,
    GV_TOOL_FRAME,
    NUM_EXTERNAL_AXES,
    NUM_ROBOT_AXES,
    REG_ALARMS,
    REG_CONTROLLER_MODE,
    REG_CYCLE_COUNT,
    REG_GO_ZERO,
    REG_PAUSE,
    REG_PROGRAM_ID,
    REG_PROGRAM_MODE,
    REG_PROGRAM_SPEED,
    REG_PROGRAM_STATE,
    REG_RESUME,
    REG_RUN_COMMAND,
    REG_STOP,
    REG_WORK_MODE,
    REGISTER_SPACE,
    TEMP_POINT_ID_MAX,
    TEMP_POINT_ID_MIN,
    gv_reg,
)
from app.sim.commands import StoredPoint
from app.sim.guard import CURRENT_CONNECTION, WATCHDOG_TIMEOUT, BadFrames, CommWatchdog
from app.sim.motion import Pose6, TraceSample
from app.sim.robot import SimRobot
from app.sim.transport import GuardedSerialServer, GuardedTcpServer, ServerGuard, ServerRunner

log = logging.getLogger(__name__)

# Longest time the 0 ("received") phase of GV291 waits for a host to read it.
ZERO_HOLD_MAX = 0.25

_FC_WRITE_SINGLE = 6
_STATUS_COMMANDS = frozenset({RunCommand.STEP_JOINT, RunCommand.STEP_BASE, RunCommand.MOVE_TO_POINT,
                              RunCommand.CREATE_POINT, RunCommand.TEACH_ENABLE, RunCommand.TEACH_DISABLE})
_GENERAL_REGISTERS = 200  # GV0..GV99 (registers 0..199): cleared by a controller restart
_STOP_TIMEOUT = 2.0
TIMING_PROFILES = ("classic", "fast", "slow")
GV291_MODES = ("ignored", "writable", "read-only")
_ANSWER_HOLD_MAX = 0.5  # s a move waits at most for its command's answer to go out
_GV291_REGS = range(gv_reg(GV_COMMAND_STATUS), gv_reg(GV_COMMAND_STATUS) + 2)


@dataclass
class SimConfig:
    """Settings of the simulated controller (``port=0`` picks a free port)."""

    host: str = "127.0.0.1"
    port: int = 5020
    unit: int = 1
    word_order: WordOrder = WordOrder.LOW_FIRST
    status_encoding: Literal["float", "int"] = "float"
    status_delay: float = 0.0
    tick_hz: float = timing.SIM_TICK_HZ
    framer: Literal["socket", "rtu"] = "socket"
    command_latency: float = timing.SIM_COMMAND_LATENCY
    datetime_layout: DateTimeLayout = DateTimeLayout.SPLIT_WORDS
    point_id_min: int = TEMP_POINT_ID_MIN
    point_id_max: int = TEMP_POINT_ID_MAX
    work_mode: WorkMode = WorkMode.AUTO  # the mode at power-on
    response_delay: float = 0.0
    # communication watchdog: stop a jog when its connection closes or no request arrives
    # for this many seconds (None or 0: off)
    watchdog: float | None = WATCHDOG_TIMEOUT
    # RTU on a serial device instead of TCP (host/port/framer are then unused)
    serial_port: str | None = None
    baudrate: int = 115200
    parity: Literal["N", "E", "O"] = "N"
    stopbits: int = 1
    timing: Literal["classic", "fast", "slow"] = "classic"  # GV291 timing profile (module docstring)
    gv291: Literal["ignored", "writable", "read-only"] = "ignored"  # what a host's write to GV291 does
    seed: int = 0  # of the "slow" profile's jitter

    def __post_init__(self) -> None:
        if isinstance(self.word_order, str):
            self.word_order = WordOrder.parse(self.word_order)
        if isinstance(self.datetime_layout, str):
            self.datetime_layout = DateTimeLayout(self.datetime_layout)
        if self.status_encoding not in ("float", "int"):
            raise ValueError(f"status_encoding must be 'float' or 'int', got {self.status_encoding!r}")
        if self.framer not in ("socket", "rtu"):
            raise ValueError(f"framer must be 'socket' or 'rtu', got {self.framer!r}")
        if not self.tick_hz > 0:
            raise ValueError("tick_hz must be > 0")
        if self.watchdog is not None and not self.watchdog >= 0:
            raise ValueError(f"watchdog must be None or >= 0 s, got {self.watchdog!r}")
        if self.parity not in ("N", "E", "O") or self.stopbits not in (1, 2) or self.baudrate <= 0:
            raise ValueError(f"serial settings: parity N/E/O, stop bits 1/2, baud > 0; got "
                             f"{self.parity!r}, {self.stopbits!r}, {self.baudrate!r}")
        if self.timing not in TIMING_PROFILES:
            raise ValueError(f"timing must be one of {', '.join(TIMING_PROFILES)}, got {self.timing!r}")
        if self.gv291 not in GV291_MODES:
            raise ValueError(f"gv291 must be one of {', '.join(GV291_MODES)}, got {self.gv291!r}")


@dataclass(frozen=True)
class WriteRecord:
    """One write request as received: monotonic time, function code, first address, values."""

    t: float
    function_code: int
    address: int
    values: tuple[int, ...]


@dataclass(frozen=True)
class SimEvent:
    """Something the controller did by itself: monotonic time, kind (``"watchdog"``), details."""

    t: float
    kind: str
    detail: str


@dataclass(frozen=True)
class SimSnapshot:
    """A consistent copy of the controller's state (what a host could read, and more)."""

    t: float  # robot clock (s)
    pose: Pose6  # X Y Z A B C, base frame
    joints: tuple[float, ...]  # J1..J11
    work_mode: WorkMode
    mode: ControllerMode  # register 560
    program_state: ProgramState  # register 561
    alarms: Alarm  # register 562
    teach_enabled: bool
    teach_frame: int
    teach_ratio: float
    jogging: bool
    command_status: int  # GV291 as published now
    last_kind: CommandKind | None
    points: dict[int, Pose6] = field(default_factory=dict)
    moving: bool = False  # a move, go-to-zero or program is under way (also when paused)
    paused: bool = False

    @property
    def ext(self) -> tuple[float, ...]:
        return self.joints[NUM_ROBOT_AXES:]


class SimController:
    """The simulated Bochuang controller: Modbus server + robot model + fault injection."""

    def __init__(self, config: SimConfig | None = None) -> None:
        self.config = config or SimConfig()
        self.lock = threading.RLock()
        self.robot = SimRobot(point_id_min=self.config.point_id_min, point_id_max=self.config.point_id_max,
                              work_mode=self.config.work_mode)
        self.writes: list[WriteRecord] = []
        self._requests = 0
        self._port: int | None = None
        self._runner = ServerRunner()
        self._tick_thread: threading.Thread | None = None
        self._stop_event = threading.Event()
        self._started = False
        self._stopped = False
        # fault injection
        self._response_delay = self.config.response_delay
        self._status_delay = self.config.status_delay
        self._silent = False
        self._exception: ExcCodes | None = None
        self._exception_range: range | None = None
        # GV291 publication hold (see module docstring)
        self._hold_old_until = 0.0
        self._hold_old_value = 0
        self._hold_zero_until = 0.0
        self._zero_unread = False  # the 0 phase has not been seen by a host read yet
        self._rng = random.Random(self.config.seed)  # the "slow" profile's jitter
        self._move_unanswered: float | None = None  # when a move command not answered yet came
        self._wipe_general = False  # set by restart_controller(): clear GV0..GV99 on the next request
        # bad input and the communication watchdog (app/sim/guard.py)
        self.events: list[SimEvent] = []
        self.bad_frames = BadFrames()
        self.watchdog = CommWatchdog(self.config.watchdog, self._watchdog_stop)
        self._registers: list[int] | None = None  # the server's register block, once seen

    # --- lifecycle ------------------------------------------------------------------------
    @property
    def port(self) -> int:
        """The bound TCP port (valid after :meth:`start`)."""
        if self.config.serial_port is not None:
            raise RuntimeError(f"the simulator serves the serial line {self.config.serial_port}, not TCP")
        if self._port is None:
            raise RuntimeError("simulator not started")
        return self._port

    @property
    def endpoint(self) -> str:
        """``host:port``, or the serial device and its settings, for messages."""
        c = self.config
        if c.serial_port is not None:
            return f"{c.serial_port} ({c.baudrate} baud, 8{c.parity}{c.stopbits})"
        return f"{c.host}:{self._port if self._port is not None else c.port}"

    @property
    def host(self) -> str:
        return self.config.host

    @property
    def running(self) -> bool:
        return self._started and not self._stopped

    def start(self) -> None:
        """Bind the server and start the ticker; returns once the port is bound."""
        if self._started:
            raise RuntimeError("simulator already started")
        self._started = True
        try:
            self._runner.start(self._serve, self.endpoint)
        except OSError:
            self._stopped = True
            raise
        self._port = self._runner.port
        self._tick_thread = threading.Thread(target=self._tick_loop, name="sim-ticker", daemon=True)
        self._tick_thread.start()
        log.info("simulator listening on %s (unit %s, %s framing, %s word order, status %s, watchdog %s, "
                 "timing %s, GV291 %s)",
                 self.endpoint, self.config.unit, "rtu" if self.config.serial_port else self.config.framer,
                 self.config.word_order.value, self.config.status_encoding,
                 f"{self.watchdog.timeout:g} s" if self.watchdog.enabled else "off",
                 self.config.timing, self.config.gv291)

    async def _serve(self) -> GuardedTcpServer | GuardedSerialServer:
        initial = [0] * REGISTER_SPACE
        self._init_registers(initial)
        device = SimDevice(self.config.unit,
                           simdata=[SimData(address=0, values=initial, datatype=DataType.REGISTERS)],
                           action=self._action)
        c = self.config
        guard = ServerGuard(c.unit, self.bad_frames, self.watchdog)
        server: GuardedTcpServer | GuardedSerialServer
        if c.serial_port is not None:
            server = GuardedSerialServer(device, guard, port=c.serial_port, baudrate=c.baudrate,
                                         parity=c.parity, stopbits=c.stopbits,
                                         trace_packet=self._trace_packet)
            await server.serve_forever(background=True)
        else:
            framer = FramerType.RTU if c.framer == "rtu" else FramerType.SOCKET
            server = GuardedTcpServer(device, guard, framer=framer, address=(c.host, c.port),
                                      trace_packet=self._trace_packet)
            await server.serve_forever(background=True)
        return server

    def stop(self) -> None:
        """Stop the server and the ticker. Idempotent and fast."""
        if not self._started or self._stopped:
            self._stopped = True
            return
        self._stopped = True
        self._stop_event.set()
        self._runner.stop()
        if self._tick_thread is not None:
            self._tick_thread.join(_STOP_TIMEOUT)
        log.info("simulator stopped")

    def __enter__(self) -> SimController:
        self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def _tick_loop(self) -> None:
        period = 1.0 / self.config.tick_hz
        last = time.monotonic()
        deadline = last + period
        while not self._stop_event.wait(max(0.0, deadline - time.monotonic())):
            now = time.monotonic()
            # a stalled thread must not teleport the arm: at most two periods a tick, so even a
            # short move spans several ticks a host can see (motion runs late, not in a jump)
            step = min(now - last, 2 * period)
            last = now
            accepted = self._move_unanswered
            # a move starts once its command is answered, as on a controller that answers
            # within its scan: a busy simulator must not run a short move to its end before
            # the host even has the answer
            with self.lock:
                if accepted is None or now - accepted >= _ANSWER_HOLD_MAX:
                    try:
                        self.robot.tick(step)
                    except Exception:  # keep the simulator alive; the failure is in the log
                        log.exception("simulator tick failed")
                        self.robot.stop()
                jogging = self.robot.jogging
            self.watchdog.check(jogging)
            self.bad_frames.flush()
            deadline += period
            if deadline < now:
                deadline = now + period

    # --- Modbus glue ----------------------------------------------------------------------
    def _trace_packet(self, sending: bool, data: bytes) -> bytes:
        if sending:
            self._move_unanswered = None  # the answer goes out: a move accepted may start
        if sending and self._silent:
            return b""  # silent: the request was received, the answer is swallowed
        return data

    async def _action(self, function_code: int, start_address: int, address: int, count: int,
                      registers: list[int], set_values: list[int] | list[bool] | None) -> ExcCodes | None:
        if set_values is None and function_code == _FC_WRITE_SINGLE:
            return None  # pymodbus reads a 0x06 write back: already handled
        connection = CURRENT_CONNECTION.get()
        with self.lock:
            self._requests += 1
            self._registers = registers
        if self._silent:
            return ExcCodes.DEVICE_FAILURE  # not executed; the answer is dropped by _trace_packet
        if self._response_delay > 0:
            await asyncio.sleep(self._response_delay)
        exc, exc_range = self._exception, self._exception_range
        hit = exc_range is None or (address < exc_range.stop and exc_range.start < address + count)
        if exc is not None and hit:
            return exc
        offset = address - start_address
        with self.lock:
            if self._wipe_general:  # a restarted controller starts with cleared general-purpose GVs
                self._wipe_general = False
                first, last = max(0, -start_address), max(0, _GENERAL_REGISTERS - start_address)
                registers[first:last] = [0] * (last - first)
            if set_values is not None:
                values = [int(v) & 0xFFFF for v in set_values]
                self.writes.append(WriteRecord(time.monotonic(), function_code, address, tuple(values)))
                log.info("write fc=0x%02X address=%d values=%s", function_code, address,
                         " ".join(f"{v:04X}" for v in values))
                before = registers[offset : offset + len(values)]
                registers[offset : offset + len(values)] = values
                result = self._handle_write(registers, start_address, address, len(values))
                if result is not None:  # refused: the write is not stored
                    registers[offset : offset + len(values)] = before
                    return result
                ratio = gv_reg(GV_PARAM3)
                if self.robot.jogging and address <= ratio + 1 and ratio < address + len(values):
                    self.watchdog.jog_written(connection)
            self._refresh(registers, start_address)
            status_reg = gv_reg(GV_COMMAND_STATUS)
            if (set_values is None and self._zero_unread and address <= status_reg < address + count
                    and time.monotonic() >= self._hold_old_until):
                self._zero_unread = False  # a host has now seen the 0
        return None

    # --- registers ------------------------------------------------------------------------
    def _init_registers(self, regs: list[int]) -> None:
        regs[REG_PROGRAM_ID] = 1
        regs[REG_PROGRAM_MODE] = 1
        regs[REG_CYCLE_COUNT] = 1
        regs[REG_PROGRAM_SPEED] = 100
        regs[REG_WORK_MODE] = int(self.config.work_mode)
        self._put_floats(regs, 0, gv_reg(GV_EXPECTED_SPEED), [10.0])
        self._put_floats(regs, 0, gv_reg(GV_TOOL_FRAME), [200.0])
        self._put_floats(regs, 0, gv_reg(GV_PARAM0), [0.0] * 6)
        with self.lock:
            self._refresh(regs, 0)

    def _put_floats(self, regs: list[int], start: int, address: int, values: list[float]) -> None:
        encoded = encode_floats(values, self.config.word_order)
        regs[address - start : address - start + len(encoded)] = encoded

    def _gv(self, regs: list[int], start: int, n: int) -> float:
        a = gv_reg(n) - start
        return registers_to_float(regs[a : a + 2], self.config.word_order)

    def _gvs(self, regs: list[int], start: int, n: int, count: int) -> list[float]:
        return [self._gv(regs, start, n + i) for i in range(count)]

    def published_status(self, now: float | None = None) -> int:
        """GV291 as a host reads it right now (honours status_delay / command_latency)."""
        now = time.monotonic() if now is None else now
        with self.lock:
            if now < self._hold_old_until:
                return self._hold_old_value
            if now < self._hold_zero_until:
                return 0
            if self._zero_unread and now < self._hold_old_until + ZERO_HOLD_MAX:
                return 0
            return self.robot.command_status

    def _hold_status(self, latency: bool) -> None:
        """Publish the old GV291 a while, then 0, then the robot's value (the timing profile)."""
        now = time.monotonic()
        old = self.published_status(now)
        profile = self.config.timing
        pickup = self._status_delay
        zero = self.config.command_latency if latency else 0.0
        if profile == "fast":
            zero = 0.0
        elif profile == "slow":
            pickup += self._rng.uniform(*timing.SIM_SLOW_PICKUP)
            zero = self._rng.uniform(*timing.SIM_SLOW_ZERO) if latency else 0.0
        self._hold_old_value = old
        self._hold_old_until = now + pickup
        self._hold_zero_until = self._hold_old_until + zero
        self._zero_unread = latency and profile == "classic"

    def _host_wrote_status(self, regs: list[int], start: int) -> ExcCodes | None:
        """A host's write covered GV291: refuse it, keep it, or let the next refresh overwrite it."""
        mode = self.config.gv291
        if mode == "read-only":
            return ExcCodes.ILLEGAL_ADDRESS
        if mode == "writable":
            s = _GV291_REGS.start - start
            self.robot.command_status = decode_status_registers(regs[s : s + 2], self.config.word_order)
            self._hold_old_until = self._hold_zero_until = 0.0  # the host's value shows at once
            self._zero_unread = False
            log.info("host wrote GV291 = %d", self.robot.command_status)
        return None

    def _refresh(self, regs: list[int], start: int) -> None:
        robot = self.robot
        self._put_floats(regs, start, gv_reg(GV_POSE), list(robot.pose))
        joints = [float(v) for v in robot.joints]
        ext = joints[NUM_ROBOT_AXES : NUM_ROBOT_AXES + NUM_EXTERNAL_AXES]
        self._put_floats(regs, start, gv_reg(GV_EXT_AXES), ext)
        self._put_floats(regs, start, gv_reg(GV_JOINTS), joints[:NUM_ROBOT_AXES])
        regs[REG_CONTROLLER_MODE - start] = int(robot.controller_mode)
        regs[REG_PROGRAM_STATE - start] = int(robot.program_state)
        regs[REG_ALARMS - start] = int(robot.alarms) & 0xFFFF
        clock = encode_clock(dt.datetime.now(), self.config.datetime_layout)
        d = gv_reg(GV_DATE) - start
        regs[d : d + 4] = clock
        status = self.published_status()
        s = gv_reg(GV_COMMAND_STATUS) - start
        if self.config.status_encoding == "int":
            regs[s : s + 2] = [status & 0xFFFF, 0]
        else:
            regs[s : s + 2] = float_to_registers(float(status), self.config.word_order)

    def _handle_write(self, regs: list[int], start: int, address: int, count: int) -> ExcCodes | None:
        """Act on the control registers a write covered (values already in ``regs``)."""
        covered = range(address, address + count)
        robot = self.robot
        if _GV291_REGS.start in covered or _GV291_REGS.stop - 1 in covered:
            refused = self._host_wrote_status(regs, start)
            if refused is not None:
                return refused

        def value(reg: int) -> int:
            return regs[reg - start]

        if REG_WORK_MODE in covered:
            if not robot.set_work_mode(value(REG_WORK_MODE)):
                return ExcCodes.ILLEGAL_VALUE
            log.info("work mode -> %s", robot.work_mode.name)
        if REG_STOP in covered and value(REG_STOP) == 1:
            self._hold_status(latency=False)
            robot.stop()
            log.info("stop")
        if REG_PAUSE in covered and value(REG_PAUSE) == 1:
            log.info("pause%s", "" if robot.pause() else " (nothing to pause)")
        if REG_RESUME in covered and value(REG_RESUME) == 1:
            log.info("resume%s", "" if robot.resume() else " (nothing paused)")
        if REG_GO_ZERO in covered:
            axis = value(REG_GO_ZERO)
            log.info("go to zero %s: %s", "all" if axis == 11 else f"J{axis + 1}",
                     "started" if robot.go_zero(axis) else "refused")
        ratio_regs = range(gv_reg(GV_PARAM3), gv_reg(GV_PARAM3) + 2)
        if robot.teach_enabled and (ratio_regs.start in covered or ratio_regs.stop - 1 in covered):
            robot.set_teach_ratio(self._gv(regs, start, GV_PARAM3), self._gv(regs, start, GV_PARAM1),
                                  self._gv(regs, start, GV_PARAM2))
        if REG_RUN_COMMAND in covered:
            return self._run_command(regs, start, value(REG_RUN_COMMAND))
        return None

    def _run_command(self, regs: list[int], start: int, code: int) -> ExcCodes | None:
        try:
            command = RunCommand(code)
        except ValueError:
            log.warning("unknown run command 0x%02X refused", code)
            return ExcCodes.ILLEGAL_VALUE
        robot = self.robot
        if command in _STATUS_COMMANDS:
            self._hold_status(latency=True)
            # moves show 6 (moving) as their own evidence; only the instant commands wait
            # for a host to have seen the 0 (classic profile)
            self._zero_unread = self._zero_unread and command in (
                RunCommand.CREATE_POINT, RunCommand.TEACH_ENABLE, RunCommand.TEACH_DISABLE)
        p = self._gvs(regs, start, GV_PARAM0, 6)
        speed = self._gv(regs, start, GV_EXPECTED_SPEED)
        ext = self._gvs(regs, start, GV_EXT_OFFSET0, NUM_EXTERNAL_AXES)
        tool = self._gv(regs, start, GV_TOOL_FRAME)
        status: int | None = None
        if command is RunCommand.RUN_PROGRAM:
            ok = robot.run_program(regs[REG_PROGRAM_ID - start], regs[REG_PROGRAM_MODE - start],
                                   regs[REG_CYCLE_COUNT - start], regs[REG_PROGRAM_SPEED - start])
            log.info("run program %d: %s", regs[REG_PROGRAM_ID - start], "started" if ok else "refused")
            return None
        if command is RunCommand.STEP_JOINT:
            status = robot.step_joint(p + ext, speed)
        elif command is RunCommand.STEP_BASE:
            status = robot.step_base(p, speed, ext)
        elif command is RunCommand.MOVE_TO_POINT:
            status = robot.move_to_point(p[0], p[1], p[2], p[3], speed, tool)
        elif command is RunCommand.CREATE_POINT:
            source = p[1]
            pose: list[float] | None = None
            if source == 1:
                first = robot.gv_source_ok(p[2])
                if first is None:
                    robot.last_kind = CommandKind.CREATE_POINT
                    robot.command_status = 1
                    log.info("create point %s refused: GV202 = %s is not a GV index 0..94", p[0], p[2])
                    return None
                pose = self._gvs(regs, start, first, 6)
            elif source != 0:
                robot.last_kind = CommandKind.CREATE_POINT
                robot.command_status = 1
                log.info("create point %s refused: GV201 = %s (0 current pose, 1 from GVs)", p[0], source)
                return None
            status = robot.create_point(p[0], pose, tool)
        elif command is RunCommand.TEACH_ENABLE:
            status = robot.teach_enable(p[0], p[3])
        elif command is RunCommand.TEACH_DISABLE:
            status = robot.teach_disable(p[3])
        if command in (RunCommand.STEP_JOINT, RunCommand.STEP_BASE, RunCommand.MOVE_TO_POINT):
            self._move_unanswered = time.monotonic()
        log.info("%s -> status %s", command.name, status)
        return None

    # --- inspection -----------------------------------------------------------------------
    @property
    def requests_count(self) -> int:
        with self.lock:
            return self._requests

    @property
    def connections_count(self) -> int:
        """Clients connected right now."""
        return self._runner.connections_count

    def bad_frame_counts(self) -> dict[str, int]:
        """Rejected frames since start, by reason (``"illegal function"``, ``"bad CRC"``, ...)."""
        return self.bad_frames.counts()

    def watchdog_events(self) -> list[SimEvent]:
        with self.lock:
            return [e for e in self.events if e.kind == "watchdog"]

    def _watchdog_stop(self, reason: str) -> bool:
        """The watchdog fired: ratio 0 (GV203 reads 0 too), teach stays enabled."""
        with self.lock:
            robot = self.robot
            if not robot.jogging:
                return False
            robot.set_teach_ratio(0.0, robot.jog_axis, robot.jog_direction)
            regs = self._registers
            if regs is not None:
                r = gv_reg(GV_PARAM3)
                regs[r : r + 2] = float_to_registers(0.0, self.config.word_order)
            self.events.append(SimEvent(time.monotonic(), "watchdog", reason))
        log.warning("watchdog: jog stopped (ratio 0, teach still enabled): %s", reason)
        return True

    def writes_to(self, address: int) -> list[WriteRecord]:
        """Writes that covered ``address``, narrowed to that one register: ``values == (v,)``."""
        with self.lock:
            return [WriteRecord(w.t, w.function_code, address, (w.values[address - w.address],))
                    for w in self.writes if w.address <= address < w.address + len(w.values)]

    def state(self) -> SimSnapshot:
        with self.lock:
            r = self.robot
            return SimSnapshot(
                t=r.time, pose=r.pose, joints=tuple(float(v) for v in r.joints), work_mode=r.work_mode,
                mode=r.controller_mode, program_state=r.program_state, alarms=r.alarms,
                teach_enabled=r.teach_enabled, teach_frame=int(r.teach_frame), teach_ratio=r.teach_ratio,
                jogging=r.jogging, command_status=self.published_status(), last_kind=r.last_kind,
                points={k: v.pose for k, v in r.points.items()}, moving=r.busy, paused=r.paused)

    def trajectory(self) -> list[TraceSample]:
        """Samples (robot time, pose, joints) recorded each tick since the last motion started."""
        with self.lock:
            return self.robot.trajectory()

    def wait_for(self, predicate: Callable[[SimSnapshot], bool], timeout: float = 5.0) -> bool:
        """Poll :meth:`state` until ``predicate`` holds; False after ``timeout`` seconds."""
        deadline = time.monotonic() + timeout
        while True:
            if predicate(self.state()):
                return True
            if time.monotonic() >= deadline:
                return False
            time.sleep(0.002)

    # --- controller operations (Python side) ----------------------------------------------
    def restart_controller(self) -> None:
        """The controller's system logs in again: temp points wiped, motion stopped, teach off."""
        with self.lock:
            self.robot.restart()
            self._hold_old_until = self._hold_zero_until = 0.0
            self._zero_unread = False
            self._wipe_general = True  # GV0..GV99 read 0 from the next request on
        log.info("controller restarted: temp points and GV0-GV99 wiped")

    def add_point(self, point_id: int, pose: Pose6, tool: int = 200) -> None:
        """Store a temp point directly (test setup)."""
        with self.lock:
            self.robot.points[point_id] = StoredPoint(pose, tool)

    # --- fault injection ------------------------------------------------------------------
    def set_alarm(self, bit: Alarm | int, on: bool) -> None:
        with self.lock:
            self.robot.set_alarm(Alarm(bit), on)
        log.info("alarm %s %s", Alarm(bit).name, "on" if on else "off")

    def refuse_point(self, point_id: int, refuse: bool = True) -> None:
        """Answer a create point of ``point_id`` with status 1 (bad point id) from now on."""
        with self.lock:
            if refuse:
                self.robot.refused_points.add(int(point_id))
            else:
                self.robot.refused_points.discard(int(point_id))
        log.info("create point %d: %s", point_id, "refused from now on" if refuse else "accepted again")

    def set_response_delay(self, seconds: float) -> None:
        self._response_delay = max(0.0, float(seconds))
        log.info("response delay %.3f s", self._response_delay)

    def set_status_delay(self, seconds: float) -> None:
        self._status_delay = max(0.0, float(seconds))
        log.info("status delay %.3f s", self._status_delay)

    def set_watchdog(self, seconds: float | None) -> None:
        """The communication watchdog's silence limit; None or 0 switches it off entirely."""
        self.watchdog.set_timeout(seconds)
        log.info("watchdog %s", f"{self.watchdog.timeout:g} s" if self.watchdog.enabled else "off")

    def set_silent(self, silent: bool) -> None:
        self._silent = bool(silent)
        log.info("silent %s", "on" if silent else "off")

    def set_exception(self, code: ExcCodes | int | None, addresses: range | None = None) -> None:
        """Answer requests touching ``addresses`` (None: all) with Modbus exception ``code``."""
        self._exception_range = addresses
        self._exception = None if code is None else ExcCodes(code)
        log.info("exception %s%s", "off" if code is None else int(code),
                 "" if addresses is None else f" on {addresses.start}..{addresses.stop - 1}")

    def drop_connections(self) -> int:
        """Close the sockets of the connected clients (the server keeps listening)."""
        count = self._runner.drop_connections()
        log.info("dropped %d connection(s)", count)
        return count
