"""The register-map self-test's checks: pure functions of one read of the documented registers.

:data:`SELFTEST_BLOCKS` are read with 0x03 only (nothing is written, nothing moves), the two
blocks the link polls: the live block (412..511: X Y Z A B C, the external axes, the program
registers 446..451 between them, the joints of the project extension) and table 2 (560..583:
mode, program state, alarms, clock, GV291).
:func:`check_register_map` turns them into one :class:`CheckLine` per check:

* **pose** -- X Y Z A B C read in the profile's word order are a pose a robot can stand at; read
  the other way round they would be one: the word order is wrong
  (:mod:`app.protocol.word_order_check`, the link's own rule, reused).
* **model** -- the robot model's forward kinematics of the joints lands on the pose (position
  and orientation, :func:`app.view3d.agreement.compare_model`). When it does not, the same
  registers are tried the other ways a controller may report them: the other word order (a
  profile setting), other A B C conventions, metres or radians (not profile settings: TeachPad's
  fixed-axis X-Y-Z in degrees and mm is fixed, :mod:`app.geometry`), and the first that agrees
  is the likely fix. A controller that publishes no joints cannot be checked (the joints are a
  project extension of the simulator).
* **clock** -- the date/time registers in the profile's layout against the PC's clock (within
  :data:`CLOCK_TOLERANCE`); the other layout is tried when they do not agree.
* **mode**, **program state**, **alarms**, **program motion mode**, **speed ratio** -- within
  their tables; **command status** (GV291) one of the documented codes, in either encoding.

Each line has a verdict (:class:`CheckVerdict`): MATCH, MISMATCH (with the likely fix) or UNCHECKED
(the controller refused the read, publishes nothing there). ``code`` and ``args`` let the GUI say
the line in the operator's language; ``text`` and ``fix`` are the English (teachpad-cli, logs).
"""

from __future__ import annotations

import datetime as dt
import enum
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Final

from app.geometry import abc_to_matrix, rot_x, rot_y, rot_z
from app.link.progress import RegisterBlocks
from app.protocol import registers
from app.protocol.codec import WordOrder, decode_floats, registers_to_float
from app.protocol.datetime_regs import DateTimeLayout, decode_clock
from app.protocol.enums import (
    ALARM_MASK,
    CONTROLLER_MODE_TEXT,
    MOVE_STATUS_TEXT,
    PROGRAM_MOTION_MODE_TEXT,
    PROGRAM_STATE_TEXT,
    TEACH_STATUS_TEXT,
    ControllerMode,
    ProgramMotionMode,
    ProgramState,
    alarm_names,
)
from app.protocol.word_order_check import is_pose, judge_values, other_order
from app.view3d.agreement import MODEL_TOLERANCE_DEG, MODEL_TOLERANCE_MM, compare_model

if TYPE_CHECKING:
    import numpy as np

    from app.view3d.kinematics import ArmModel
else:
    from app.lazy_numpy import np
from app.lazy_numpy import Matrix

__all__ = [
    "CLOCK_TOLERANCE",
    "SELFTEST_BLOCKS",
    "CheckLine",
    "CheckVerdict",
    "SelfTestReport",
    "check_register_map",
]

#: The blocks the self-test reads (start, count), all 0x03: those the link polls.
POSE_BLOCK: Final = (registers.POSE_BLOCK_START, registers.POSE_BLOCK_COUNT)  # 412..511 (446..451 inside)
STATUS_BLOCK: Final = (registers.STATUS_BLOCK_START, registers.STATUS_BLOCK_COUNT)  # 560..583
SELFTEST_BLOCKS: Final = (POSE_BLOCK, STATUS_BLOCK)

#: The controller's clock and the PC's may differ this much (s) and still agree: the clock
#: registers have whole seconds, a controller's clock set by hand drifts a little.
CLOCK_TOLERANCE: Final = 120.0

_SPEED_RATIO_RANGE: Final = (0, 100)  # 449: 1..100 by the table; 0 before any program was set


class CheckVerdict(enum.Enum):
    MATCH = "match"
    MISMATCH = "mismatch"
    UNCHECKED = "not checked"


