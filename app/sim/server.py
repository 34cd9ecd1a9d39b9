"""The simulated controller as a real Modbus server (pymodbus 3.16 ``SimDevice`` API).

:class:`SimController` runs a Modbus TCP server (or RTU on a serial line, ``serial_port``) in
its own asyncio loop on a daemon thread (:mod:`app.sim.transport`; request screening, the
bad-frame log and the communication watchdog are in :mod:`app.sim.guard`) and a ticker thread
that advances :class:`~app.sim.robot.SimRobot` at ``SimConfig.tick_hz``. Every request passes
:meth:`SimController._action` (the SimDevice action), which, under :attr:`SimController.lock`,
applies writes (commands, teach ratio) and refreshes the live registers (pose, joints, status,
clock, GV291) so reads always see the current state.

The parts: :mod:`app.sim.config` (settings and records), :mod:`app.sim.register_image` (the
live registers), :mod:`app.sim.execute` (what a write does), :mod:`app.sim.status` (GV291
publication and the timing profiles ``SimConfig.timing``). ``SimConfig.gv291`` says what a
host's write to GV291 (registers 582/583) does: ``"ignored"`` (acknowledged, overwritten by the
next scan: the classic simulator), ``"writable"`` (the value stays until the controller writes
its next result) or ``"read-only"`` (Modbus exception 2, illegal data address: what a
controller that protects its status registers answers).
"""

from __future__ import annotations

import asyncio
import logging
import threading
import time
from collections.abc import Callable

from pymodbus.constants import ExcCodes
from pymodbus.framer import FramerType
from pymodbus.simulator import DataType, SimData, SimDevice

from app.protocol.codec import float_to_registers
from app.protocol.enums import Alarm
from app.protocol.registers import (
    GV_COMMAND_STATUS,
    GV_PARAM3,
    REGISTER_SPACE,
    gv_reg,
)
from app.sim.commands import StoredPoint
from app.sim.config import REST_LOG_LIMIT, RestRecord, SimConfig, SimEvent, SimSnapshot, WriteRecord
from app.sim.execute import CommandExecutor
from app.sim.guard import CURRENT_CONNECTION, BadFrames, CommWatchdog
from app.sim.motion import Pose6, TraceSample
from app.sim.refusals import PointWriteRefusals, at_text, on_text, touches
from app.sim.register_image import RegisterImage
from app.sim.robot import SimRobot
from app.sim.status import StatusPublisher
from app.sim.transport import GuardedSerialServer, GuardedTcpServer, ServerGuard, ServerRunner

log = logging.getLogger(__name__)

_FC_WRITE_SINGLE = 6
_GENERAL_REGISTERS = 200  # GV0..GV99 (registers 0..199): cleared by a controller restart
_STOP_TIMEOUT = 2.0
_ANSWER_HOLD_MAX = 0.5  # s a move waits at most for its command's answer to go out
#: Writes the simulator keeps in :attr:`SimController.writes` (tests read the log from the start;
#: none comes near this): beyond it the oldest tenth is dropped, so a long session does not grow.
WRITE_LOG_LIMIT = 200_000


