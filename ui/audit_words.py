"""The audit viewer's command and detail columns in the operator's language.

The audit trail keeps English (it is a record: the file, its hash chain and the CSV export stay
as written). The viewer words what it knows: the actions and session events the product records
(:mod:`app.safety.session`, :class:`app.safety.roles.Action`), a command write's action (the
protocol's names, context "Protocol": "teach enable (440 ← 0x80)" reads "示教使能（440 ← 0x80）"),
a register write, and an outcome by its reason code (``args["reason"]``, ``args["reason_args"]``:
:func:`app.link.outcome.outcome_args`; a write's error since stop 27: :mod:`app.safety.audit`).

A detail recorded without a reason code (records written before the codes, and the refusals whose
producers write English only: a wrong password, the CLI's refusals, the link's refusal of a motion
before the wire, the jog guard's stop, another master seen) is known by its recorded English
(:data:`_DETAIL_PATTERNS`, each pattern the producer's sentence) and its arguments, and worded from
them. Anything else is shown as recorded.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping
from typing import Any

from PySide6.QtCore import QCoreApplication

from app.errors import Reason
from app.protocol.enums import PROGRAM_STATE_TEXT, ProgramState
from app.safety.audit_read import UNKNOWN_DETAIL, UNKNOWN_OUTCOME_DETAIL, AuditRecord

__all__ = ["command_words", "detail_words"]

_CONTEXT = "AuditWords"


def QT_TRANSLATE_NOOP(context: str, text: str) -> str:
    return text


# Recorded as they are (app.safety.roles.Action values, session events)
_PHRASES = frozenset(
    {
        QT_TRANSLATE_NOOP("AuditWords", "jog"),
        QT_TRANSLATE_NOOP("AuditWords", "step"),
        QT_TRANSLATE_NOOP("AuditWords", "teach"),
        QT_TRANSLATE_NOOP("AuditWords", "run plan"),
        QT_TRANSLATE_NOOP("AuditWords", "run program"),
        QT_TRANSLATE_NOOP("AuditWords", "stop"),
        QT_TRANSLATE_NOOP("AuditWords", "reduced speed"),
        QT_TRANSLATE_NOOP("AuditWords", "edit points"),
        QT_TRANSLATE_NOOP("AuditWords", "edit plans"),
        QT_TRANSLATE_NOOP("AuditWords", "edit envelope"),
        QT_TRANSLATE_NOOP("AuditWords", "change robot model"),
        QT_TRANSLATE_NOOP("AuditWords", "leave reduced speed"),
        QT_TRANSLATE_NOOP("AuditWords", "reconnect to the same controller"),
        QT_TRANSLATE_NOOP("AuditWords", "change connection"),
        QT_TRANSLATE_NOOP("AuditWords", "change register profile"),
        QT_TRANSLATE_NOOP("AuditWords", "manage roles and passwords"),
        QT_TRANSLATE_NOOP("AuditWords", "write a support bundle"),
        QT_TRANSLATE_NOOP("AuditWords", "write controller registers directly"),
        QT_TRANSLATE_NOOP("AuditWords", "move to point"),
        QT_TRANSLATE_NOOP("AuditWords", "set the idle lock time"),
        QT_TRANSLATE_NOOP("AuditWords", "reduced speed on"),
        QT_TRANSLATE_NOOP("AuditWords", "stop measured"),  # measured stopping (app/safety/stopping.py)
        QT_TRANSLATE_NOOP("AuditWords", "jog release measured"),
        QT_TRANSLATE_NOOP("AuditWords", "reduced speed off"),
        QT_TRANSLATE_NOOP("AuditWords", "clear the administrator password"),
    }
)
_ROLES = frozenset(
    {
        QT_TRANSLATE_NOOP("AuditWords", "operator"),
        QT_TRANSLATE_NOOP("AuditWords", "engineer"),
        QT_TRANSLATE_NOOP("AuditWords", "administrator"),
    }
)
# (pattern of the recorded English, its sentence with the groups as placeholders)
_PATTERNS: tuple[tuple[re.Pattern[str], str], ...] = (
    (re.compile(r"log in as (?P<role>\w+)"), QT_TRANSLATE_NOOP("AuditWords", "log in as {role}")),
    (re.compile(r"log out \((?P<role>\w+)\)"), QT_TRANSLATE_NOOP("AuditWords", "log out ({role})")),
    (
        re.compile(r"set the (?P<role>\w+) password"),
        QT_TRANSLATE_NOOP("AuditWords", "set the {role} password"),
    ),
    (
        re.compile(r"change the (?P<role>\w+) password"),
        QT_TRANSLATE_NOOP("AuditWords", "change the {role} password"),
    ),
    (
        re.compile(r"clear the (?P<role>\w+) password"),
        QT_TRANSLATE_NOOP("AuditWords", "clear the {role} password"),
    ),
    (
        re.compile(r"locked back to operator after (?P<seconds>[\d.]+) s idle"),
        QT_TRANSLATE_NOOP("AuditWords", "locked back to operator after {seconds} s idle"),
    ),
    # a command write (FC06): "teach enable (440 ← 0x80)"
    (
        re.compile(r"(?P<action>[a-z][a-z ]*[a-z]) \((?P<register>\d+ ← [^)]+)\)"),
        QT_TRANSLATE_NOOP("AuditWords", "{action} ({register})"),
    ),
    (re.compile(r"write (?P<what>.+)"), QT_TRANSLATE_NOOP("AuditWords", "write {what}")),
)
_DETAILS = {
    UNKNOWN_DETAIL: QT_TRANSLATE_NOOP("AuditWords", "sent; TeachPad stopped before the answer was recorded"),
    UNKNOWN_OUTCOME_DETAIL: QT_TRANSLATE_NOOP(
        "AuditWords",
        "sent and answered; the controller's outcome was not recorded (still under way when read, "
        "or TeachPad stopped first)",
    ),
}


def _tr(text: str) -> str:
    return QCoreApplication.translate(_CONTEXT, text)


def _field(name: str, value: str) -> str:
    if name == "role" and value in _ROLES:
        return _tr(value)
    if name == "action":
        return QCoreApplication.translate("Protocol", value)
    return value


def command_words(record: AuditRecord) -> str:
    """The record's command in the operator's language, or as recorded when it is not known."""
    command = record.command
    if command in _PHRASES:
        return _tr(command)
    for pattern, sentence in _PATTERNS:
        match = pattern.fullmatch(command)
        if match is not None:
            fields = {name: _field(name, value) for name, value in match.groupdict().items()}
            return _tr(sentence).format(**fields)
    return command


def detail_words(record: AuditRecord) -> str:
    """Why, in the operator's language: the outcome's reason when the record keeps its code."""
    from ui.messages import reason_text  # the words of the whole product: not at import

    args: Mapping[str, Any] = record.args
    code = args.get("reason")
    if isinstance(code, str) and code:
        reason_args = args.get("reason_args")
        plain = dict(reason_args) if isinstance(reason_args, dict) else {}
        text = _role_refused(plain) if code == "role_refused" else reason_text(Reason(code, plain))
        if text:
            return text
    if record.detail in _DETAILS:
        return _tr(_DETAILS[record.detail])
    return _recorded_words(record) or record.detail


def _recorded_words(record: AuditRecord) -> str | None:
    """A detail recorded without a reason code, worded from its English and its arguments (None:
    not one this module knows)."""
    args: Mapping[str, Any] = record.args
    if record.command == "another Modbus master seen" and "what" in args and "value" in args:
        from ui.foreign_words import foreign_master_text

        return foreign_master_text(str(args["what"]), float(args["value"]))
    for pattern, words in _DETAIL_PATTERNS:
        match = pattern.fullmatch(record.detail)
        if match is not None:
            return words(match.groupdict(), args)
    return None


# --- details recorded without a reason code -----------------------------------------------------
_Words = Callable[[dict[str, Any], Mapping[str, Any]], "str | None"]


def _sentence(sentence: str) -> _Words:
    """A fixed sentence whose placeholders are the pattern's groups (a role is translated)."""

    def words(groups: dict[str, Any], _args: Mapping[str, Any]) -> str:
        fields = {name: _field(name, str(value or "")) for name, value in groups.items()}
        return _tr(sentence).format(**fields)

    return words


