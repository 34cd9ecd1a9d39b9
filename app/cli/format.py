"""teachpad-cli's output formats and argument parsers (the pure parts of app/cli/main.py).

The ``parse_*`` functions are public: argparse ``type=`` callables (they raise
``argparse.ArgumentTypeError``) and the parsers of command words (they raise
:class:`~app.errors.InvalidInput`), shared by every command module.
"""

from __future__ import annotations

import argparse
import datetime as dt
from collections.abc import Sequence
from typing import Any

from app.errors import InvalidInput
from app.link.types import StepFrame
from app.models import ControllerStatus, Pose
from app.protocol import registers
from app.protocol.codec import WordOrder
from app.protocol.enums import (
    CARTESIAN_AXIS_NAMES,
    JOINT_AXIS_NAMES,
    CommandStatus,
    alarm_names,
    controller_mode_text,
    program_state_text,
)

__all__ = [
    "JOG_SECONDS_MAX",
    "format_number",
    "format_status",
    "format_watch_line",
    "parse_axis",
    "parse_direction",
    "parse_jog_seconds",
    "parse_moment",
    "parse_positive_float",
    "parse_positive_int",
    "parse_step_offsets",
    "parse_word_order",
    "parse_zero_axis",
    "status_to_dict",
]

JOG_SECONDS_MAX = 30.0  # s: no jog from the CLI runs longer
# --------------------------------------------------------------------------------------------
# Formatting
# --------------------------------------------------------------------------------------------


def format_number(value: float) -> str:
    return f"{value:.3f}"


def status_to_dict(pose: Pose, status: ControllerStatus) -> dict[str, Any]:
    """The JSON shape of ``status --json``."""
    code = status.command_status_code
    decoded = CommandStatus(None, code)
    clock = status.clock
    return {
        "pose": dict(zip(("x", "y", "z", "a", "b", "c"), pose.xyzabc, strict=True)),
        "external_axes": list(pose.ext),
        "joints": list(pose.joints) if pose.joints is not None else None,
        "mode": {"value": int(status.mode), "name": controller_mode_text(int(status.mode))},
        "program_state": {
            "value": int(status.program_state),
            "name": program_state_text(int(status.program_state)),
        },
        "alarms": {"value": int(status.alarms), "names": alarm_names(int(status.alarms))},
        "command_status": {"code": code, "text": decoded.text},
        "clock": None
        if clock is None
        else {
            "iso": clock.value.isoformat() if clock.value is not None else None,
            "raw": list(clock.raw),
            "raw_hex": clock.raw_hex,
        },
    }


def format_status(pose: Pose, status: ControllerStatus) -> str:
    data = status_to_dict(pose, status)
    cart = "  ".join(
        f"{n} {format_number(v)}" for n, v in zip(CARTESIAN_AXIS_NAMES, pose.xyzabc, strict=True)
    )
    ext = "  ".join(f"J{i} {format_number(v)}" for i, v in enumerate(pose.ext, start=7))
    joints = (
        "  ".join(f"J{i} {format_number(v)}" for i, v in enumerate(pose.joints, start=1))
        if pose.joints is not None
        else "-"
    )
    alarms = ", ".join(data["alarms"]["names"]) or "none"
    lines = [
        f"pose      {cart}",
        f"external  {ext}",
        f"joints    {joints}",
        f"mode      {data['mode']['name']} ({data['mode']['value']})",
        f"program   {data['program_state']['name']} ({data['program_state']['value']})",
        f"alarms    {alarms} ({data['alarms']['value']})",
        f"command   {data['command_status']['code']} {data['command_status']['text']}",
    ]
    clock = data["clock"]
    if clock is not None:
        when = clock["iso"].replace("T", " ") if clock["iso"] else "invalid"
        lines.append(f"clock     {when} (raw {clock['raw_hex']})")
    return "\n".join(lines)


