"""Results and errors in the operator's language.

The core reports why a command ended or what went wrong as a :class:`~app.errors.Reason` (a
stable code and its arguments) beside a plain English message (logs, CLI). Here a reason
becomes one translated sentence: :func:`result_text` for a :class:`CommandResult`,
:func:`error_text` for a :class:`WorkerError` or a typed error. Command, status and alarm names
reuse the "Protocol" translations. Something without a reason (an older producer) falls back to
its English message.

The plan's checks and the safety envelope are worded in :mod:`ui.messages_plan`, refused values
and files in :mod:`ui.messages_files` (:func:`refusal_text` here words them).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from app.errors import Reason, TeachPadError
from app.link.types import ConnectionState, WorkerError
from app.models import CommandResult
from app.points.fields import FieldError
from app.points.point import FileFormatError
from app.protocol.enums import (
    RUN_COMMAND_TEXT,
    UNKNOWN_STATUS_TEXT,
    CommandKind,
    CommandStatus,
    RunCommand,
    alarm_names,
    controller_mode_text,
)
from app.protocol.exceptions import GATEWAY_EXCEPTIONS
from ui.joins import join_names
from ui.messages_files import FILE_TEMPLATES, file_fields, file_text, os_problem
from ui.messages_plan import _number, _tr, envelope_text
from ui.messages_profile import is_profile_code, profile_text
from ui.messages_watch import WATCH_TEMPLATES

__all__ = [
    "LEVEL_ERROR",
    "LEVEL_INFO",
    "LEVEL_WARNING",
    "connection_text",
    "error_text",
    "operation_text",
    "os_error_text",
    "reason_text",
    "refusal_text",
    "result_level",
    "result_text",
    "status_text",
]

CONTEXT = "Messages"
LEVEL_INFO = "info"
LEVEL_WARNING = "warning"
LEVEL_ERROR = "error"


def QT_TRANSLATE_NOOP(context: str, text: str) -> str:
    return text


# code -> sentence; placeholders are filled with already translated / formatted values.
_TEMPLATES: dict[str, str] = {
    # how a command ended
    "done": QT_TRANSLATE_NOOP("Messages", "{command}: {status}."),
    "done_unconfirmed": QT_TRANSLATE_NOOP("Messages", "{command}: done, not confirmed by the controller."),
    "done_by_mode": QT_TRANSLATE_NOOP("Messages", "{command}: done (the controller is now in {mode} mode)."),
    "command_refused": QT_TRANSLATE_NOOP("Messages", "{command} refused by the controller: {status}."),
    "refused_unconfirmed": QT_TRANSLATE_NOOP(
        "Messages",
        "{command} not taken: the controller still shows \u201c{status}\u201d from the previous command.",
    ),
    "alarm_while_waiting": QT_TRANSLATE_NOOP("Messages", "{command} ended by an alarm: {alarms}."),
    "not_acknowledged": QT_TRANSLATE_NOOP(
        "Messages", "{command}: the controller did not acknowledge it within {seconds} s."
    ),
    "command_timeout": QT_TRANSLATE_NOOP(
        "Messages", "{command} did not finish within {seconds} s (last status: {status})."
    ),
    "result_unknown": QT_TRANSLATE_NOOP(
        "Messages", "{command}: the arm moved and stopped, but the controller did not report the result."
    ),
    "stopped_by_operator": QT_TRANSLATE_NOOP("Messages", "{command}: stopped by the operator."),
    "stopped_by_controller": QT_TRANSLATE_NOOP("Messages", "{command}: stopped by the controller."),
    "sent": QT_TRANSLATE_NOOP("Messages", "{command}: sent (not waited for)."),
    "no_motion": QT_TRANSLATE_NOOP(
        "Messages", "{command}: no motion within {seconds} s (refused by the controller, or already there)."
    ),
    # the controller's outcome (app/link/outcome.py): refused, unknown, and the motion-told commands
    "refused_alarm": QT_TRANSLATE_NOOP("Messages", "{command} refused by the controller: {alarms}."),
    "outcome_unknown": QT_TRANSLATE_NOOP(
        "Messages", "{command}: sent; the outcome is unknown — check the robot before sending it again."
    ),
    "zero_already": QT_TRANSLATE_NOOP("Messages", "{command}: done (the axes were already at zero)."),
    "zero_stopped_short": QT_TRANSLATE_NOOP(
        "Messages", "{command}: the arm stopped before zero ({axis} at {value})."
    ),
    "foreign_master": QT_TRANSLATE_NOOP(
        "Messages",
        "{command} not sent: another Modbus master wrote to the controller less than {seconds} s ago and "
        "its writes could change this move. Make sure no other master is commanding the robot, then send it again.",
    ),
    "controller_busy": QT_TRANSLATE_NOOP(
        "Messages",
        "{command} not sent: a program or motion is under way on the controller; wait for it to end, or press Stop.",
    ),
    "state_not_reached": QT_TRANSLATE_NOOP(
        "Messages", "{command}: the controller did not show it within {seconds} s."
    ),
    "program_not_started": QT_TRANSLATE_NOOP(
        "Messages", "Program {program} did not start: no such program, or the controller refused it."
    ),
    "upload_done": QT_TRANSLATE_NOOP("Messages", "Uploaded {uploaded} of {total} points."),
    # requests the worker handles without a GV291 status (stop, pause, mode...)
    "request_done": QT_TRANSLATE_NOOP("Messages", "{operation}: sent."),
    "request_failed": QT_TRANSLATE_NOOP("Messages", "{operation}: failed."),
    "busy": QT_TRANSLATE_NOOP("Messages", "{operation} is still under way: wait for it or press Stop."),
    "busy_upload": QT_TRANSLATE_NOOP(
        "Messages", "{operation} is still under way: wait for it, cancel it or press Stop."
    ),
    "link_shut_down": QT_TRANSLATE_NOOP("Messages", "The link is shut down: nothing was sent."),
    "not_connected": QT_TRANSLATE_NOOP("Messages", "Not connected to a controller: nothing was sent."),
    # the jog (app/link/jog.py)
    "jog_stopped_silent": QT_TRANSLATE_NOOP(
        "Messages", "Jog stopped: the controller is not answering (speed 0 is sent as soon as it answers)."
    ),
    "left_teach_mode": QT_TRANSLATE_NOOP(
        "Messages", "Jog stopped: the controller left teach mode (now in {mode} mode)."
    ),
    "jog_not_answering": QT_TRANSLATE_NOOP(
        "Messages", "The controller is not answering: the jog was not started."
    ),
    # a write that stops motion, until the controller confirms it (app/link/halt.py)
    "release_unconfirmed": QT_TRANSLATE_NOOP(
        "Messages",
        "Releasing — the controller has not confirmed: it refused or did not answer speed 0. "
        "Speed 0 is sent again at every poll until the controller answers and the arm stands still.",
    ),
    "release_escalated": QT_TRANSLATE_NOOP(
        "Messages",
        "Releasing — the controller has not confirmed speed 0 after {seconds} s: Stop is sent as well, "
        "at every poll, until the controller takes it.",
    ),
    "release_confirmed": QT_TRANSLATE_NOOP(
        "Messages", "Jog stopped: the controller confirmed after {seconds} s and the arm stands still."
    ),
    "stop_unconfirmed": QT_TRANSLATE_NOOP(
        "Messages",
        "Stopping — the controller has not confirmed: it refused or did not answer the Stop. "
        "Stop is sent again at every poll until the controller takes it and the arm stands still.",
    ),
    "stop_confirmed": QT_TRANSLATE_NOOP(
        "Messages", "Stop confirmed by the controller after {seconds} s; the arm stands still."
    ),
    "pause_unconfirmed": QT_TRANSLATE_NOOP(
        "Messages",
        "Pausing — the controller has not confirmed: it refused or did not answer the Pause; the arm "
        "may still be moving. Pause is sent again at every poll. Press STOP if it must stop now.",
    ),
    "pause_escalated": QT_TRANSLATE_NOOP(
        "Messages",
        "Pause not confirmed by the controller after {seconds} s: Stop is sent instead, at every poll, "
        "until the controller takes it.",
    ),
    "pause_confirmed": QT_TRANSLATE_NOOP(
        "Messages", "Pause confirmed by the controller after {seconds} s: the arm is paused."
    ),
    "pause_stopped": QT_TRANSLATE_NOOP(
        "Messages",
        "Pause not confirmed by the controller within {seconds} s: the arm was stopped (Stop) instead.",
    ),
    "pause_nothing_running": QT_TRANSLATE_NOOP(
        "Messages", "Pause: nothing left to pause (the motion ended before the controller took the Pause)."
    ),
    "pause_dropped": QT_TRANSLATE_NOOP(
        "Messages",
        "Pause not confirmed by the controller: it was not sent again (Resume, Stop, another motion or "
        "a new connection came first).",
    ),
    "halt_unconfirmed": QT_TRANSLATE_NOOP(
        "Messages",
        "{operation} refused: the controller has not confirmed that the arm stopped (the stop is "
        "sent again at every poll). Press Stop, or wait until the arm stands still.",
    ),
    "run_not_answering_start": QT_TRANSLATE_NOOP(
        "Messages", "The controller is not answering: the plan was not started. Try again when it answers."
    ),
    "bad_jog_ratio": QT_TRANSLATE_NOOP("Messages", "Jog speed {value}% is not within 1..100%."),
    # the link
    "link_lost": QT_TRANSLATE_NOOP("Messages", "Lost the connection to the controller at {endpoint}."),
    "link_closed": QT_TRANSLATE_NOOP("Messages", "The controller at {endpoint} closed the connection."),
    "host_unresolved": QT_TRANSLATE_NOOP("Messages", "The host name {host} cannot be resolved."),
    "host_invalid": QT_TRANSLATE_NOOP("Messages", "The host name {host} is not valid: check it in Connect…"),
    "connection_refused": QT_TRANSLATE_NOOP(
        "Messages", "Connection refused: nothing listens on port {port}."
    ),
    "connect_timeout": QT_TRANSLATE_NOOP(
        "Messages", "No answer to the connection request within {seconds} s."
    ),
    "connect_failed": QT_TRANSLATE_NOOP("Messages", "The connection could not be opened."),
    "serial_open_failed": QT_TRANSLATE_NOOP("Messages", "Cannot open the serial port {port}."),
    "no_answer": QT_TRANSLATE_NOOP(
        "Messages", "The controller at {endpoint} did not answer within {seconds} s."
    ),
    "malformed_answer": QT_TRANSLATE_NOOP(
        "Messages",
        "Malformed answer from the controller at {endpoint}: {field} expected {expected}, got {got}.",
    ),
    "modbus_exception": QT_TRANSLATE_NOOP(
        "Messages", "The controller refused the request: Modbus exception {exception} ({name})."
    ),
    # a request the controller refused with a Modbus exception, named (app/link/worker.py): which
    # one, what it means for the arm and what to do
    "pause_refused": QT_TRANSLATE_NOOP(
        "Messages",
        "Pause refused by the controller (Modbus exception {exception}, {name}): the arm was not paused. "
        "Press STOP if it must stop now, or press Pause again.",
    ),
    "resume_refused": QT_TRANSLATE_NOOP(
        "Messages",
        "Resume refused by the controller (Modbus exception {exception}, {name}): the arm stays paused. "
        "Press Resume again in a moment.",
    ),
    "mode_refused": QT_TRANSLATE_NOOP(
        "Messages",
        "Switch to {mode} mode refused by the controller (Modbus exception {exception}, {name}): the "
        "work mode did not change. Switch it again in a moment.",
    ),
    "request_refused": QT_TRANSLATE_NOOP(
        "Messages", "{command} refused by the controller: Modbus exception {exception} ({name})."
    ),
    # a gateway's 10 / 11 (app/protocol/exceptions.py GATEWAY_EXCEPTIONS): nothing at the unit id
    "modbus_gateway": QT_TRANSLATE_NOOP(
        "Messages",
        "No device answered at unit id {unit} (Modbus exception {exception}, {name}): check the unit id in Connect…",
    ),
    "monitor_only": QT_TRANSLATE_NOOP("Messages", "Monitor-only mode: nothing was sent to the controller."),
    "audit_unavailable": QT_TRANSLATE_NOOP(
        "Messages",
        "Not sent: the audit trail in {folder} cannot be written ({cause}). No write goes out without "
        "its record (Stop still does): free disk space or fix the audit folder.",
    ),
    "manual_mode": QT_TRANSLATE_NOOP(
        "Messages",
        "{operation}: not sent, the controller is in {mode} mode. Switching it to auto is the operator's "
        "decision: say yes when the confirmation asks, or switch it to auto first.",
    ),
    "reduced_speed_refused": QT_TRANSLATE_NOOP(
        "Messages",
        "{operation}: not sent in reduced-speed mode: it runs at the controller's own speed, which "
        "TeachPad cannot cap.",
    ),
    "invalid_input": QT_TRANSLATE_NOOP("Messages", "Invalid value: nothing was sent."),
    "unexpected": QT_TRANSLATE_NOOP("Messages", "Unexpected internal error; the log has the details."),
    # a plan run's point guard (app/points/guard.py, ui/controllers/run_points.py)
    "point_mismatch": QT_TRANSLATE_NOOP(
        "Messages",
        "The arm stopped at ({got}), {distance} mm from {point} ({want}): the controller's copy of the point is not this project's (overwritten by another tool?). Check the point and the robot before resuming.",
    ),
    "point_not_created": QT_TRANSLATE_NOOP(
        "Messages", "The controller did not create {point} again before the move: the arm was not moved."
    ),
    "point_missing": QT_TRANSLATE_NOOP(
        "Messages", "The project has no point {point}: the arm was not moved."
    ),
    "arrival_unknown": QT_TRANSLATE_NOOP(
        "Messages", "The arm's position after the move to {point} is not known: the run is stopped."
    ),
    # the link's own state and the commands it cut short (app/link/supervisor.py)
    "link_was_shut_down": QT_TRANSLATE_NOOP("Messages", "The link was shut down."),
    "outcome_unknown_link_lost": QT_TRANSLATE_NOOP(
        "Messages",
        "{operation}: the connection was lost while it was under way; the outcome is unknown — check the robot before sending it again.",
    ),
    "outcome_unknown_link_closed": QT_TRANSLATE_NOOP(
        "Messages",
        "{operation}: the connection was closed while it was under way; the outcome is unknown — check the robot before sending it again.",
    ),
    # queued requests the link never sent (app/link/worker.py fail_queued)
    "queued_link_down": QT_TRANSLATE_NOOP(
        "Messages", "{operation}: not sent, the connection to the controller is down."
    ),
    "queued_link_closed": QT_TRANSLATE_NOOP("Messages", "{operation}: not sent, the connection was closed."),
    # the point ledger's refusals (app/points/ledger.py): parts of a sentence ("P3, ID: refused, ...")
    "points_outside_range": QT_TRANSLATE_NOOP("Messages", "points outside {id_min}..{id_max}: {ids}"),
    "no_such_point": QT_TRANSLATE_NOOP("Messages", "there is no point P{id}"),
    "no_free_point_id": QT_TRANSLATE_NOOP("Messages", "no free point id left in {start}..{id_max}"),
    "no_such_row": QT_TRANSLATE_NOOP("Messages", "there is no row {row}"),
    "cannot_move_row": QT_TRANSLATE_NOOP("Messages", "cannot move row {src} to {dst} in {rows} rows"),
    "duplicate_row_id": QT_TRANSLATE_NOOP("Messages", "row {row}: id {id} is already used on row {other}"),
    "import_duplicate_id": QT_TRANSLATE_NOOP("Messages", "imported point {number}: id {id} appears twice"),
    "point_id_taken": QT_TRANSLATE_NOOP("Messages", "id {id} is already used by {point}"),
    "empty_import": QT_TRANSLATE_NOOP(
        "Messages",
        "the file has no points: replacing with it would remove all {existing} points of the project (merge it, or ask explicitly for an empty import)",
    ),
}

_TEMPLATES.update(FILE_TEMPLATES)  # refused values and files (ui/messages_files.py)
_TEMPLATES.update(WATCH_TEMPLATES)  # the watch list (ui/messages_watch.py)

# A reason whose arguments lack a placeholder of the full sentence uses this one.
_BARE: dict[str, str] = {
    "link_lost": QT_TRANSLATE_NOOP("Messages", "No connection to the controller."),
    "link_closed": QT_TRANSLATE_NOOP("Messages", "The controller closed the connection."),
    "connection_refused": QT_TRANSLATE_NOOP("Messages", "Connection refused by the controller."),
    "no_answer": QT_TRANSLATE_NOOP("Messages", "The controller did not answer."),
    "malformed_answer": QT_TRANSLATE_NOOP("Messages", "Malformed answer from the controller."),
    "serial_open_failed": QT_TRANSLATE_NOOP("Messages", "Cannot open the serial port."),
    "host_unresolved": QT_TRANSLATE_NOOP("Messages", "The host name cannot be resolved."),
    "host_invalid": QT_TRANSLATE_NOOP("Messages", "The host name is not valid."),
    "connect_timeout": QT_TRANSLATE_NOOP("Messages", "No answer to the connection request."),
    "command_timeout": QT_TRANSLATE_NOOP("Messages", "{command} did not finish in time."),
    "not_acknowledged": QT_TRANSLATE_NOOP("Messages", "{command}: the controller did not acknowledge it."),
    "alarm_while_waiting": QT_TRANSLATE_NOOP("Messages", "{command} ended by an alarm."),
    "command_refused": QT_TRANSLATE_NOOP("Messages", "{command} refused by the controller."),
    "done": QT_TRANSLATE_NOOP("Messages", "{command}: done."),
    "modbus_exception": QT_TRANSLATE_NOOP(
        "Messages", "The controller refused the request (Modbus exception)."
    ),
    "manual_mode": QT_TRANSLATE_NOOP(
        "Messages", "{operation}: not sent, the controller is not in auto mode."
    ),
    "pause_refused": QT_TRANSLATE_NOOP(
        "Messages",
        "Pause refused by the controller: the arm was not paused. Press STOP if it must stop now, "
        "or press Pause again.",
    ),
    "resume_refused": QT_TRANSLATE_NOOP(
        "Messages", "Resume refused by the controller: the arm stays paused. Press Resume again in a moment."
    ),
    "mode_refused": QT_TRANSLATE_NOOP(
        "Messages",
        "Work mode change refused by the controller: the work mode did not change. Switch it again in a moment.",
    ),
    "request_refused": QT_TRANSLATE_NOOP("Messages", "{command} refused by the controller."),
}

# The requests whose refusal (a Modbus exception) has a sentence of its own; any other named
# request reads "request_refused".
_REFUSED_REQUESTS = {"pause": "pause_refused", "resume": "resume_refused", "set mode": "mode_refused"}

_RECONNECT = QT_TRANSLATE_NOOP("Messages", "Cannot reconnect to the controller at {endpoint}: {cause}")
_CONNECT = QT_TRANSLATE_NOOP("Messages", "Cannot connect to the controller at {endpoint}: {cause}")
_A_COMMAND = QT_TRANSLATE_NOOP("Messages", "The command")
_FAILED = QT_TRANSLATE_NOOP("Messages", "Failed.")
_FAILED_WITH = QT_TRANSLATE_NOOP("Messages", "Failed: {message}")

_OPERATIONS: dict[str, str] = {  # app.link.types.Operation values
    "stop": QT_TRANSLATE_NOOP("Messages", "stop"),
    "pause": QT_TRANSLATE_NOOP("Messages", "pause"),
    "resume": QT_TRANSLATE_NOOP("Messages", "resume"),
    "jog": QT_TRANSLATE_NOOP("Messages", "jog"),
    "jog release": QT_TRANSLATE_NOOP("Messages", "jog release"),
    "jog speed": QT_TRANSLATE_NOOP("Messages", "jog speed"),
    "step": QT_TRANSLATE_NOOP("Messages", "incremental move"),
    "set mode": QT_TRANSLATE_NOOP("Messages", "work mode"),
    "go to zero": QT_TRANSLATE_NOOP("Messages", "go to zero"),
    "run program": QT_TRANSLATE_NOOP("Messages", "run program"),
    "create point": QT_TRANSLATE_NOOP("Messages", "create temp point"),
    "move to point": QT_TRANSLATE_NOOP("Messages", "move to temp point"),
    "upload points": QT_TRANSLATE_NOOP("Messages", "upload temp points"),
    "cancel upload": QT_TRANSLATE_NOOP("Messages", "cancel upload"),
    "teach disable": QT_TRANSLATE_NOOP("Messages", "teach disable"),
    "poll": QT_TRANSLATE_NOOP("Messages", "monitor"),
    "connect": QT_TRANSLATE_NOOP("Messages", "connect"),
    "disconnect": QT_TRANSLATE_NOOP("Messages", "disconnect"),
    "shutdown": QT_TRANSLATE_NOOP("Messages", "shutdown"),
    "restart check": QT_TRANSLATE_NOOP("Messages", "restart check"),
    "read registers": QT_TRANSLATE_NOOP("Messages", "read registers"),
}
_AN_OPERATION = QT_TRANSLATE_NOOP("Messages", "request")

_FIELDS: dict[str, str] = {
    "length": QT_TRANSLATE_NOOP("Messages", "length"),
    "function": QT_TRANSLATE_NOOP("Messages", "function code"),
    "byte count": QT_TRANSLATE_NOOP("Messages", "byte count"),
    "exception code": QT_TRANSLATE_NOOP("Messages", "exception code"),
    "address": QT_TRANSLATE_NOOP("Messages", "address"),
    "value": QT_TRANSLATE_NOOP("Messages", "value"),
    "quantity": QT_TRANSLATE_NOOP("Messages", "quantity"),
    "transaction id": QT_TRANSLATE_NOOP("Messages", "transaction id"),
    "protocol id": QT_TRANSLATE_NOOP("Messages", "protocol id"),
    "unit id": QT_TRANSLATE_NOOP("Messages", "unit id"),
    "CRC": QT_TRANSLATE_NOOP("Messages", "CRC"),
}

_MODBUS_EXCEPTIONS: dict[int, str] = {
    0x01: QT_TRANSLATE_NOOP("Messages", "illegal function"),
    0x02: QT_TRANSLATE_NOOP("Messages", "illegal data address"),
    0x03: QT_TRANSLATE_NOOP("Messages", "illegal data value"),
    0x04: QT_TRANSLATE_NOOP("Messages", "server device failure"),
    0x05: QT_TRANSLATE_NOOP("Messages", "acknowledge"),
    0x06: QT_TRANSLATE_NOOP("Messages", "server device busy"),
    0x07: QT_TRANSLATE_NOOP("Messages", "negative acknowledge"),
    0x08: QT_TRANSLATE_NOOP("Messages", "memory parity error"),
    0x0A: QT_TRANSLATE_NOOP("Messages", "gateway path unavailable"),
    0x0B: QT_TRANSLATE_NOOP("Messages", "gateway target device failed to respond"),
}
_UNKNOWN_EXCEPTION = QT_TRANSLATE_NOOP("Messages", "unknown exception")


def _command_name(command: Any) -> str:
    try:
        member = RunCommand(int(command))
    except (TypeError, ValueError):
        return _tr(_A_COMMAND)
    return _tr(RUN_COMMAND_TEXT[member], "Protocol") if member in RUN_COMMAND_TEXT else _tr(_A_COMMAND)


def operation_text(operation: str) -> str:
    """An :class:`~app.link.types.Operation` name in the operator's language."""
    return _tr(_OPERATIONS.get(operation, _AN_OPERATION))