def _coded(code: str) -> _Words:
    """A typed refusal the link wrote as English beside its arguments: its sentence by ``code``."""

    def words(_groups: dict[str, Any], args: Mapping[str, Any]) -> str | None:
        from ui.messages import reason_text

        return reason_text(Reason(code, dict(args)))

    return words


def _busy(_groups: dict[str, Any], args: Mapping[str, Any]) -> str:
    try:
        state = QCoreApplication.translate(
            "Protocol", PROGRAM_STATE_TEXT[ProgramState(args["program_state"])]
        )
    except (KeyError, ValueError):
        state = str(args.get("program_state", ""))
    return _tr(_BUSY).format(state=state)


def _envelope(violation: str, approaching: bool = False) -> _Words:
    """An envelope violation's English (app.safety.envelope.EnvelopeViolation.message) back to its
    arguments, then the envelope's own words."""

    def words(groups: dict[str, Any], _args: Mapping[str, Any]) -> str:
        from ui.messages_plan import envelope_text

        code = violation
        if approaching:  # which boundary: a keep-out zone, a joint's limit, the work space
            code = (
                "keep_out" if groups.get("box") else "joint_limit" if groups.get("unit") == "°" else "keep_in"
            )
        segment = groups.get("segment")
        params = {
            "violation": code,
            "approaching": approaching,
            "axis": groups.get("axis") or "",
            "box": groups.get("box") or "",
            "value": float(groups["value"]),
            "limit": float(groups["limit"]),
            "reduced": bool(groups.get("reduced")),
            "segment": None if segment is None else int(segment) - 1,
        }
        return envelope_text(params, prefix=False)

    return words