def format_watch_line(elapsed: float, pose: Pose, status: ControllerStatus) -> str:
    cart = " ".join(f"{n}={format_number(v)}" for n, v in zip(CARTESIAN_AXIS_NAMES, pose.xyzabc, strict=True))
    alarms = ",".join(alarm_names(int(status.alarms))) or "none"
    return (
        f"t={elapsed:.3f} {cart} mode={controller_mode_text(int(status.mode))} "
        f"program={program_state_text(int(status.program_state))} alarms={alarms} "
        f"cmd={status.command_status_code}"
    )


# --------------------------------------------------------------------------------------------
# Argument helpers
# --------------------------------------------------------------------------------------------


def parse_axis(name: str, joint_frame: bool) -> int:
    key = name.strip().upper()
    names = JOINT_AXIS_NAMES if joint_frame else CARTESIAN_AXIS_NAMES
    if key in names:
        return names.index(key)
    frame = "joint frame" if joint_frame else "base, user and tool frames"
    raise InvalidInput(f"axis {name[:8]!r} does not exist in the {frame} (use {', '.join(names)})")


def parse_direction(text: str) -> int:
    key = text.strip().lower()
    if key in ("+", "pos", "positive", "1"):
        return 1
    if key in ("-", "neg", "negative", "0"):
        return 0
    raise InvalidInput(f"direction must be + or -, got {text!r}")


def parse_step_offsets(frame: StepFrame, items: Sequence[str]) -> tuple[list[float], list[float]]:
    offsets = [0.0] * registers.NUM_ROBOT_AXES
    ext = [0.0] * registers.NUM_EXTERNAL_AXES
    main_names = JOINT_AXIS_NAMES[:6] if frame is StepFrame.JOINT else CARTESIAN_AXIS_NAMES
    ext_names = JOINT_AXIS_NAMES[6:]
    if not items:
        raise InvalidInput(f"step needs offsets like {main_names[0]}=10")
    for item in items:
        name, sep, value_text = item.partition("=")
        if not sep:
            raise InvalidInput(f"offset {item!r} is not AXIS=VALUE")
        key = name.strip().upper()
        try:
            value = float(value_text)
        except ValueError:
            raise InvalidInput(f"offset {item!r}: {value_text!r} is not a number") from None
        if key in main_names:
            offsets[main_names.index(key)] = value
        elif key in ext_names:
            ext[ext_names.index(key)] = value
        else:
            allowed = ", ".join((*main_names, *ext_names))
            raise InvalidInput(f"axis {name!r} is not valid for a {frame.value} step (use {allowed})")
    return offsets, ext


def parse_zero_axis(text: str) -> int | None:
    key = text.strip().upper()
    if key == "ALL":
        return None
    if key in JOINT_AXIS_NAMES:
        return JOINT_AXIS_NAMES.index(key)
    if key.isdigit() and 1 <= int(key) <= registers.NUM_AXES_TOTAL:
        return int(key) - 1
    raise InvalidInput(f"zero: axis must be J1..J11, 1..11 or all, got {text!r}")


def parse_word_order(text: str) -> WordOrder:
    try:
        return WordOrder.parse(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def parse_jog_seconds(text: str) -> float:
    value = parse_positive_float(text)
    if value > JOG_SECONDS_MAX:
        raise argparse.ArgumentTypeError(f"a jog runs at most {JOG_SECONDS_MAX:g} s, got {text[:20]}")
    return value


def parse_positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not value > 0 or value == float("inf"):
        raise argparse.ArgumentTypeError(f"must be a positive number, got {text}")
    return value


def parse_positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a whole number: {text[:20]!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError("must be at least 1")
    return value


def parse_moment(text: str) -> dt.datetime:
    """A local date or time, ``YYYY-MM-DD[THH:MM[:SS]]``."""
    try:
        return dt.datetime.fromisoformat(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a date or time (YYYY-MM-DD[THH:MM]): {text[:20]!r}") from None