def status_text(status: CommandStatus) -> str:
    """GV291 in words, translated (context "Protocol")."""
    if status.text == UNKNOWN_STATUS_TEXT.format(code=status.code):
        return _tr(UNKNOWN_STATUS_TEXT, "Protocol").format(code=status.code)
    return _tr(status.text, "Protocol")


def _status(args: Mapping[str, Any]) -> str | None:
    if "status" not in args:
        return None
    kind: CommandKind | None = None
    if args.get("kind") is not None:
        kind = CommandKind(args["kind"])
    elif "command" in args:
        try:
            kind = CommandKind.of(RunCommand(int(args["command"])))
        except ValueError:
            kind = None
    return status_text(CommandStatus(kind, int(args["status"])))


def _alarms(mask: int) -> str:
    return join_names(
        _tr(name, "Protocol") if not name.startswith("bit ") else name[4:] for name in alarm_names(mask)
    )


def _fields(code: str, args: Mapping[str, Any]) -> dict[str, str]:
    """The placeholders of ``code``'s sentence, formatted and translated from its arguments. A
    command without a 440 code (go to zero, the plain commands) is named by its operation."""
    if args.get("command") is None and "operation" in args:
        out: dict[str, str] = {"command": operation_text(str(args["operation"]))}
    else:
        out = {"command": _command_name(args.get("command"))}
    for key, value in args.items():
        if key in ("command", "kind") or value is None:
            continue
        out[key] = (
            _number(value) if isinstance(value, int | float) and not isinstance(value, bool) else str(value)
        )
    status = _status(args)
    if status is not None:
        out["status"] = status
    if "alarms" in args:
        out["alarms"] = _alarms(int(args["alarms"]))
    _named_fields(args, out)
    file_fields(code, args, out)
    if code == "modbus_exception" and "exception" in args:
        out["name"] = _tr(_MODBUS_EXCEPTIONS.get(int(args["exception"]), _UNKNOWN_EXCEPTION))
    return out


