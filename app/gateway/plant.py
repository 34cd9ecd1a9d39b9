"""Writes from the plant: a Sparkplug DCMD that an administrator enabled for one robot.

Off by default. The cell file's ``plant_writes`` names, per controller, the writes a plant may make
(:data:`app.safety.roles.PLANT_WRITES`: ``program/run``, ``program/stop``, ``speed_ratio``); the
DBIRTH advertises exactly those as metrics (``Plant/Program run``, ``Plant/Program stop``,
``Plant/Speed ratio``). Each DCMD metric becomes a :class:`PlantCommand`, and :class:`PlantWriter`
makes it the way a pendant's write is made:

* **the plant role** (:func:`app.safety.roles.plant_reason`): a write not enabled for this robot is
  refused at once, nothing is sent;
* **the one write guard**: the write goes out through the poller's own
  :class:`~app.link.client.RobotClient` (monitor-only for a robot without plant writes: its guard
  refuses any write) in the poller's thread, between two polls, with the status just read;
* **the audit trail** (:class:`~app.safety.audit.AuditLog`, role ``plant (ROBOT)``): every write
  (judged: a run's and a stop's outcome recorded against them) and every refusal;
* **the safety envelope**: the speed ratio (and a run's, which is the last ratio the plant set, else
  the envelope's cap) may not pass the envelope's ratio cap (:meth:`Envelope.jog_ratio_cap`, the cap
  reduced-speed mode also puts on programs); a controller program's path is the controller's, the
  host cannot check it;
* **refused while a pendant commands the robot**. The gateway cannot see a pendant, only what it
  does to the controller, and decides so: the robot is commanded by a pendant while (1) this
  TeachPad's own pendant took control of it (:meth:`EdgeNode.set_pendant_robot`, the GUI's Take
  control), (2) the controller is not in auto -- manual is its teach mode (its own pendant), Modbus
  teach is a pendant's jog session, (3) another master was seen on it within
  :data:`app.timing.GATEWAY_PLANT_PENDANT_WINDOW` (GV291 results or shared registers changing without
  a write of ours: a pendant's step, move or teach), or (4) a program or motion the plant did not
  start is under way (another master's command). A stop is refused then too: the pendant holding
  the robot has its own stop, and the plant's must not stop what the operator is doing.

What became of each command is said, in words and numbered (``#4 program/run 7: ...``), in the
device's ``Plant/Last command result`` metric (:meth:`PlantListener.plant_said`): refused and why,
sent, then its outcome (a run is followed by the poller's own reads to its end). A command that
waited longer than :data:`app.timing.GATEWAY_PLANT_COMMAND_TTL` for its robot (one that does not
answer) is refused, never made late.
"""

from __future__ import annotations

import math
import threading
import time
from collections import deque
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Protocol

from app import timing
from app.cell.cell_file import CellController
from app.errors import TeachPadError
from app.gateway.payload import Value
from app.link.client import RobotClient
from app.link.outcome import outcome_note
from app.link.watch import MotionWatch, StateCheck
from app.models import ControllerStatus, Pose
from app.protocol import registers
from app.protocol.enums import (
    ControllerMode,
    ProgramMotionMode,
    ProgramState,
    controller_mode_text,
    program_state_text,
)
from app.safety.audit import AuditLog
from app.safety.envelope import Envelope
from app.safety.roles import PLANT_ROLE, plant_reason

__all__ = ["PlantCommand", "PlantListener", "PlantWriter", "plant_audit_role"]

_UNDER_WAY = (ProgramState.RUNNING, ProgramState.PAUSED)


def plant_audit_role(robot: str) -> str:
    """The role the audit trail names for the plant's writes to ``robot``."""
    return f"{PLANT_ROLE} ({robot})"