@dataclass(frozen=True)
class CheckLine:
    """One check's outcome. ``check``: which (pose, model, clock, ...); ``code`` what was found
    (for the GUI's words) with ``args``; ``text`` the English; ``fix`` the likely fix in English
    ("" none); ``setting`` (field, value) when the fix is a register profile setting."""

    check: str
    verdict: CheckVerdict
    code: str
    text: str
    args: Mapping[str, str | int | float] = field(default_factory=dict)
    fix: str = ""
    fix_code: str = ""
    setting: tuple[str, str] | None = None

    @property
    def line(self) -> str:
        """One line for a terminal or a log: ``mismatch  pose: ...; fix: ...``."""
        text = f"{self.verdict.value:<11} {self.check}: {self.text}"
        return f"{text}; likely fix: {self.fix}" if self.fix else text


@dataclass(frozen=True)
class SelfTestReport:
    """Every line of one self-test, the profile's choices it ran with, and when."""

    lines: tuple[CheckLine, ...]
    word_order: WordOrder
    datetime_layout: DateTimeLayout
    read_at: float

    @property
    def passed(self) -> bool:
        """Everything that could be checked matched (lines not checked do not fail it)."""
        return not self.mismatches

    @property
    def mismatches(self) -> tuple[CheckLine, ...]:
        return tuple(line for line in self.lines if line.verdict is CheckVerdict.MISMATCH)

    @property
    def settings_to_change(self) -> dict[str, str]:
        """The register profile settings the mismatches point at (field -> value)."""
        return dict(line.setting for line in self.mismatches if line.setting is not None)

    def summary(self) -> str:
        counts = {v: sum(1 for line in self.lines if line.verdict is v) for v in CheckVerdict}
        head = "the register map matches" if self.passed else "the register map does not match"
        return (
            f"{head}: {counts[CheckVerdict.MATCH]} matched, {counts[CheckVerdict.MISMATCH]} did not, "
            f"{counts[CheckVerdict.UNCHECKED]} not checked"
        )


def _setting_fix(name: str, value: str) -> tuple[str, str, tuple[str, str]]:
    return (f'set the register profile\'s {name} to "{value}"', "setting", (name, value))


def _refused(check: str, block: tuple[int, int], code: int) -> CheckLine:
    what = f"{block[0]}..{block[0] + block[1] - 1}"
    return CheckLine(
        check,
        CheckVerdict.UNCHECKED,
        "refused",
        f"the controller refused the read of registers {what} (Modbus exception {code})",
        {"what": what, "exception": code},
    )


def check_register_map(
    read: RegisterBlocks,
    word_order: WordOrder,
    datetime_layout: DateTimeLayout,
    model: ArmModel | None,
    pc_now: dt.datetime | None = None,
) -> SelfTestReport:
    """Every check on one read (see the module docstring). ``pc_now``: the PC's local time when
    the registers were read (default: from ``read.read_at``)."""
    now = pc_now or dt.datetime.fromtimestamp(read.read_at)
    pose_regs = read.block(*POSE_BLOCK)
    status_regs = read.block(*STATUS_BLOCK)
    lines: list[CheckLine] = []
    if pose_regs is None:
        code = read.refusal(*POSE_BLOCK) or 0
        lines.append(_refused("pose", POSE_BLOCK, code))
    else:
        lines.append(check_pose(pose_regs, word_order))
        lines.append(check_model(pose_regs, word_order, model))
    if status_regs is None:
        code = read.refusal(*STATUS_BLOCK) or 0
        lines.append(_refused("status", STATUS_BLOCK, code))
    else:
        lines += check_status(status_regs, word_order, datetime_layout, now)
    if pose_regs is not None:
        program = registers.REG_PROGRAM_ID - registers.POSE_BLOCK_START
        lines += check_program(pose_regs[program : program + 6])
    return SelfTestReport(tuple(lines), word_order, datetime_layout, read.read_at)


# --- the pose ---------------------------------------------------------------------------------


def _gvs(regs: Sequence[int], gv: int, count: int, order: WordOrder) -> list[float]:
    start = registers.gv_reg(gv) - registers.POSE_BLOCK_START
    return decode_floats(regs[start : start + 2 * count], order)


def _pose_text(values: Sequence[float]) -> str:
    return " ".join(f"{n}={v:.6g}" for n, v in zip("XYZABC", values, strict=False))