def _named_fields(args: Mapping[str, Any], out: dict[str, str]) -> None:
    """The arguments that are names in the protocol's or the operator's words: an operation, a
    controller mode, a settings field (a field with no name of its own is left out)."""
    if "operation" in args:
        out["operation"] = operation_text(str(args["operation"]))
    if "mode" in args:
        out["mode"] = _tr(controller_mode_text(int(args["mode"])), "Protocol")
    if "field" in args:
        field = str(args["field"])
        if field in _FIELDS:
            out["field"] = _tr(_FIELDS[field])
        else:
            out.pop("field", None)


def reason_text(reason: Reason) -> str | None:
    """One translated sentence for ``reason``; None for a code this module does not know."""
    text = _own_sentence(reason)
    if text is not None:
        return text
    return _template_text(reason)


def _own_sentence(reason: Reason) -> str | None:
    """The codes worded by a sentence of their own (the envelope, the stops that name another
    failure, a robot profile); None for the codes of the template tables."""
    args = reason.args
    if reason.code == "envelope_refused":
        return envelope_text(args)
    if reason.code == "stop_sent_on_line":  # the main link's failure, in its own sentence
        cause = reason_text(Reason(str(args.get("cause", "")), dict(args.get("cause_args") or {})))
        if cause is None:
            return _tr(_BARE["stop_sent_on_line"])
        return _tr(_TEMPLATES["stop_sent_on_line"]).format(cause=cause)
    if reason.code in _FRESH_STOP:
        return _fresh_stop_text(reason)
    if is_profile_code(reason.code):
        return profile_text(reason.code, args)
    return None


