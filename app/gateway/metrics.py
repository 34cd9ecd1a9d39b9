"""The metrics of one robot (a Sparkplug device), their datatypes, deadbands and aliases.

A device's metrics are what one poll of the controller gives -- the status block (560..583, with
the clock every :data:`app.timing.GATEWAY_CLOCK_PERIOD`) and the pose block (GV206..GV255) -- plus
the poller's own link figures. Not published (the reads the gateway makes do not give them): the
cycle counter (no register in PROTOCOL.md's tables), the external axes E1..E5 (in the pose block,
but nothing says which a controller has), and the controller's temperature, firmware or program id.

Aliases are unique over the edge node: the node's ``Node Control/Rebirth`` is 1, device ``d``
(0-based, in the cell file's order) has ``1000 * (d + 1) + i`` for its ``i``-th metric.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

from app.gateway.payload import DataType, Value
from app.models import ControllerStatus, Pose
from app.protocol.datetime_regs import ControllerClock
from app.protocol.enums import ALARM_BITS, Alarm

__all__ = ["DEVICE_METRICS", "REBIRTH", "MetricSpec", "changed", "device_alias", "device_values"]

REBIRTH = "Node Control/Rebirth"
REBIRTH_ALIAS = 1
BDSEQ = "bdSeq"
HISTORY_DROPPED = "Node Info/History dropped"
ALIAS_BLOCK = 1000

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
    return (*pose, *joints, *state, *alarms, *link)


DEVICE_METRICS: tuple[MetricSpec, ...] = _specs()
METRIC_INDEX: dict[str, int] = {spec.name: i for i, spec in enumerate(DEVICE_METRICS)}


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


def device_values(reading: Reading, freshness_ms: int, clock: str | None) -> dict[str, Value]:
    """Every metric's value for ``reading`` (the names of :data:`DEVICE_METRICS`)."""
    pose, status = reading.pose, reading.status
    joints = pose.joints or (math.nan,) * 6
    values: dict[str, Value] = {f"Pose/{axis}": v for axis, v in zip("XYZABC", pose.xyzabc, strict=True)}
    values.update({f"Joints/J{i + 1}": float(v) for i, v in enumerate(joints[:6])})
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
    values.update({ALARM_METRIC_NAMES[bit]: bool(alarms & bit) for bit in ALARM_BITS})
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