def check_pose(regs: Sequence[int], order: WordOrder) -> CheckLine:
    """X Y Z A B C and the external axes: a pose in the profile's order, or only in the other."""
    values = _gvs(regs, registers.GV_POSE, 6, order) + _gvs(
        regs, registers.GV_EXT_AXES, registers.NUM_EXTERNAL_AXES, order
    )
    start = registers.gv_reg(registers.GV_POSE) - registers.POSE_BLOCK_START
    if not any(regs[start : start + 12]):
        return CheckLine(
            "pose", CheckVerdict.UNCHECKED, "pose-zero", "X Y Z A B C are all 0: nothing to judge"
        )
    verdict = judge_values(values, order)
    args: dict[str, str | int | float] = {"order": order.value, "pose": _pose_text(verdict.read)}
    args.update({f"p{i}": v for i, v in enumerate(verdict.read[:6])})  # the GUI writes them its way
    if is_pose(verdict.read):
        return CheckLine(
            "pose", CheckVerdict.MATCH, "pose-ok", f"read {order.value}, {args['pose']} is a pose", args
        )
    if verdict.swapped:
        other = other_order(order).value
        args.update(other=other, other_pose=_pose_text(verdict.other))
        args.update({f"o{i}": v for i, v in enumerate(verdict.other[:6])})
        fix, fix_code, setting = _setting_fix("word_order", other)
        text = f"read {order.value} the pose is {args['pose']}; read {other} it is {args['other_pose']}"
        return CheckLine("pose", CheckVerdict.MISMATCH, "pose-swapped", text, args, fix, fix_code, setting)
    return CheckLine(
        "pose",
        CheckVerdict.MISMATCH,
        "pose-implausible",
        f"X Y Z A B C read either way are no pose a robot stands at ({args['pose']})",
        args,
        "check the unit id and that this controller has the vendor document's register map",
        "check-map",
    )


# --- the pose against the joints through the robot model -------------------------------------


def _fixed_xyz(a: float, b: float, c: float) -> Matrix:
    return abc_to_matrix(a, b, c)


def _euler_xyz(a: float, b: float, c: float) -> Matrix:
    """Rotating axes X-Y'-Z'' (the same angles as fixed Z-Y-X)."""
    return rot_x(a) @ rot_y(b) @ rot_z(c)


def _euler_zyz(a: float, b: float, c: float) -> Matrix:
    return rot_z(a) @ rot_y(b) @ rot_z(c)


def _radians(a: float, b: float, c: float) -> Matrix:
    return abc_to_matrix(math.degrees(a), math.degrees(b), math.degrees(c))


#: The other ways a controller may report A B C: (name in the report, rotation of a, b, c)
_ABC_READINGS = (
    ("rotating-axis X-Y'-Z'' (fixed Z-Y-X)", _euler_xyz),
    ("Z-Y-Z Euler angles", _euler_zyz),
    ("fixed-axis X-Y-Z in radians", _radians),
)


@dataclass(frozen=True)
class _Fit:
    distance_mm: float
    angle_deg: float

    @property
    def position_ok(self) -> bool:
        return self.distance_mm <= MODEL_TOLERANCE_MM

    @property
    def ok(self) -> bool:
        return self.position_ok and self.angle_deg <= MODEL_TOLERANCE_DEG


def _fit(flange: Matrix, xyz: Sequence[float], rotation: Matrix) -> _Fit:
    distance = float(np.linalg.norm(flange[:3, 3] - np.asarray(xyz, dtype=np.float64)))
    turn = flange[:3, :3].T @ rotation
    cosine = max(-1.0, min(1.0, (float(np.trace(turn)) - 1.0) / 2.0))
    return _Fit(distance, math.degrees(math.acos(cosine)))


def _finite(values: Sequence[float]) -> bool:
    return all(math.isfinite(v) and abs(v) < 1e9 for v in values)