def _template_text(reason: Reason) -> str | None:
    """``reason`` in the sentence of the template tables (the bare one when an argument is
    missing), wrapped in the (re)connect sentence when it says which controller."""
    args = reason.args
    code = _sentence_code(reason)
    template = _TEMPLATES.get(code)
    if template is None:
        return None
    fields = _fields(reason.code, args)
    try:
        text = _tr(template).format(**fields)
    except KeyError:
        bare = _BARE.get(code, _BARE.get(reason.code))
        if bare is None:
            return None
        try:
            text = _tr(bare).format(**fields)
        except KeyError:
            return None
    if "reconnect" in args and "endpoint" in args:
        wrapper = _RECONNECT if args["reconnect"] else _CONNECT
        text = _tr(wrapper).format(endpoint=args["endpoint"], cause=text)
    return text


def _sentence_code(reason: Reason) -> str:
    """The template ``reason`` reads in: its code, but a Modbus exception is said as a wrong unit id
    (a gateway's 10 / 11 at a unit id) or as the refusal of the request it names."""
    args = reason.args
    if reason.code != "modbus_exception":
        return reason.code
    if "unit" in args and args.get("exception") in GATEWAY_EXCEPTIONS:
        return "modbus_gateway"  # a wrong unit id, most often: said as such
    if "operation" in args:
        return _REFUSED_REQUESTS.get(str(args["operation"]), "request_refused")
    return reason.code