@dataclass(frozen=True)
class PlantCommand:
    """One DCMD metric for one robot: its number (per robot), the write and the value sent."""

    number: int
    write: str  # a name of app.safety.roles.PLANT_WRITES (or not: refused)
    value: Value
    received: float  # time.monotonic()

    @property
    def text(self) -> str:
        return f"#{self.number} {self.write} {_value_text(self.value)}".rstrip()


def _value_text(value: Value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    return "" if value is None else f"{value:g}" if isinstance(value, float) else str(value)


class PlantListener(Protocol):
    """Who hears what became of a command (the edge node: a DDATA), from any thread."""

    def plant_said(self, device: str, text: str, values: Mapping[str, Value]) -> None: ...


class PlantRefused(Exception):
    """A command refused before anything was sent; the message says why."""


def _whole(value: Value, low: int, high: int, what: str) -> int:
    """A whole number low..high (an integral float too: hosts send what their tag holds)."""
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise PlantRefused(f"{what} must be a whole number {low}..{high}, got {_value_text(value) or 'null'}")
    if value != int(value) or not low <= value <= high:
        raise PlantRefused(f"{what} must be a whole number {low}..{high}, got {_value_text(value)}")
    return int(value)


class PlantWriter:
    """One robot's plant writes, made in its poller's thread (see the module docstring)."""

    def __init__(
        self,
        controller: CellController,
        envelope: Envelope | None,
        audit: AuditLog,
        listener: PlantListener,
        pendant: Callable[[], bool],
    ) -> None:
        self.name = controller.name
        self.enabled = frozenset(controller.plant_writes)
        self._envelope = envelope
        self.audit = audit
        self._listener = listener
        self._pendant = pendant
        self._lock = threading.Lock()
        self._queue: deque[PlantCommand] = deque()
        self.ratio: int | None = None  # the program speed ratio the plant set last (None: not yet)
        self._following: tuple[PlantCommand, MotionWatch | StateCheck] | None = None

    # -- any thread ---------------------------------------------------------------------------
    def submit(self, command: PlantCommand) -> None:
        """Take a DCMD: refused at once when not enabled, else made between the next two polls."""
        why = plant_reason(command.write, self.enabled)
        if why is not None:
            self.refuse(command, why)
            return
        with self._lock:
            self._queue.append(command)

    def refuse(self, command: PlantCommand, why: str) -> None:
        """Refused before anything was sent: audited, and said."""
        args = {"robot": self.name, "write": command.write, "value": command.value, "number": command.number}
        self.audit.record_refused(f"plant {command.write}", why, args)
        self._listener.plant_said(self.name, f"{command.text} refused: {why}", {})

    def _say(self, command: PlantCommand, text: str, values: Mapping[str, Value] | None = None) -> None:
        self._listener.plant_said(self.name, f"{command.text}: {text}", values or {})

    # -- the poller's thread ------------------------------------------------------------------
    def after_poll(self, client: RobotClient, status: ControllerStatus, pose: Pose) -> None:
        """After an answered poll: follow what the plant started, then make the waiting commands."""
        now = time.monotonic()
        self._follow(status, pose, now)
        while True:
            with self._lock:
                if not self._queue:
                    return
                command = self._queue.popleft()
            self._make(command, client, pose, now)  # it reads the status itself

    def _follow(self, status: ControllerStatus, pose: Pose, now: float) -> None:
        if self._following is None:
            return
        command, completion = self._following
        result = completion.result or completion.update(status, pose, now)
        if result is not None:
            self._following = None
            self._say(command, result.message)

    def _make(self, command: PlantCommand, client: RobotClient, pose: Pose, now: float) -> None:
        try:
            if now - command.received > timing.GATEWAY_PLANT_COMMAND_TTL:
                raise PlantRefused(
                    f"{self.name} did not answer within {timing.GATEWAY_PLANT_COMMAND_TTL:g} s of the command"
                )
            # read now: the poll's status may have been read before the command came (a poll in
            # flight when it arrived), and another master's program started in between would be
            # missed (a run beside busy loops: a plant Stop sent into a pendant's program)
            status = client.read_status()
            self._check_commanded(client, status, now)
            if command.write == "speed_ratio":
                self._set_ratio(command, client)
            elif command.write == "program/run":
                self._run(command, client, pose)
            else:
                self._stop(command, client, now)
        except PlantRefused as exc:
            self.refuse(command, str(exc))
        except TeachPadError as exc:  # the client's own refusal (audited there) or the link's failure
            self._say(command, f"not done: {exc}")

    def _check_commanded(self, client: RobotClient, status: ControllerStatus, now: float) -> None:
        """:class:`PlantRefused` while a pendant (or another master) commands the robot."""
        name = self.name
        if self._pendant():
            raise PlantRefused(f"a pendant commands {name} (TeachPad's Take control)")
        if status.mode == ControllerMode.MODBUS_TEACH:
            raise PlantRefused(f"a pendant commands {name}: the controller is in Modbus teach mode (a jog)")
        if status.mode != ControllerMode.AUTO:
            mode = controller_mode_text(int(status.mode))
            raise PlantRefused(
                f"{name} is in {mode} mode: its own pendant commands it (the plant writes only in auto)"
            )
        window = timing.GATEWAY_PLANT_PENDANT_WINDOW
        seen = client.foreign.last_seen
        if seen is not None and now - seen < window:
            raise PlantRefused(
                f"another master (a pendant or a PLC) commanded {name} {now - seen:.0f} s ago "
                f"(the plant waits {window:g} s after it)"
            )
        ours = self._following is not None and isinstance(self._following[1], MotionWatch)
        if status.program_state in _UNDER_WAY and not ours:
            raise PlantRefused(f"{name} is moving under another master's command (not a run of the plant's)")

    def _cap(self) -> float:
        return 100.0 if self._envelope is None else self._envelope.jog_ratio_cap(False)

    def _set_ratio(self, command: PlantCommand, client: RobotClient) -> None:
        ratio = _whole(command.value, 1, 100, "the speed ratio")
        if ratio > self._cap():
            raise PlantRefused(
                f"speed ratio {ratio} % is above the {self._cap():g} % the safety envelope allows"
            )
        client.write_register(registers.REG_PROGRAM_SPEED, ratio)
        self.ratio = ratio
        self._say(command, f"done: program speed ratio {ratio} %", {"Plant/Speed ratio": ratio})

    def _run(self, command: PlantCommand, client: RobotClient, pose: Pose) -> None:
        program = _whole(command.value, 0, 0xFFFF, "the program id")
        ratio = self.ratio if self.ratio is not None else max(1, math.floor(self._cap()))
        if ratio > self._cap():  # the envelope changed since the ratio was set
            raise PlantRefused(
                f"speed ratio {ratio} % is above the {self._cap():g} % the safety envelope allows"
            )
        # as the pendant's and the CLI's: the trigger (440) is judged, its outcome recorded against it
        watch = client.run_program(program, ProgramMotionMode.SINGLE_RUN, 1, ratio, before=pose)
        self._following = (command, watch)
        self._say(
            command, f"sent: run program {program} at {ratio} % (under way)", {"Plant/Program run": program}
        )

    def _stop(self, command: PlantCommand, client: RobotClient, now: float) -> None:
        if command.value is not True:
            raise PlantRefused(f"a stop takes true, got {_value_text(command.value) or 'null'}")
        with client.judged_writes() as judged:
            client.stop()
        if self._following is not None and self._following[1].result is not None:  # the run it stopped
            self._say(self._following[0], self._following[1].result.message)
        check = StateCheck("stop", _stopped, _state_words, now)
        check.note = outcome_note(client.audit, judged)
        self._following = (command, check)
        self._say(command, "sent: stop")


def _stopped(status: ControllerStatus) -> bool:
    return status.program_state == ProgramState.STOPPED


def _state_words(status: ControllerStatus) -> str:
    return f"the program state reads {program_state_text(int(status.program_state))}"
