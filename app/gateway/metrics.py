"""The metrics of one robot (a Sparkplug device), their datatypes, deadbands and aliases.

A device's metrics are what one poll of the controller gives -- the status block (560..583, with
the clock every :data:`app.timing.GATEWAY_CLOCK_PERIOD`) and the pose block (GV206..GV255) -- plus
the poller's own link figures and what the gateway counts and says:

* **always** (:data:`DEVICE_METRICS`): pose, joints, mode, program state, alarms, GV291, link
  figures, the controller's clock, the program cycles counted from the program-state register
  (561) by :func:`app.cell.history.program_cycle` -- started, finished, stopped -- since the gateway
  started watching the robot (the controller has no cycle register), and ``Plant/Last command
  result`` (what became of the last DCMD, in words, numbered: ``#3 program/run 7: done ...``);
* **where present** (:data:`EXTERNAL_METRICS`): the external axes E1..E5 (GV212..GV216, the GUI's
  J7..J11), as many as the cell file's ``external_axes`` says the robot has;
* **where enabled** (:data:`COMMAND_METRICS`): the writable metrics, one per ``plant_writes`` entry
  of the cell file -- the DBIRTH advertises exactly these, a DCMD writes them.

Not published: the controller's temperature, firmware or program id (no register for them).

Aliases are unique over the edge node: the node's ``Node Control/Rebirth`` is 1, device ``d``
(0-based, in the cell file's order) has ``1000 * (d + 1) + i`` for metric ``i`` of
:data:`ALL_METRICS` (the same alias whichever of them a device has).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

from app.cell.cell_file import CellController
from app.gateway.payload import DataType, Value
from app.models import ControllerStatus, Pose
from app.protocol.datetime_regs import ControllerClock
from app.protocol.enums import ALARM_BITS, Alarm

__all__ = [
    "ALL_METRICS",
    "COMMAND_METRICS",
    "DEVICE_METRICS",
    "EXTERNAL_METRICS",
    "REBIRTH",
    "MetricSpec",
    "changed",
    "device_alias",
    "device_metrics",
    "device_values",
]

REBIRTH = "Node Control/Rebirth"
REBIRTH_ALIAS = 1
BDSEQ = "bdSeq"
HISTORY_DROPPED = "Node Info/History dropped"
ALIAS_BLOCK = 1000
PLANT_RESULT = "Plant/Last command result"
#: the cycle counters, by the word of :func:`app.cell.history.program_cycle`
CYCLE_METRICS: dict[str, str] = {
    "started": "Program/Cycles started",
    "finished": "Program/Cycles finished",
    "stopped": "Program/Cycles stopped",
}
#: the writable metrics and the cell file's name of each (app.safety.roles.PLANT_WRITES)
COMMAND_WRITES: dict[str, str] = {
    "Plant/Program run": "program/run",
    "Plant/Program stop": "program/stop",
    "Plant/Speed ratio": "speed_ratio",
}
WRITE_METRICS: dict[str, str] = {write: name for name, write in COMMAND_WRITES.items()}

ALARM_METRIC_NAMES: dict[Alarm, str] = {
    Alarm.ESTOP: "Alarms/Emergency stop",
    Alarm.SERVO: "Alarms/Servo",
    Alarm.BRAKE: "Alarms/Brake",
    Alarm.ALGORITHM: "Alarms/Algorithm",
    Alarm.ENCODER: "Alarms/Encoder",
}


@dataclass(frozen=True)
class MetricSpec:
    """One device metric: its name, datatype and deadband (a change within it is not sent)."""

    name: str
    datatype: DataType
    deadband: float = 0.0
    unit: str = ""  # for the README's table


def _specs() -> tuple[MetricSpec, ...]:
    pose = [
        MetricSpec(f"Pose/{axis}", DataType.DOUBLE, 0.01, "mm" if axis in "XYZ" else "deg")
        for axis in "XYZABC"
    ]
    joints = [MetricSpec(f"Joints/J{i}", DataType.DOUBLE, 0.01, "deg") for i in range(1, 7)]
    state = [
        MetricSpec("Status/Work mode", DataType.UINT16),
        MetricSpec("Status/Program state", DataType.UINT16),
        MetricSpec("Alarms/Word", DataType.UINT16),
    ]
    alarms = [MetricSpec(ALARM_METRIC_NAMES[bit], DataType.BOOLEAN) for bit in ALARM_BITS]
    link = [
        MetricSpec("Command/Last result", DataType.UINT32),
        MetricSpec("Link/Freshness", DataType.INT64, 500.0, "ms"),
        MetricSpec("Link/RTT", DataType.DOUBLE, 5.0, "ms"),
        MetricSpec("Link/Errors", DataType.UINT64),
        MetricSpec("Controller/Clock", DataType.STRING),
    ]
    cycles = [MetricSpec(name, DataType.UINT64) for name in CYCLE_METRICS.values()]
    return (*pose, *joints, *state, *alarms, *link, *cycles, MetricSpec(PLANT_RESULT, DataType.STRING))


DEVICE_METRICS: tuple[MetricSpec, ...] = _specs()
EXTERNAL_METRICS: tuple[MetricSpec, ...] = tuple(
    MetricSpec(f"External/E{i}", DataType.DOUBLE, 0.01, "mm or deg") for i in range(1, 6)
)
COMMAND_METRICS: tuple[MetricSpec, ...] = (
    MetricSpec("Plant/Program run", DataType.UINT16),  # the program id to run (446, then 440 <- 1)
    MetricSpec("Plant/Program stop", DataType.BOOLEAN),  # true: stop (441 <- 1)
    MetricSpec("Plant/Speed ratio", DataType.UINT16, unit="%"),  # the program speed ratio (449), 1..100
)
ALL_METRICS: tuple[MetricSpec, ...] = (*DEVICE_METRICS, *EXTERNAL_METRICS, *COMMAND_METRICS)
METRIC_INDEX: dict[str, int] = {spec.name: i for i, spec in enumerate(ALL_METRICS)}


def device_metrics(controller: CellController) -> tuple[int, ...]:
    """The indexes (in :data:`ALL_METRICS`) of the metrics ``controller``'s device has, in order."""
    names = [spec.name for spec in DEVICE_METRICS]
    names += [spec.name for spec in EXTERNAL_METRICS[: controller.external_axes]]
    names += [spec.name for spec in COMMAND_METRICS if COMMAND_WRITES[spec.name] in controller.plant_writes]
    return tuple(METRIC_INDEX[name] for name in names)