def result_text(result: CommandResult) -> str:
    """How a command ended, as one sentence ("Last command", the event log, status lines)."""
    reason = result.reason
    if reason is None and not result.ok and result.status is None:
        # nothing structured: a failure without a controller status is not "refused"; say what
        # we have (the English message) rather than guess a cause
        return _tr(_FAILED_WITH).format(message=result.message) if result.message else _tr(_FAILED)
    if reason is None:
        reason = Reason(
            "done" if result.ok else "command_refused",
            {
                "command": int(result.command) if result.command is not None else None,
                **(
                    {
                        "status": result.status.code,
                        "kind": result.status.kind.value if result.status.kind else None,
                    }
                    if result.status is not None
                    else {}
                ),
            },
        )
        if result.ok and result.unconfirmed:
            reason = Reason("done_unconfirmed", reason.args)
    text = reason_text(reason)
    if text is None:
        return result.message or _tr(_FAILED)
    return text


def result_level(result: CommandResult) -> str:
    """info for success and the operator's own stop, warning for an unconfirmed success and for a
    Stop the main connection did not carry (the stop connection or a fresh one did)."""
    if result.ok:
        another_way = result.reason is not None and result.reason.code in (
            "stop_sent_on_line",
            "stop_sent_fresh",
        )
        return LEVEL_WARNING if result.unconfirmed or another_way else LEVEL_INFO
    return LEVEL_INFO if result.stopped_by_operator else LEVEL_ERROR