class SimController:
    """The simulated Bochuang controller: Modbus server + robot model + fault injection."""

    def __init__(self, config: SimConfig | None = None) -> None:
        self.config = config or SimConfig()
        self.lock = threading.RLock()
        self.robot = SimRobot(
            point_id_min=self.config.point_id_min,
            point_id_max=self.config.point_id_max,
            work_mode=self.config.work_mode,
        )
        # every write received, oldest first: the last WRITE_LOG_LIMIT (writes_dropped: how many
        # older ones were forgotten -- a simulator child of the GUI may run for days)
        self.writes: list[WriteRecord] = []
        self.writes_dropped = 0
        self._requests = 0
        self._requests_on: dict[int | None, int] = {}  # requests by connection id
        self._port: int | None = None
        self._runner = ServerRunner()
        self._tick_thread: threading.Thread | None = None
        self._stop_event = threading.Event()
        self._started = False
        self._stopped = False
        # fault injection
        # (seconds, connection or None: all, addresses or None: all), replaced whole (the loop reads it)
        self._delay_rule: tuple[float, int | None, range | None] = (self.config.response_delay, None, None)
        self._slow_answers = (0.0, 0)  # (s, n): every n-th answer held this long (late polls)
        self._status_delay = self.config.status_delay
        self._silent = False
        # (code or None: off, addresses or None: all, connection or None: all), replaced whole
        self._exception_rule: tuple[ExcCodes | None, range | None, int | None] = (None, None, None)
        # set_exception(after_write=REG): the rule waits for a stored write covering REG (None: armed)
        self._exception_after: int | None = None
        # answer_after_applying(code, register): the next write starting at register is carried
        # out, then answered with this exception (a controller that acted and said it failed)
        self._applied_then: tuple[ExcCodes, int] | None = None
        # set_exception(seconds=S): the rule lifts itself S s after it is armed (None: until lifted)
        self._exception_seconds: float | None = None
        self._exception_until: float | None = None
        self._exceptions_answered = 0  # requests answered by the exception rule
        self.point_write_refusals = PointWriteRefusals()
        # GV291 publication hold (app/sim/status.py), the register image, the command execution
        self.status = StatusPublisher(self.config.timing, self.config.command_latency, self.config.seed)
        self.image = RegisterImage(self.config)
        self.executor = CommandExecutor(
            self.robot, self.config, self.image, self.status, lambda: self._status_delay, self._move_accepted
        )
        self._move_unanswered: float | None = None  # when a move command not answered yet came
        self._wipe_general = False  # set by restart_controller(): clear GV0..GV99 on the next request
        # restart_after_write(): (register, writes to go) -- the controller restarts after that write
        self._restart_after: tuple[int, int] | None = None
        # bad input and the communication watchdog (app/sim/guard.py)
        self.events: list[SimEvent] = []
        self.bad_frames = BadFrames()
        self.watchdog = CommWatchdog(self.config.watchdog, self._watchdog_stop)
        self._registers: list[int] | None = None  # the server's register block, once seen
        # every time the arm came to rest (a move's end, a stop, a jog released), oldest first:
        # the controller's own record of a stop, which measured stopping is checked against
        self.rests: list[RestRecord] = []
        self._was_moving = False

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
        log.info(
            "simulator listening on %s (unit %s, %s framing, %s word order, status %s, watchdog %s, "
            "timing %s, GV291 %s)",
            self.endpoint,
            self.config.unit,
            "rtu" if self.config.serial_port else self.config.framer,
            self.config.word_order.value,
            self.config.status_encoding,
            f"{self.watchdog.timeout:g} s" if self.watchdog.enabled else "off",
            self.config.timing,
            self.config.gv291,
        )

    async def _serve(self) -> GuardedTcpServer | GuardedSerialServer:
        initial = [0] * REGISTER_SPACE
        self.image.init(initial)
        with self.lock:
            self._refresh(initial, 0)
        device = SimDevice(
            self.config.unit,
            simdata=[SimData(address=0, values=initial, datatype=DataType.REGISTERS)],
            action=self._action,
        )
        c = self.config
        guard = ServerGuard(c.unit, self.bad_frames, self.watchdog)
        server: GuardedTcpServer | GuardedSerialServer
        if c.serial_port is not None:
            server = GuardedSerialServer(
                device,
                guard,
                port=c.serial_port,
                baudrate=c.baudrate,
                parity=c.parity,
                stopbits=c.stopbits,
                trace_packet=self._trace_packet,
            )
            await server.serve_forever(background=True)
        else:
            framer = FramerType.RTU if c.framer == "rtu" else FramerType.SOCKET
            server = GuardedTcpServer(
                device, guard, framer=framer, address=(c.host, c.port), trace_packet=self._trace_packet
            )
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
                self._note_rest()
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

    async def _action(
        self,
        function_code: int,
        start_address: int,
        address: int,
        count: int,
        registers: list[int],
        set_values: list[int] | list[bool] | None,
    ) -> ExcCodes | None:
        if set_values is None and function_code == _FC_WRITE_SINGLE:
            return None  # pymodbus reads a 0x06 write back: already handled
        connection = CURRENT_CONNECTION.get()
        with self.lock:
            self._requests += 1
            serial = self._requests
            self._requests_on[connection] = self._requests_on.get(connection, 0) + 1
            self._registers = registers
        if self._silent:
            return ExcCodes.DEVICE_FAILURE  # not executed; the answer is dropped by _trace_packet
        injected = await self._injected_fault(serial, connection, address, count)
        if injected is not None:
            if set_values is not None:
                self._log_refused(function_code, address, injected)
            return injected
        values = None if set_values is None else [int(v) & 0xFFFF for v in set_values]
        if values is not None:
            refused = self.point_write_refusals.check(address, values, self.config.word_order)
            if refused is not None:
                log.info("write fc=0x%02X address=%d refused: exception %d", function_code, address, refused)
                return refused
        with self.lock:
            answer = self._carry_out(
                function_code, start_address, address, count, registers, values, connection
            )
            self._note_rest()
            return answer

    async def _injected_fault(
        self, serial: int, connection: int | None, address: int, count: int
    ) -> ExcCodes | None:
        """The fault knobs, in order: the answer held (response delay, slow answers), then the
        exception rule's code when it applies to this request."""
        slow, every = self._slow_answers
        held, delay_on, delay_range = self._delay_rule
        if not (delay_on in (None, connection) and touches(delay_range, address, count)):
            held = 0.0
        delay = max(held, slow if every and serial % every == 0 else 0.0)
        if delay > 0:
            await asyncio.sleep(delay)
        exc, exc_range, exc_on = self._exception_rule
        hit = (
            touches(exc_range, address, count)
            and exc_on in (None, connection)
            and self._exception_after is None
        )
        if exc is not None and hit and self._exception_window_open():
            with self.lock:
                self._exceptions_answered += 1
            return exc
        return None

    def _carry_out(
        self,
        function_code: int,
        start_address: int,
        address: int,
        count: int,
        registers: list[int],
        values: list[int] | None,
        connection: int | None,
    ) -> ExcCodes | None:
        """Carry the request out (under the lock): a write stored and acted on, the live registers
        refreshed; the exception to answer, if any."""
        if self._wipe_general:  # a restarted controller starts with cleared general-purpose GVs
            self._wipe_general = False
            first, last = max(0, -start_address), max(0, _GENERAL_REGISTERS - start_address)
            registers[first:last] = [0] * (last - first)
        answer: ExcCodes | None = None
        if values is not None:
            refused = self._store_write(function_code, start_address, address, registers, values)
            if refused is not None:  # refused: the write is not stored
                return refused
            answer = self._after_write(address, len(values), connection)
        self._refresh(registers, start_address)
        status_reg = gv_reg(GV_COMMAND_STATUS)
        if values is None and address <= status_reg < address + count:
            self.status.seen(time.monotonic())  # a host has now seen the 0 (if it shows)
        return answer

    def _store_write(
        self, function_code: int, start_address: int, address: int, registers: list[int], values: list[int]
    ) -> ExcCodes | None:
        """Log the write, store it and act on it; a write the controller refuses is put back."""
        self._log_write(WriteRecord(time.monotonic(), function_code, address, tuple(values)))
        log.info(
            "write fc=0x%02X address=%d values=%s",
            function_code,
            address,
            " ".join(f"{v:04X}" for v in values),
        )
        offset = address - start_address
        before = registers[offset : offset + len(values)]
        registers[offset : offset + len(values)] = values
        result = self.executor.handle_write(registers, start_address, address, len(values))
        if result is not None:
            registers[offset : offset + len(values)] = before
        return result

    def _after_write(self, address: int, n: int, connection: int | None) -> ExcCodes | None:
        """What a stored write sets off besides its command: the jog watchdog fed, the exception
        rule armed, a restart that was due, a "carried out, answered exception" rule (its code)."""
        ratio = gv_reg(GV_PARAM3)
        if self.robot.jogging and address <= ratio + 1 and ratio < address + n:
            self.watchdog.jog_written(connection)
        armer = self._exception_after
        if armer is not None and address <= armer < address + n:
            self._exception_after = None  # the exception rule applies from the next request on
            self._arm_exception_window()
            log.info("exception rule armed by the write to %d", armer)
        self._restart_if_due(address, n)
        applied = self._applied_then
        if applied is None or address != applied[1]:
            return None
        self._applied_then = None  # once
        log.info("write to %d carried out, answered exception %d", address, int(applied[0]))
        return applied[0]

    # --- registers ------------------------------------------------------------------------
    def published_status(self, now: float | None = None) -> int:
        """GV291 as a host reads it right now (honours status_delay / command_latency)."""
        now = time.monotonic() if now is None else now
        with self.lock:
            return self.status.published(now, self.robot.command_status)

    def _refresh(self, regs: list[int], start: int) -> None:
        self.image.refresh(regs, start, self.robot, self.published_status())

    def _move_accepted(self) -> None:
        self._move_unanswered = time.monotonic()

    def _arm_exception_window(self) -> None:
        """The exception rule applies from now on: its window (``seconds``) starts (lock held)."""
        if self._exception_seconds is not None:
            self._exception_until = time.monotonic() + self._exception_seconds

    def _exception_window_open(self) -> bool:
        until = self._exception_until
        return until is None or time.monotonic() < until

    # --- inspection -----------------------------------------------------------------------
    @property
    def exceptions_answered(self) -> int:
        """Requests answered with the exception of :meth:`set_exception` so far."""
        with self.lock:
            return self._exceptions_answered

    @property
    def requests_count(self) -> int:
        with self.lock:
            return self._requests

    def requests_by_connection(self) -> dict[int | None, int]:
        """Requests so far by connection id (those of :meth:`connection_ids`): which link carries what."""
        with self.lock:
            return dict(self._requests_on)

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

    def _log_write(self, record: WriteRecord) -> None:
        """Keep ``record``; past :data:`WRITE_LOG_LIMIT` the oldest tenth goes (under the lock)."""
        writes = self.writes
        writes.append(record)
        if len(writes) > WRITE_LOG_LIMIT:
            drop = len(writes) - WRITE_LOG_LIMIT + WRITE_LOG_LIMIT // 10
            del writes[:drop]
            self.writes_dropped += drop

    def refused_writes(self) -> list[SimEvent]:
        """The writes the exception rule (:meth:`set_exception`) answered with its exception, not
        carried out (kind ``"refused"``; detail: function code, address, exception)."""
        with self.lock:
            return [e for e in self.events if e.kind == "refused"]

    def _log_refused(self, function_code: int, address: int, code: ExcCodes) -> None:
        detail = f"write fc=0x{function_code:02X} address={address}: exception {int(code)}"
        with self.lock:
            self.events.append(SimEvent(time.monotonic(), "refused", detail))
        log.info("%s", detail)

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

    def _note_rest(self) -> None:
        """Under the lock, after anything that may start or end motion: note a rest."""
        moving = self.robot.moving
        if self._was_moving and not moving:
            self.rests.append(RestRecord(time.monotonic(), self.robot.pose))
            del self.rests[:-REST_LOG_LIMIT]
        self._was_moving = moving

    def rest_records(self) -> list[RestRecord]:
        """When (``time.monotonic()``) and where the arm came to rest, oldest first."""
        with self.lock:
            return list(self.rests)

    def writes_to(self, address: int) -> list[WriteRecord]:
        """Writes that covered ``address``, narrowed to that one register: ``values == (v,)``."""
        with self.lock:
            return [
                WriteRecord(w.t, w.function_code, address, (w.values[address - w.address],))
                for w in self.writes
                if w.address <= address < w.address + len(w.values)
            ]

    def state(self) -> SimSnapshot:
        with self.lock:
            r = self.robot
            return SimSnapshot(
                t=r.time,
                pose=r.pose,
                joints=tuple(float(v) for v in r.joints),
                work_mode=r.work_mode,
                mode=r.controller_mode,
                program_state=r.program_state,
                alarms=r.alarms,
                teach_enabled=r.teach_enabled,
                teach_frame=int(r.teach_frame),
                teach_ratio=r.teach_ratio,
                jogging=r.jogging,
                command_status=self.published_status(),
                last_kind=r.last_kind,
                points={k: v.pose for k, v in r.points.items()},
                moving=r.busy,
                paused=r.paused,
            )

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
            self.status.release()
            self._wipe_general = True  # GV0..GV99 read 0 from the next request on
        log.info("controller restarted: temp points and GV0-GV99 wiped")

    def restart_after_write(self, register: int, nth: int = 1) -> None:
        """Restart the controller (:meth:`restart_controller`) right after the ``nth`` stored write
        covering ``register`` from now on -- its answer still goes out, the next request finds the
        controller restarted: e.g. between an upload's staged pose and its create point."""
        with self.lock:
            self._restart_after = (int(register), int(nth))

    def _restart_if_due(self, address: int, count: int) -> None:
        rule = self._restart_after  # (under the lock)
        if rule is None or not address <= rule[0] < address + count:
            return
        if rule[1] > 1:
            self._restart_after = (rule[0], rule[1] - 1)
            return
        self._restart_after = None
        self.restart_controller()

    def add_point(self, point_id: int, pose: Pose6, tool: int = 200) -> None:
        """Store a temp point directly (test setup)."""
        with self.lock:
            self.robot.points[point_id] = StoredPoint(pose, tool)

    def remove_point(self, point_id: int) -> None:
        """Forget one temp point (test setup: the controller lost it, a move to it answers 13)."""
        with self.lock:
            self.robot.points.pop(point_id, None)

    def set_joint(self, axis: int, value: float) -> None:
        """Put joint ``axis`` (1..11: J1..J6, then the external axes J7..J11) at ``value`` at once,
        not checked against its limits (test setup: a far external axis, a value that reads as
        garbage with the other word order)."""
        with self.lock:
            joints = self.robot.joints.copy()
            joints[axis - 1] = value
            self.robot.set_joints(joints)

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

    def overwrite_after_create(self, point_id: int, pose: Pose6 | None, tool: int = 200) -> None:
        """Another master that writes its own ``point_id`` at ``pose`` right after every create of
        it (a host's create reports success, then the controller holds the other pose): the
        window between a host's create point and its move. None: no more."""
        with self.lock:
            if pose is None:
                self.robot.foreign_points.pop(int(point_id), None)
            else:
                self.robot.foreign_points[int(point_id)] = StoredPoint(pose, tool)
        log.info("create point %d: %s", point_id, "overwritten by another master" if pose else "kept again")

    def refuse_point_write(
        self, point_id: int, code: ExcCodes | int = ExcCodes.ILLEGAL_VALUE, times: int = 1
    ) -> None:
        """Answer the next ``times`` writes of GV200 naming ``point_id`` (a create point's
        parameters) with Modbus exception ``code``; nothing of them is stored (0: accept again)."""
        self.point_write_refusals.set(point_id, ExcCodes(code), times)
        log.info("create point %d: GV200 write refused %d time(s), exception %d", point_id, times, code)

    def set_response_delay(
        self, seconds: float, connection: int | None = None, addresses: range | None = None
    ) -> None:
        """Hold answers ``seconds``: all of them, or only on one connection (an id of
        :meth:`connection_ids`: a wedged link beside a good one) and/or only for requests touching
        ``addresses``."""
        self._delay_rule = (max(0.0, float(seconds)), connection, addresses)
        log.info("response delay %.3f s%s%s", self._delay_rule[0], on_text(connection), at_text(addresses))

    def set_status_delay(self, seconds: float) -> None:
        self._status_delay = max(0.0, float(seconds))
        log.info("status delay %.3f s", self._status_delay)

    def set_slow_answers(self, seconds: float, every: int) -> None:
        """Hold the answer of every ``every``-th request ``seconds`` (beside the response delay):
        a host whose polls come late now and then, as on a loaded PC. ``every`` 0: off."""
        self._slow_answers = (max(0.0, float(seconds)), max(0, int(every)))
        log.info("every %d. answer held %.3f s", every, seconds)

    def set_watchdog(self, seconds: float | None) -> None:
        """The communication watchdog's silence limit; None or 0 switches it off entirely."""
        self.watchdog.set_timeout(seconds)
        log.info("watchdog %s", f"{self.watchdog.timeout:g} s" if self.watchdog.enabled else "off")

    def set_silent(self, silent: bool) -> None:
        self._silent = bool(silent)
        log.info("silent %s", "on" if silent else "off")

    def set_exception(
        self,
        code: ExcCodes | int | None,
        addresses: range | None = None,
        connection: int | None = None,
        *,
        after_write: int | None = None,
        seconds: float | None = None,
    ) -> None:
        """Answer requests touching ``addresses`` (None: all) with Modbus exception ``code``; only
        on one connection when ``connection`` (an id of :meth:`connection_ids`) is given; only
        from the first request after a stored write covering register ``after_write`` on (e.g.
        440: the status becomes unreadable once a command was taken); for ``seconds`` from then
        on (a controller *busy* for 2 s), else until lifted."""
        with self.lock:
            self._exception_after = None if code is None else after_write
            self._exception_rule = (None if code is None else ExcCodes(code), addresses, connection)
            self._exception_seconds = None if code is None else seconds
            self._exception_until = None
            if self._exception_after is None:
                self._arm_exception_window()
        after = "" if after_write is None else f" after a write to {after_write}"
        log.info(
            "exception %s%s%s%s",
            "off" if code is None else int(code),
            at_text(addresses),
            on_text(connection),
            after,
        )

    def answer_after_applying(self, code: ExcCodes | int, register: int) -> None:
        """The next write starting at ``register`` is carried out, then answered with Modbus
        exception ``code``: a controller (or a gateway) that acted and reported a failure, the
        answer after which the host cannot know what the write did (once)."""
        with self.lock:
            self._applied_then = (ExcCodes(code), register)
        log.info("the next write to %d: carried out, answered exception %d", register, int(code))

    def connection_ids(self) -> list[int]:
        """The ids of the connections open now, oldest first."""
        return self._runner.connection_ids()

    def drop_connections(self) -> int:
        """Close the sockets of the connected clients (the server keeps listening)."""
        count = self._runner.drop_connections()
        log.info("dropped %d connection(s)", count)
        return count