def device_alias(device_index: int, metric_index: int) -> int:
    return ALIAS_BLOCK * (device_index + 1) + metric_index


def clock_text(clock: ControllerClock) -> str:
    """The controller's clock as it reads (it has no time zone), or its raw words when invalid."""
    if clock.value is None:
        return f"invalid ({clock.raw_hex})"
    return clock.value.isoformat()


@dataclass(frozen=True)
class Reading:
    """One answered poll of a controller, with the poller's link figures."""

    pose: Pose
    status: ControllerStatus
    clock: ControllerClock | None  # None: not read this poll (the last one stands)
    rtt_ms: float
    errors: int  # failed polls since the gateway started
    answered_at: float  # time.monotonic() of the answer
    wall_ms: int  # the same moment as ms since the epoch (the metrics' timestamp)


_POSE_NAMES = tuple(f"Pose/{axis}" for axis in "XYZABC")
_JOINT_NAMES = tuple(f"Joints/J{i}" for i in range(1, 7))
_EXTERNAL_NAMES = tuple(spec.name for spec in EXTERNAL_METRICS)
_ALARM_NAMES = tuple((ALARM_METRIC_NAMES[bit], int(bit)) for bit in ALARM_BITS)  # ints: no enum op a poll
_NO_JOINTS = (math.nan,) * 6


def device_values(
    reading: Reading, freshness_ms: int, clock: str | None, kept: Mapping[str, Value]
) -> dict[str, Value]:
    """Every metric's value for ``reading`` (the names of :data:`ALL_METRICS`): what the poll read,
    and ``kept``, what the gateway holds of the device (the cycle counters, the plant's metrics)."""
    pose, status = reading.pose, reading.status
    joints = pose.joints or _NO_JOINTS
    values: dict[str, Value] = dict(zip(_POSE_NAMES, pose.xyzabc, strict=True))
    values.update(zip(_JOINT_NAMES, map(float, joints[:6]), strict=False))
    alarms = int(status.alarms)
    values.update(
        {
            "Status/Work mode": int(status.mode),
            "Status/Program state": int(status.program_state),
            "Alarms/Word": alarms,
            "Command/Last result": int(status.command_status_code) & 0xFFFFFFFF,
            "Link/Freshness": freshness_ms,
            "Link/RTT": round(reading.rtt_ms, 3),
            "Link/Errors": reading.errors,
            "Controller/Clock": clock,
        }
    )
    values.update((name, bool(alarms & bit)) for name, bit in _ALARM_NAMES)
    values.update(zip(_EXTERNAL_NAMES, map(float, pose.ext), strict=True))
    values.update(kept)
    return values


def changed(spec: MetricSpec, sent: Value, now: Value, deadbands: Mapping[str, float]) -> bool:
    """Report by exception: does ``now`` differ from what was last ``sent`` by more than the deadband?"""
    if sent is None or now is None or isinstance(now, bool | str):
        return sent != now
    deadband = deadbands.get(spec.name, spec.deadband)
    if isinstance(sent, bool | str):
        return True
    if math.isnan(now) or math.isnan(sent):
        return not (math.isnan(now) and math.isnan(sent))
    return abs(now - sent) > deadband if deadband > 0 else now != sent