def error_text(error: WorkerError | TeachPadError | Reason) -> str:
    """What went wrong, as one sentence; the English message when there is no known reason."""
    if isinstance(error, Reason):
        return reason_text(error) or error.code
    if isinstance(error, TeachPadError):
        return reason_text(error.as_reason()) or str(error)
    if error.reason is not None:
        text = reason_text(error.reason)
        if text is not None:
            return text
    return error.message


# The main link's stop failed but the controller took the stop line's (app/link/commands.py): the
# arm was stopped; the main link's failure is said after it.
_TEMPLATES["stop_sent_on_line"] = QT_TRANSLATE_NOOP(
    "Messages", "Stop sent (on the separate stop connection); the main connection did not take it: {cause}"
)
_BARE["stop_sent_on_line"] = QT_TRANSLATE_NOOP(
    "Messages", "Stop sent (on the separate stop connection); the main connection did not take it."
)

# A GUI plan run ended because the controller went silent while the connection stays open
# (LinkState.NOT_ANSWERING, ui/controllers/plan_run_controller.py): not a lost link.
_TEMPLATES["run_not_answering"] = QT_TRANSLATE_NOOP(
    "Messages",
    "The controller at {endpoint} is not answering (the connection is still open): no further segment is sent. The arm may still finish its current move; check the robot before resuming.",
)
_BARE["run_not_answering"] = QT_TRANSLATE_NOOP(
    "Messages",
    "The controller is not answering (the connection is still open): no further segment is sent. The arm may still finish its current move; check the robot before resuming.",
)


