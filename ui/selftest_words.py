"""The register-map self-test's lines in the operator's language (:mod:`app.selftest.checks`):
each line's check, verdict, what was found and the likely fix, from its ``code`` and ``args``
(the English ``text`` / ``fix`` are teachpad-cli's and the logs')."""

from __future__ import annotations

from collections.abc import Mapping

from PySide6.QtCore import QCoreApplication

from app.protocol.codec import WordOrder
from app.protocol.datetime_regs import DateTimeLayout
from app.protocol.enums import ALARM_BITS, ALARM_TEXT
from app.selftest.checks import CheckLine, CheckVerdict, SelfTestReport
from ui.joins import join_names
from ui.messages_word_order import order_name, value_text

__all__ = ["check_name", "fix_text", "found_text", "summary_text", "verdict_text"]

_CONTEXT = "SelfTestWords"


def QT_TRANSLATE_NOOP(context: str, text: str) -> str:
    return text


def _tr(text: str) -> str:
    return QCoreApplication.translate(_CONTEXT, text)


_CHECKS = {
    "pose": QT_TRANSLATE_NOOP("SelfTestWords", "Pose X Y Z A B C (word order)"),
    "model": QT_TRANSLATE_NOOP("SelfTestWords", "Pose from the joints (robot model)"),
    "mode": QT_TRANSLATE_NOOP("SelfTestWords", "Controller mode (560)"),
    "program state": QT_TRANSLATE_NOOP("SelfTestWords", "Program state (561)"),
    "alarms": QT_TRANSLATE_NOOP("SelfTestWords", "Alarm bits (562)"),
    "clock": QT_TRANSLATE_NOOP("SelfTestWords", "Date and time (576–579)"),
    "command status": QT_TRANSLATE_NOOP("SelfTestWords", "Command status (GV291)"),
    "program motion mode": QT_TRANSLATE_NOOP("SelfTestWords", "Program motion mode (447)"),
    "speed ratio": QT_TRANSLATE_NOOP("SelfTestWords", "Program speed ratio (449)"),
    "status": QT_TRANSLATE_NOOP("SelfTestWords", "Status registers (560–583)"),
}
_VERDICTS = {
    CheckVerdict.MATCH: QT_TRANSLATE_NOOP("SelfTestWords", "matches"),
    CheckVerdict.MISMATCH: QT_TRANSLATE_NOOP("SelfTestWords", "does not match"),
    CheckVerdict.UNCHECKED: QT_TRANSLATE_NOOP("SelfTestWords", "not checked"),
}
_FOUND = {
    "refused": QT_TRANSLATE_NOOP(
        "SelfTestWords", "The controller refused the read of registers {what} (Modbus exception {exception})."
    ),
    "pose-zero": QT_TRANSLATE_NOOP("SelfTestWords", "X Y Z A B C are all 0: nothing to judge."),
    "pose-ok": QT_TRANSLATE_NOOP(
        "SelfTestWords", "Read {order}, the pose is one a robot can stand at: {pose}."
    ),
    "pose-swapped": QT_TRANSLATE_NOOP(
        "SelfTestWords", "Read {order}, the pose is {pose}; read {other}, it is {other_pose}."
    ),
    "pose-implausible": QT_TRANSLATE_NOOP(
        "SelfTestWords", "X Y Z A B C read either way are no pose a robot stands at: {pose}."
    ),
    "no-model": QT_TRANSLATE_NOOP("SelfTestWords", "No robot model to compute the pose with."),
    "no-joints": QT_TRANSLATE_NOOP(
        "SelfTestWords",
        "The controller publishes no joint angles in GV250–GV255 (a TeachPad extension): the pose "
        "cannot be computed from them.",
    ),
    "model-agrees": QT_TRANSLATE_NOOP(
        "SelfTestWords",
        "The robot model “{model}” computes the pose from the joints within {mm} mm and {deg}°.",
    ),
    "model-word-order": QT_TRANSLATE_NOOP(
        "SelfTestWords",
        "The robot model “{model}” does not compute the pose from the joints read {order}; "
        "read {other}, it does.",
    ),
    "model-unreadable": QT_TRANSLATE_NOOP(
        "SelfTestWords", "The joints or the pose are not finite numbers, read either way."
    ),
    "model-units": QT_TRANSLATE_NOOP(
        "SelfTestWords",
        "The robot model “{model}” computes the pose from the joints only if the controller reports "
        "{reading}; TeachPad reads mm, degrees and fixed-axis X-Y-Z angles.",
    ),
    "model-disagrees": QT_TRANSLATE_NOOP(
        "SelfTestWords",
        "The robot model “{model}” puts the pose {mm} mm and {deg}° from the one the controller reports.",
    ),
    "in-table": QT_TRANSLATE_NOOP("SelfTestWords", "Register {register} = {value} ({meaning})."),
    "out-of-table": QT_TRANSLATE_NOOP(
        "SelfTestWords", "Register {register} = {value}: not one of its table's values ({allowed})."
    ),
    "alarms-ok": QT_TRANSLATE_NOOP("SelfTestWords", "Register 562 = {value} (alarms on: {alarms})."),
    "alarms-unknown": QT_TRANSLATE_NOOP(
        "SelfTestWords", "Register 562 = {value}: bits {bits} are none of the five documented alarms."
    ),
    "clock-zero": QT_TRANSLATE_NOOP("SelfTestWords", "The date/time registers are all 0."),
    "clock-ok": QT_TRANSLATE_NOOP("SelfTestWords", "The controller's clock reads {clock}, this PC's {pc}."),
    "clock-layout": QT_TRANSLATE_NOOP(
        "SelfTestWords", "The date/time words ({raw}) read as {other} are this PC's time ({other_clock})."
    ),
    "clock-invalid": QT_TRANSLATE_NOOP(
        "SelfTestWords", "The date/time words ({raw}) are no date in either layout."
    ),
    "clock-ahead": QT_TRANSLATE_NOOP(
        "SelfTestWords", "The controller's clock reads {clock}: {apart} ahead of this PC's ({pc})."
    ),
    "clock-behind": QT_TRANSLATE_NOOP(
        "SelfTestWords", "The controller's clock reads {clock}: {apart} behind this PC's ({pc})."
    ),
    "status-ok": QT_TRANSLATE_NOOP("SelfTestWords", "GV291 = {value} ({meaning})."),
    "status-word-order": QT_TRANSLATE_NOOP(
        "SelfTestWords",
        "GV291's words ({raw}) are no status code read {order}; read {other}, they are {other_value}.",
    ),
    "status-unknown": QT_TRANSLATE_NOOP(
        "SelfTestWords", "GV291's words ({raw}) are none of the documented status codes."
    ),
    "in-range": QT_TRANSLATE_NOOP("SelfTestWords", "Register {register} = {value} (within {low}–{high})."),
    "out-of-range": QT_TRANSLATE_NOOP(
        "SelfTestWords", "Register {register} = {value}: outside {low}–{high}."
    ),
}
_FIXES = {
    "setting": QT_TRANSLATE_NOOP(
        "SelfTestWords",
        "Set the register profile's {field} to {value} (Safety → Register profile…), then connect again.",
    ),
    "check-map": QT_TRANSLATE_NOOP(
        "SelfTestWords", "Check the unit id, and that this controller has the vendor document's register map."
    ),
    "units": QT_TRANSLATE_NOOP(
        "SelfTestWords",
        "Not a register profile setting: set the controller to mm, degrees and fixed-axis X-Y-Z angles, "
        "or tell the TeachPad team.",
    ),
    "robot-model": QT_TRANSLATE_NOOP(
        "SelfTestWords",
        "Load the robot model of this arm (3D view → Robot model…), or check the joint registers.",
    ),
    "clock": QT_TRANSLATE_NOOP(
        "SelfTestWords", "Set the controller's clock (or this PC's): not a register profile setting."
    ),
}
_FIELDS = {
    "word_order": QT_TRANSLATE_NOOP("SelfTestWords", "word order"),
    "datetime_layout": QT_TRANSLATE_NOOP("SelfTestWords", "date/time layout"),
}
_LAYOUTS = {
    DateTimeLayout.SPLIT_WORDS.value: QT_TRANSLATE_NOOP("SelfTestWords", "split words (year, month·day)"),
    DateTimeLayout.PACKED32.value: QT_TRANSLATE_NOOP("SelfTestWords", "packed 32-bit values"),
}
_READINGS = {  # app.selftest.checks' names of the other readings of the same registers
    "the position in metres": QT_TRANSLATE_NOOP("SelfTestWords", "the position in metres"),
    "the joints in radians": QT_TRANSLATE_NOOP("SelfTestWords", "the joints in radians"),
    "A B C as rotating-axis X-Y'-Z'' (fixed Z-Y-X)": QT_TRANSLATE_NOOP(
        "SelfTestWords", "A B C as rotating-axis X-Y'-Z'' angles (fixed Z-Y-X)"
    ),
    "A B C as Z-Y-Z Euler angles": QT_TRANSLATE_NOOP("SelfTestWords", "A B C as Z-Y-Z Euler angles"),
    "A B C as fixed-axis X-Y-Z in radians": QT_TRANSLATE_NOOP("SelfTestWords", "A B C in radians"),
}
_DAYS = QT_TRANSLATE_NOOP("SelfTestWords", "{n} days")
_HOURS = QT_TRANSLATE_NOOP("SelfTestWords", "{n} h")
_SECONDS = QT_TRANSLATE_NOOP("SelfTestWords", "{n} s")
_NONE = QT_TRANSLATE_NOOP("SelfTestWords", "none")
_PASSED = QT_TRANSLATE_NOOP(
    "SelfTestWords",
    "The register map matches the register profile: {match} checks matched, {unchecked} not checked.",
)
_FAILED = QT_TRANSLATE_NOOP(
    "SelfTestWords",
    "The register map does not match the register profile: {mismatch} of {total} checks do not match.",
)