_SEG = r"(?:segment (?P<segment>\d+): )?"
_NUM = r"-?[\d.]+(?:e[+-]?\d+)?"
_BUSY = QT_TRANSLATE_NOOP(
    "AuditWords", "not sent: the controller is busy (program {state}); wait for it to end, or stop it"
)
_DETAIL_PATTERNS: tuple[tuple[re.Pattern[str], _Words], ...] = (
    # logins (app/safety/roles.py, app/cli/guard.py, app/cli/support.py)
    (
        re.compile(r"wrong password for the (?P<role>\w+) role"),
        _sentence(QT_TRANSLATE_NOOP("AuditWords", "wrong password for the {role} role")),
    ),
    (
        re.compile(r"no password is set for the (?P<role>\w+) role; an administrator sets it"),
        _sentence(
            QT_TRANSLATE_NOOP(
                "AuditWords", "no password is set for the {role} role; an administrator sets it"
            )
        ),
    ),
    (
        re.compile(r"the (?P<role>\w+) role needs its password: run it in a terminal, or set (?P<env>\w+)"),
        _sentence(
            QT_TRANSLATE_NOOP(
                "AuditWords", "the {role} role needs its password: run it in a terminal, or set {env}"
            )
        ),
    ),
    (
        re.compile(r"the administrator password is needed: run it in a terminal, or set (?P<env>\w+)"),
        _sentence(
            QT_TRANSLATE_NOOP(
                "AuditWords", "the administrator password is needed: run it in a terminal, or set {env}"
            )
        ),
    ),
    (
        re.compile(r"wrong administrator password"),
        _sentence(QT_TRANSLATE_NOOP("AuditWords", "wrong administrator password")),
    ),
    (
        re.compile(r"the administrator password can be changed, not removed \(anyone could then set it\)"),
        _sentence(
            QT_TRANSLATE_NOOP(
                "AuditWords",
                "the administrator password can be changed, not removed (anyone could then set it)",
            )
        ),
    ),
    # the CLI's move without the project (app/cli/guard.py)
    (
        re.compile(
            r"P(?P<id>\d+) cannot be checked against the safety envelope: the host has no copy of it "
            r"\(give the project holding the point with (?P<option>--project)\)"
        ),
        _sentence(
            QT_TRANSLATE_NOOP(
                "AuditWords",
                "P{id} cannot be checked against the safety envelope: the host has no copy of it "
                "(give the project holding the point with {option})",
            )
        ),
    ),
    # the link's refusals before the wire (app/link/client.py, command_client.py)
    (
        re.compile(
            r".+ not sent: the controller is busy \(program state \w+\); wait for it to end, or stop it"
        ),
        _busy,
    ),
    (re.compile(r".+ refused in reduced-speed mode: .+"), _coded("reduced_speed_refused")),
    (
        re.compile(r".+ refused: the controller is (?:in manual mode|not in auto mode) .+"),
        _coded("manual_mode"),
    ),
    (
        re.compile(r".+ not sent: .+ less than \S+ s ago; its writes could change this move.*"),
        _coded("foreign_master"),
    ),
    # a plan run's Resume within another master's hold (ui/controllers/plan_run_controller.py)
    (
        re.compile(r"another master wrote to the controller less than (?P<hold>[\d.]+) s ago"),
        _sentence(
            QT_TRANSLATE_NOOP(
                "AuditWords", "another Modbus master wrote to the controller less than {hold} s ago"
            )
        ),
    ),
    # the envelope's violations as the CLI and the jog guard record them (EnvelopeViolation.message)
    (
        re.compile(
            _SEG + rf"(?P<axis>\S+) = (?P<value>{_NUM}) (?P<unit>mm|°) is within stopping distance of "
            rf"(?:the keep-out zone '(?P<box>.*)'|its limit|the edge of the allowed work space) at "
            rf"(?P<limit>{_NUM}) (?:mm|°)"
        ),
        _envelope("", approaching=True),
    ),
    (
        re.compile(
            _SEG + rf"(?P<axis>\S+) = (?P<value>{_NUM}) mm is outside the allowed work space "
            rf"\((?:above|below) its limit (?P<limit>{_NUM}) mm\)"
        ),
        _envelope("keep_in"),
    ),
    (
        re.compile(
            _SEG
            + rf"the path enters the keep-out zone '(?P<box>.*)' \((?P<axis>\S+) = (?P<value>{_NUM}) mm, "
            rf"its face is at (?P<limit>{_NUM}) mm\)"
        ),
        _envelope("keep_out"),
    ),
    (
        re.compile(
            _SEG + rf"(?P<axis>\S+) = (?P<value>{_NUM})° is (?:above|below) its limit (?P<limit>{_NUM})°"
        ),
        _envelope("joint_limit"),
    ),
    (
        re.compile(
            _SEG + rf"speed (?P<value>{_NUM}) mm/s is above the (?P<limit>{_NUM}) mm/s allowed"
            r"(?P<reduced> in reduced-speed mode)?"
        ),
        _envelope("speed"),
    ),
    (
        re.compile(
            _SEG + rf"jog speed (?P<value>{_NUM})% is above the (?P<limit>{_NUM})% allowed"
            r"(?P<reduced> in reduced-speed mode)?"
        ),
        _envelope("jog_ratio"),
    ),
)


def _role_refused(args: Mapping[str, Any]) -> str | None:
    """A control the role in force may not use (app.safety.session.require)."""
    need, role = str(args.get("need", "")), str(args.get("role", ""))
    if need not in _ROLES or role not in _ROLES:
        return None
    return _tr(_ROLE_REFUSED).format(need=_tr(need), role=_tr(role))


_ROLE_REFUSED = QT_TRANSLATE_NOOP("AuditWords", "needs the {need} role ({role} was logged in)")