def check_model(regs: Sequence[int], order: WordOrder, model: ArmModel | None) -> CheckLine:
    """The model's forward kinematics of the joints against the pose (see the module docstring)."""
    start = registers.gv_reg(registers.GV_JOINTS) - registers.POSE_BLOCK_START
    if model is None:
        return CheckLine(
            "model", CheckVerdict.UNCHECKED, "no-model", "no robot model to compute the pose with"
        )
    if not any(regs[start : start + 2 * registers.NUM_ROBOT_AXES]):
        return CheckLine(
            "model",
            CheckVerdict.UNCHECKED,
            "no-joints",
            "the controller publishes no joint angles in GV250..GV255 (a project extension): "
            "the pose cannot be computed from the joints",
        )
    joints = _gvs(regs, registers.GV_JOINTS, registers.NUM_ROBOT_AXES, order)
    pose = _gvs(regs, registers.GV_POSE, 6, order)
    name = model.profile.name
    agreement = compare_model(model, joints, pose) if _finite(joints + pose) else None
    if agreement is not None and agreement.agrees:
        args: dict[str, str | int | float] = {
            "model": name,
            "mm": round(agreement.distance_mm, 2),
            "deg": round(agreement.angle_deg, 2),
        }
        text = (
            f"the robot model '{name}' computes the pose from the joints within "
            f"{args['mm']} mm and {args['deg']}°"
        )
        return CheckLine("model", CheckVerdict.MATCH, "model-agrees", text, args)
    return _model_disagrees(regs, order, model, agreement is None)


def _model_disagrees(regs: Sequence[int], order: WordOrder, model: ArmModel, unreadable: bool) -> CheckLine:
    """Which other reading of the same registers the model agrees with: the likely fix."""
    name = model.profile.name
    other = other_order(order)
    joints_o, pose_o = _gvs(regs, registers.GV_JOINTS, 6, other), _gvs(regs, registers.GV_POSE, 6, other)
    if _finite(joints_o + pose_o):
        agreement = compare_model(model, joints_o, pose_o)
        if agreement is not None and agreement.agrees:
            fix, fix_code, setting = _setting_fix("word_order", other.value)
            text = (
                f"the robot model '{name}' does not compute the pose from the joints read {order.value}; "
                f"read {other.value} it does"
            )
            args: dict[str, str | int | float] = {"model": name, "order": order.value, "other": other.value}
            return CheckLine(
                "model", CheckVerdict.MISMATCH, "model-word-order", text, args, fix, fix_code, setting
            )
    joints, pose = _gvs(regs, registers.GV_JOINTS, 6, order), _gvs(regs, registers.GV_POSE, 6, order)
    if unreadable or not _finite(joints + pose):
        return CheckLine(
            "model",
            CheckVerdict.MISMATCH,
            "model-unreadable",
            "the joints or the pose are not finite numbers read either way",
            {"model": name},
            "check the unit id and that this controller has the vendor document's register map",
            "check-map",
        )
    return _model_other_units(model, joints, pose)


def _model_other_units(model: ArmModel, joints: Sequence[float], pose: Sequence[float]) -> CheckLine:
    """The model against the pose in other units and A B C conventions (not profile settings)."""
    name = model.profile.name
    flange = model.forward(joints)
    xyz, abc = pose[:3], pose[3:6]
    fixed = _fixed_xyz(*abc)
    readings: list[tuple[str, Matrix, Matrix, Sequence[float]]] = [
        ("the position in metres", flange, fixed, [v * 1000.0 for v in xyz]),
        ("the joints in radians", model.forward([math.degrees(v) for v in joints]), fixed, xyz),
    ]
    readings += [(f"A B C as {label}", flange, rotation(*abc), xyz) for label, rotation in _ABC_READINGS]
    for label, frame, rotation, position in readings:
        if _fit(frame, position, rotation).ok:
            text = (
                f"the robot model '{name}' computes the pose from the joints only when the controller "
                f"reports {label}; TeachPad reads mm, degrees and fixed-axis X-Y-Z A B C"
            )
            fix = (
                f"the controller reports {label}: not a register profile setting; set the controller "
                "to mm, degrees and fixed-axis X-Y-Z, or report it to the TeachPad team"
            )
            args: dict[str, str | int | float] = {"model": name, "reading": label}
            return CheckLine("model", CheckVerdict.MISMATCH, "model-units", text, args, fix, "units")
    found = _fit(flange, xyz, fixed)
    args = {"model": name, "mm": round(found.distance_mm, 1), "deg": round(found.angle_deg, 1)}
    text = (
        f"the robot model '{name}' puts the pose {args['mm']} mm and {args['deg']}° from the one the "
        "controller reports"
    )
    fix = "load the robot model of this arm (3D view, Robot model…), or check the joint registers"
    return CheckLine("model", CheckVerdict.MISMATCH, "model-disagrees", text, args, fix, "robot-model")


# --- table 2 ----------------------------------------------------------------------------------