def check_name(line: CheckLine) -> str:
    name = _CHECKS.get(line.check)
    return _tr(name) if name is not None else line.check


def verdict_text(verdict: CheckVerdict) -> str:
    return _tr(_VERDICTS[verdict])


def _value_name(name: str, value: str) -> str:
    if name == "word_order":
        return order_name(WordOrder(value))
    if name == "datetime_layout" and value in _LAYOUTS:
        return _tr(_LAYOUTS[value])
    return value


def _protocol(text: object) -> str:
    return QCoreApplication.translate("Protocol", str(text))


def _apart(seconds: float) -> str:
    s = abs(seconds)
    if s >= 86400:
        return _tr(_DAYS).format(n=round(s / 86400))
    if s >= 3600:
        return _tr(_HOURS).format(n=f"{s / 3600:.1f}")
    return _tr(_SECONDS).format(n=round(s))


def _alarms(value: int) -> str:
    names = [_protocol(ALARM_TEXT[bit]) for bit in ALARM_BITS if value & bit]
    return join_names(names) or _tr(_NONE)


def _args(line: CheckLine) -> dict[str, object]:
    """The arguments in the operator's language (word orders, layouts, meanings, durations)."""
    args: dict[str, object] = dict(line.args)
    for key in ("order", "other"):
        value = args.get(key)
        if isinstance(value, str):
            args[key] = _value_name("word_order" if line.check != "clock" else "datetime_layout", value)
    for key, prefix in (("pose", "p"), ("other_pose", "o")):  # numbers without letters (1.2×10⁻⁴¹)
        if f"{prefix}0" in args:
            args[key] = " ".join(
                f"{name} = {value_text(float(str(args[f'{prefix}{i}'])))}" for i, name in enumerate("XYZABC")
            )
    if "meaning" in args:
        args["meaning"] = _protocol(args["meaning"])
    if "reading" in args:
        reading = str(args["reading"])
        args["reading"] = _tr(_READINGS[reading]) if reading in _READINGS else reading
    if "seconds" in args:
        args["apart"] = _apart(float(str(args["seconds"])))
    if line.code == "alarms-ok":
        args["alarms"] = _alarms(int(str(args["value"])))
    return args