def connection_text(connection: ConnectionState) -> str:
    """Why the link is in its state, as one sentence ("" when there is nothing to say); the
    English message only from a producer that gives no reason."""
    if connection.reason is not None:
        return reason_text(connection.reason) or ""
    return connection.message


def refusal_text(exc: BaseException) -> str:
    """Why the core refused an edit or a file, in the operator's language when the error
    carries a specific code this module words; else its English text (a field's own reason
    for a :class:`~app.points.point.FieldError`)."""
    if isinstance(exc, FileFormatError):
        problem = reason_text(exc.problem) if exc.problem is not None else None
        return file_text(exc, problem) or str(exc)
    if isinstance(exc, TeachPadError) and exc.code not in ("error", "invalid_input"):
        text = reason_text(exc.as_reason())
        if text is not None:
            return text
    return exc.reason if isinstance(exc, FieldError) else str(exc)


def os_error_text(path: object, exc: OSError) -> str:
    """A file the system would not open or write, in the operator's language ("a.csv: ...")."""
    code, args = os_problem(exc)
    return refusal_text(FileFormatError(exc.strerror or str(exc), path=str(path), problem=Reason(code, args)))


# A Stop the main link could not carry went over a fresh connection to the last controller
# (app/link/halt.py: disconnected, lost, or its own stop failed), or could not reach it.
_TEMPLATES["stop_sent_fresh"] = QT_TRANSLATE_NOOP(
    "Messages", "Stop sent to {endpoint} over a fresh connection (TeachPad was not connected to it)."
)
_TEMPLATES["stop_sent_fresh_after"] = QT_TRANSLATE_NOOP(
    "Messages",
    "Stop sent to {endpoint} over a fresh connection; the main connection did not take it: {cause}",
)
_BARE["stop_sent_fresh_after"] = QT_TRANSLATE_NOOP(
    "Messages", "Stop sent to {endpoint} over a fresh connection; the main connection did not take it."
)
_TEMPLATES["stop_unreachable"] = QT_TRANSLATE_NOOP(
    "Messages", "Stop could not reach the controller at {endpoint}: {cause} Check the robot."
)
_BARE["stop_unreachable"] = QT_TRANSLATE_NOOP(
    "Messages", "Stop could not reach the controller at {endpoint}. Check the robot."
)
_FRESH_STOP = ("stop_sent_fresh", "stop_unreachable")