def check_status(
    regs: Sequence[int], order: WordOrder, layout: DateTimeLayout, now: dt.datetime
) -> list[CheckLine]:
    """Mode, program state, alarms, clock and GV291 from registers 560..583."""
    base = registers.STATUS_BLOCK_START
    clock = registers.gv_reg(registers.GV_DATE) - base
    status = registers.gv_reg(registers.GV_COMMAND_STATUS) - base
    return [
        _in_table("mode", registers.REG_CONTROLLER_MODE, regs[registers.REG_CONTROLLER_MODE - base], _MODES),
        _in_table(
            "program state", registers.REG_PROGRAM_STATE, regs[registers.REG_PROGRAM_STATE - base], _STATES
        ),
        check_alarms(regs[registers.REG_ALARMS - base]),
        check_clock(regs[clock : clock + 4], layout, now),
        check_command_status(regs[status : status + 2], order),
    ]


_MODES: Final = {int(m): CONTROLLER_MODE_TEXT[m] for m in ControllerMode}
_STATES: Final = {int(s): PROGRAM_STATE_TEXT[s] for s in ProgramState}
_MOTION_MODES: Final = {int(m): PROGRAM_MOTION_MODE_TEXT[m] for m in ProgramMotionMode}


def _in_table(check: str, register: int, value: int, table: Mapping[int, str]) -> CheckLine:
    allowed = ", ".join(f"{k} {v}" for k, v in table.items())
    args: dict[str, str | int | float] = {"register": register, "value": value}
    if value in table:
        args["meaning"] = table[value]
        return CheckLine(
            check, CheckVerdict.MATCH, "in-table", f"register {register} = {value} ({table[value]})", args
        )
    args["allowed"] = allowed
    return CheckLine(
        check,
        CheckVerdict.MISMATCH,
        "out-of-table",
        f"register {register} = {value}, not one of its table's values ({allowed})",
        args,
        "check the unit id and that this controller has the vendor document's register map",
        "check-map",
    )


def check_alarms(value: int) -> CheckLine:
    """Register 562: only the five documented bits (an alarm that is on still matches the map)."""
    unknown = value & ~ALARM_MASK & 0xFFFF
    names = ", ".join(alarm_names(value & ALARM_MASK)) or "none"
    args: dict[str, str | int | float] = {"register": registers.REG_ALARMS, "value": value, "alarms": names}
    if not unknown:
        return CheckLine(
            "alarms", CheckVerdict.MATCH, "alarms-ok", f"register 562 = {value} (alarms: {names})", args
        )
    args["bits"] = f"0x{unknown:04X}"
    return CheckLine(
        "alarms",
        CheckVerdict.MISMATCH,
        "alarms-unknown",
        f"register 562 = {value}: bits {args['bits']} are none of the five documented alarms",
        args,
        "check the unit id and that this controller has the vendor document's register map",
        "check-map",
    )


def _clock_text(value: dt.datetime) -> str:
    return value.strftime("%Y-%m-%d %H:%M:%S")


def _apart(seconds: float) -> str:
    s = abs(seconds)
    if s >= 86400:
        return f"{s / 86400:.0f} days"
    if s >= 3600:
        return f"{s / 3600:.1f} h"
    return f"{s:.0f} s"


