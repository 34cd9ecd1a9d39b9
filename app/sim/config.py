"""Settings of the simulated controller and the records it keeps (writes, events, snapshots)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

from app import timing
from app.protocol.codec import WordOrder
from app.protocol.datetime_regs import DateTimeLayout
from app.protocol.enums import Alarm, CommandKind, ControllerMode, ProgramState, WorkMode
from app.protocol.registers import NUM_ROBOT_AXES, TEMP_POINT_ID_MAX, TEMP_POINT_ID_MIN
from app.sim.guard import WATCHDOG_TIMEOUT
from app.sim.motion import Pose6

TIMING_PROFILES = ("classic", "fast", "slow")  # GV291 timing (app.sim.status)
GV291_MODES = ("ignored", "writable", "read-only")  # what a host's write to GV291 does


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
    timing: Literal["classic", "fast", "slow"] = "classic"  # GV291 timing profile (app.sim.status)
    gv291: Literal["ignored", "writable", "read-only"] = "ignored"  # what a host's write to GV291 does
    seed: int = 0  # of the "slow" profile's jitter
    clock_offset: float = 0.0  # s the controller's clock (GV288/289) is ahead of the PC's (negative: behind)

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
            raise ValueError(
                f"serial settings: parity N/E/O, stop bits 1/2, baud > 0; got "
                f"{self.parity!r}, {self.stopbits!r}, {self.baudrate!r}"
            )
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
    """Something the controller did by itself: monotonic time, kind (``"watchdog"``; ``"refused"``: a
    write answered by the exception rule), details."""

    t: float
    kind: str
    detail: str


@dataclass(frozen=True)
class RestRecord:
    """The arm came to rest (a move ended, a stop, a jog released): ``time.monotonic()`` and the
    pose it rests at (``SimController.rest_records``)."""

    t: float
    pose: Pose6


REST_LOG_LIMIT = 1000  # rest records kept (the oldest are dropped)


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