def _fresh_stop_text(reason: Reason) -> str:
    """A Stop over a fresh connection: sent (after the main link's failure, when it had one) or
    not (why: the fresh connection's failure), naming the controller."""
    args = reason.args
    endpoint = str(args.get("endpoint", ""))
    cause = None
    if args.get("cause"):
        cause_args = dict(args.get("cause_args") or {})
        for named_here in ("endpoint", "reconnect"):  # the controller is named once, by this sentence
            cause_args.pop(named_here, None)
        cause = reason_text(Reason(str(args["cause"]), cause_args))
    if reason.code == "stop_sent_fresh":
        if "cause" not in args:
            return _tr(_TEMPLATES["stop_sent_fresh"]).format(endpoint=endpoint)
        if cause is None:
            return _tr(_BARE["stop_sent_fresh_after"]).format(endpoint=endpoint)
        return _tr(_TEMPLATES["stop_sent_fresh_after"]).format(endpoint=endpoint, cause=cause)
    if cause is None:
        return _tr(_BARE["stop_unreachable"]).format(endpoint=endpoint)
    return _tr(_TEMPLATES["stop_unreachable"]).format(endpoint=endpoint, cause=cause)


# A queued request the worker dropped before sending it (app/link/commands.py): a motion queued
# behind a Stop, an upload queued when the operator cancelled uploads. Nothing was sent.
_TEMPLATES["cancelled_by_stop"] = QT_TRANSLATE_NOOP("Messages", "{operation}: not sent, cancelled by Stop.")
_TEMPLATES["upload_cancelled"] = QT_TRANSLATE_NOOP(
    "Messages", "{operation}: not sent, the upload was cancelled."
)
