"""The plan's checks and the safety envelope in the operator's language.

:func:`issue_text` words a :class:`~app.plan.checks.PlanIssue` (its code and arguments);
:func:`envelope_text` a refusal of the safety envelope (app/safety/envelope.py).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

from PySide6.QtCore import QCoreApplication

from app.plan.issue_kind import IssueKind
from app.points.point import SYNC_STATE_TEXT, SyncState
from app.protocol.registers import TOOL_NONE
from ui.joins import labelled

if TYPE_CHECKING:  # the checks are imported by the first plan checked, after the first paint
    from app.plan.checks import PlanIssue

CONTEXT = "Messages"


def QT_TRANSLATE_NOOP(context: str, text: str) -> str:
    return text


_INVALID_INPUT = QT_TRANSLATE_NOOP("Messages", "Invalid value: nothing was sent.")

# the safety envelope (app/safety/envelope.py ViolationCode values)
_ENVELOPE: dict[str, str] = {
    "keep_in": QT_TRANSLATE_NOOP(
        "Messages", "{where}{axis} = {value} {unit} is outside the allowed work space (limit {limit} {unit})."
    ),
    "keep_out": QT_TRANSLATE_NOOP(
        "Messages",
        "{where}the path enters the keep-out zone \u201c{box}\u201d ({axis} = {value} {unit}, its face is at {limit} {unit}).",
    ),
    "joint_limit": QT_TRANSLATE_NOOP("Messages", "{where}{axis} = {value}° is past its limit {limit}°."),
    "speed": QT_TRANSLATE_NOOP("Messages", "{where}speed {value} mm/s is above the {limit} mm/s allowed."),
    "jog_ratio": QT_TRANSLATE_NOOP("Messages", "{where}jog speed {value}% is above the {limit}% allowed."),
    "approaching": QT_TRANSLATE_NOOP(
        "Messages", "{where}{axis} = {value} {unit} is within stopping distance of its limit {limit} {unit}."
    ),
}
_ENVELOPE_PREFIX = QT_TRANSLATE_NOOP("Messages", "Refused by the safety envelope: {text}")
_SEGMENT = QT_TRANSLATE_NOOP("Messages", "segment {n}: ")
_REDUCED = QT_TRANSLATE_NOOP("Messages", " (reduced-speed mode)")


def _tr(text: str, context: str = CONTEXT) -> str:
    return QCoreApplication.translate(context, text)


def _number(value: Any) -> str:
    if isinstance(value, float):
        return f"{value:.1f}" if abs(value) >= 10 else f"{value:g}"
    return str(value)


def envelope_text(args: Mapping[str, Any], prefix: bool = True) -> str:
    code = "approaching" if args.get("approaching") else str(args.get("violation", ""))
    template = _ENVELOPE.get(code)
    if template is None:
        return _tr(_INVALID_INPUT)
    unit = "°" if args.get("violation") == "joint_limit" else "mm"
    segment = args.get("segment")
    text = _tr(template).format(
        where="" if segment is None else _tr(_SEGMENT).format(n=int(segment) + 1),
        axis=args.get("axis", ""),
        box=args.get("box", ""),
        unit=unit,
        value=_number(float(args.get("value", 0.0))),
        limit=_number(float(args.get("limit", 0.0))),
    )
    if args.get("reduced"):
        end = text[-1] if text[-1:] in ("。", ".") else ""
        text = text[: len(text) - len(end)] + _tr(_REDUCED) + end
    return _tr(_ENVELOPE_PREFIX).format(text=text) if prefix else text


# --- the plan's checks (app/plan/checks.py: IssueCode values and their args) -------------------
_ISSUES: dict[str, str] = {
    "empty-plan": QT_TRANSLATE_NOOP("Messages", "Plan \u201c{plan}\u201d has no segments."),
    "bad-start": QT_TRANSLATE_NOOP(
        "Messages", "Cannot start at segment {start}: the plan has {segments} segments."
    ),
    "bad-speed": QT_TRANSLATE_NOOP("Messages", "speed {speed} mm/s is not in (0, {max}] mm/s."),
    "arc-no-middle": QT_TRANSLATE_NOOP("Messages", "the arc has no middle point."),
    "missing-point/middle": QT_TRANSLATE_NOOP("Messages", "middle point P{id} does not exist."),
    "missing-point/end": QT_TRANSLATE_NOOP("Messages", "end point P{id} does not exist."),
    "needs-upload": QT_TRANSLATE_NOOP("Messages", "{point} is not on the controller ({sync}); upload it."),
    "tool-mismatch": QT_TRANSLATE_NOOP(
        "Messages", "{point} was taught with {point_tool}, the segment moves with {segment_tool}."
    ),
    "zero-length": QT_TRANSLATE_NOOP(
        "Messages", "the line goes nowhere (start and end {length} mm apart){where}."
    ),
    "arc-start-unknown": QT_TRANSLATE_NOOP(
        "Messages",
        "the arc starts at the robot's current pose, which is not known: its shape is not checked.",
    ),
    "arc-points-coincide/start-middle": QT_TRANSLATE_NOOP(
        "Messages",
        "the arc's start and middle points coincide (closer than {tolerance} mm): three distinct points are needed{where}.",
    ),
    "arc-points-coincide/middle-end": QT_TRANSLATE_NOOP(
        "Messages",
        "the arc's middle and end points coincide (closer than {tolerance} mm): three distinct points are needed{where}.",
    ),
    "arc-points-coincide/start-end": QT_TRANSLATE_NOOP(
        "Messages",
        "the arc's start and end points coincide (closer than {tolerance} mm): three distinct points are needed{where}.",
    ),
    "arc-collinear": QT_TRANSLATE_NOOP(
        "Messages",
        "the arc's three points are (nearly) on one line: the middle point is {offset} mm off the start-end line (at least {tolerance} mm needed); use a line instead{where}.",
    ),
    "arc-resume-past-middle/past": QT_TRANSLATE_NOOP(
        "Messages",
        "the arm stopped past the arc's middle point: sent from here the arc would swing {sweep}° round through the middle point (planned {planned}°); move to the end point with a line, or run from the segment before.",
    ),
    "arc-resume-past-middle/larger": QT_TRANSLATE_NOOP(
        "Messages",
        "sent from here the arc would swing {sweep}° round through the middle point (planned {planned}°); check the preview before running from here.",
    ),
    "unreachable/point": QT_TRANSLATE_NOOP("Messages", "{point} is out of the robot model's reach."),
    "unreachable/path": QT_TRANSLATE_NOOP("Messages", "the path is out of the robot model's reach."),
    "joint-limit/point": QT_TRANSLATE_NOOP("Messages", "{point} passes a joint limit of the robot model."),
    "joint-limit/path": QT_TRANSLATE_NOOP("Messages", "the path passes a joint limit of the robot model."),
    "model-disagrees/position": QT_TRANSLATE_NOOP(
        "Messages",
        "The robot model \u201c{model}\u201d disagrees with the controller's pose by {distance} mm: reach checks may be wrong.",
    ),
    "model-disagrees/orientation": QT_TRANSLATE_NOOP(
        "Messages",
        "The robot model \u201c{model}\u201d disagrees with the controller's pose by {angle}°: reach checks may be wrong.",
    ),
    "model-disagrees/both": QT_TRANSLATE_NOOP(
        "Messages",
        "The robot model \u201c{model}\u201d disagrees with the controller's pose by {distance} mm and {angle}°: reach checks may be wrong.",
    ),
    "speed-capped": QT_TRANSLATE_NOOP(
        "Messages", "runs at {cap} mm/s, the reduced-speed cap (planned {speed} mm/s)."
    ),
}
_FROM_CURRENT_POSE = QT_TRANSLATE_NOOP("Messages", " (from the current pose)")
_FROM_LATER_LOOPS = QT_TRANSLATE_NOOP(
    "Messages", " (on loops after the first, starting at the end of segment {after})"
)
_ISSUE_KINDS = {
    IssueKind.ERROR: "error",
    IssueKind.NEEDS_UPLOAD: "needs upload",
    IssueKind.WARNING: "warning",
}  # the "SegmentTableModel" translations


def _tool(tool: Any) -> str:
    """A tool frame as the points table shows it (translations of "PointsModel")."""
    if int(tool) == TOOL_NONE:
        return QCoreApplication.translate("PointsModel", "none")
    return QCoreApplication.translate("PointsModel", "tool {n}").format(n=int(tool))  # as in the CSV


def _issue_key(issue: PlanIssue) -> str:
    code, args = issue.code.value, issue.args
    if code == "missing-point":
        return f"{code}/{args.get('role')}"
    if code == "arc-points-coincide":
        return f"{code}/{args.get('pair')}"
    if code == "arc-resume-past-middle":
        return f"{code}/{'past' if args.get('past_middle') else 'larger'}"
    if code in ("unreachable", "joint-limit"):
        return f"{code}/{'point' if args.get('point') else 'path'}"
    if code == "model-disagrees":
        position, orientation = bool(args.get("position_off")), bool(args.get("orientation_off"))
        return f"{code}/{'both' if position and orientation else 'position' if position else 'orientation'}"
    return code


def issue_text(issue: PlanIssue) -> str:
    """One check of a plan as a sentence in the operator's language ("segment 2: ..."); the
    issue's English message when it carries no arguments this module knows."""
    args = issue.args
    if issue.code.value == "outside-envelope" and args:
        return envelope_text(args, prefix=False)
    template = _ISSUES.get(_issue_key(issue))
    if template is None:
        return issue.message
    fields: dict[str, str] = {
        k: _number(v) if isinstance(v, int | float) and not isinstance(v, bool) else str(v)
        for k, v in args.items()
    }
    source = args.get("from")
    fields["where"] = (
        _tr(_FROM_CURRENT_POSE)
        if source == "current_pose"
        else _tr(_FROM_LATER_LOOPS).format(after=args.get("after", "?"))
        if source == "later_loops"
        else ""
    )
    if "sync" in args:
        try:
            fields["sync"] = _tr(SYNC_STATE_TEXT[SyncState(args["sync"])], "Points")
        except (ValueError, KeyError):
            fields["sync"] = str(args["sync"])
    for key in ("point_tool", "segment_tool"):
        if key in args:
            fields[key] = _tool(args[key])
    try:
        text = _tr(template).format(**fields)
    except (KeyError, ValueError):
        return issue.message
    if issue.segment is None:
        return text
    return _tr(_SEGMENT).format(n=issue.segment + 1) + text


def issue_line(issue: PlanIssue) -> str:
    """An issue with its kind ("error: segment 2: ..."), for lists and tooltips."""
    kind = QCoreApplication.translate("SegmentTableModel", _ISSUE_KINDS[issue.kind])
    return labelled(kind, issue_text(issue))