def _code(line: CheckLine) -> str:
    if line.code == "clock-off":
        return "clock-ahead" if line.args.get("direction") == "ahead" else "clock-behind"
    return line.code


def found_text(line: CheckLine) -> str:
    """What the check found, in the operator's language (the English when the code is new)."""
    template = _FOUND.get(_code(line))
    if template is None:
        return line.text
    try:
        return _tr(template).format(**_args(line))
    except (KeyError, IndexError, ValueError):  # a translation with a broken placeholder
        return line.text


def fix_text(line: CheckLine) -> str:
    """The likely fix in the operator's language ("" when the line needs none)."""
    if not line.fix_code:
        return ""
    template = _FIXES.get(line.fix_code)
    if template is None:
        return line.fix
    field, value = line.setting if line.setting is not None else ("", "")
    args: Mapping[str, str] = {"field": _tr(_FIELDS.get(field, field)), "value": _value_name(field, value)}
    try:
        return _tr(template).format(**args)
    except (KeyError, IndexError, ValueError):
        return line.fix


def summary_text(report: SelfTestReport) -> str:
    counts = {v: sum(1 for line in report.lines if line.verdict is v) for v in CheckVerdict}
    if report.passed:
        return _tr(_PASSED).format(match=counts[CheckVerdict.MATCH], unchecked=counts[CheckVerdict.UNCHECKED])
    return _tr(_FAILED).format(mismatch=counts[CheckVerdict.MISMATCH], total=len(report.lines))