def check_clock(regs: Sequence[int], layout: DateTimeLayout, now: dt.datetime) -> CheckLine:
    """GV288/289 against the PC's clock, in the profile's layout (the other one as the fix)."""
    if not any(regs):
        return CheckLine("clock", CheckVerdict.UNCHECKED, "clock-zero", "the date/time registers are all 0")
    clock = decode_clock(regs, layout)
    args: dict[str, str | int | float] = {
        "layout": layout.value,
        "raw": clock.raw_hex,
        "pc": _clock_text(now),
    }
    if clock.value is not None:
        off = (clock.value - now).total_seconds()
        args.update(clock=_clock_text(clock.value), apart=_apart(off), seconds=round(off))
        if abs(off) <= CLOCK_TOLERANCE:
            text = f"the controller's clock reads {args['clock']}, the PC's {args['pc']}"
            return CheckLine("clock", CheckVerdict.MATCH, "clock-ok", text, args)
    other = next(x for x in DateTimeLayout if x is not layout)
    swapped = decode_clock(regs, other).value
    if swapped is not None and abs((swapped - now).total_seconds()) <= CLOCK_TOLERANCE:
        args.update(other=other.value, other_clock=_clock_text(swapped))
        fix, fix_code, setting = _setting_fix("datetime_layout", other.value)
        text = (
            f"the date/time words ({clock.raw_hex}) read {other.value} are the PC's time "
            f"{args['other_clock']}"
        )
        return CheckLine("clock", CheckVerdict.MISMATCH, "clock-layout", text, args, fix, fix_code, setting)
    if clock.value is None:
        text = f"the date/time words ({clock.raw_hex}) are no date read {layout.value} or {other.value}"
        return CheckLine(
            "clock", CheckVerdict.MISMATCH, "clock-invalid", text, args, "set the controller's clock", "clock"
        )
    ahead = "ahead of" if clock.value > now else "behind"
    args["direction"] = "ahead" if clock.value > now else "behind"
    text = f"the controller's clock reads {args['clock']}, {args['apart']} {ahead} the PC's ({args['pc']})"
    fix = "set the controller's clock (or the PC's): not a register profile setting"
    return CheckLine("clock", CheckVerdict.MISMATCH, "clock-off", text, args, fix, "clock")


_STATUS_CODES: Final = {**TEACH_STATUS_TEXT, **MOVE_STATUS_TEXT}


def _integral_code(words: Sequence[int], order: WordOrder) -> int | None:
    value = registers_to_float(words, order)
    if math.isfinite(value) and value.is_integer() and 0 <= value <= 255:
        return int(value)
    return None


def check_command_status(words: Sequence[int], order: WordOrder) -> CheckLine:
    """GV291: a float32 code read in the profile's order, or an integer in 582."""
    as_float = _integral_code(words, order)
    code = as_float if as_float is not None else int(words[0])
    args: dict[str, str | int | float] = {"value": code, "raw": f"{words[0]:04X} {words[1]:04X}"}
    if code in _STATUS_CODES and (as_float is not None or words[1] == 0):
        args["meaning"] = MOVE_STATUS_TEXT.get(code, _STATUS_CODES[code])
        text = f"GV291 = {code} ({args['meaning']})"
        return CheckLine("command status", CheckVerdict.MATCH, "status-ok", text, args)
    swapped = _integral_code(words, other_order(order))
    if swapped is not None and swapped in _STATUS_CODES:
        other = other_order(order).value
        args.update(other=other, other_value=swapped)
        fix, fix_code, setting = _setting_fix("word_order", other)
        text = (
            f"GV291's words ({args['raw']}) are no status code read {order.value}; "
            f"read {other} they are {swapped}"
        )
        return CheckLine(
            "command status", CheckVerdict.MISMATCH, "status-word-order", text, args, fix, fix_code, setting
        )
    text = f"GV291's words ({args['raw']}) are none of the documented status codes"
    fix = "check the unit id and that this controller has the vendor document's register map"
    return CheckLine("command status", CheckVerdict.MISMATCH, "status-unknown", text, args, fix, "check-map")


# --- the program registers (446..451) ---------------------------------------------------------


def check_program(regs: Sequence[int]) -> list[CheckLine]:
    """Program motion mode (447) within its table, speed ratio (449) within 0..100."""
    base = registers.REG_PROGRAM_ID
    lines = [
        _in_table(
            "program motion mode",
            registers.REG_PROGRAM_MODE,
            regs[registers.REG_PROGRAM_MODE - base],
            _MOTION_MODES,
        )
    ]
    ratio = regs[registers.REG_PROGRAM_SPEED - base]
    lo, hi = _SPEED_RATIO_RANGE
    args: dict[str, str | int | float] = {
        "register": registers.REG_PROGRAM_SPEED,
        "value": ratio,
        "low": lo,
        "high": hi,
    }
    if lo <= ratio <= hi:
        lines.append(
            CheckLine(
                "speed ratio",
                CheckVerdict.MATCH,
                "in-range",
                f"register 449 = {ratio} (within {lo}..{hi})",
                args,
            )
        )
    else:
        lines.append(
            CheckLine(
                "speed ratio",
                CheckVerdict.MISMATCH,
                "out-of-range",
                f"register 449 = {ratio}, outside {lo}..{hi}",
                args,
                "check the unit id and that this controller has the vendor document's register map",
                "check-map",
            )
        )
    return lines
