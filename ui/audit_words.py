"""The audit viewer's command and detail columns in the operator's language.

The audit trail keeps English (it is a record: the file, its hash chain and the CSV export stay
as written). The viewer words what it knows: the actions and session events the product records
(:mod:`app.safety.session`, :class:`app.safety.roles.Action`), a command write's action (the
protocol's names, context "Protocol": "teach enable (440 ← 0x80)" reads "示教使能（440 ← 0x80）"),
a register write, and an outcome by its reason code (``args["reason"]``, ``args["reason_args"]``:
:func:`app.link.outcome.outcome_args`). Anything else is shown as recorded.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from typing import Any

from PySide6.QtCore import QCoreApplication

from app.errors import Reason
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
    return record.detail


def _role_refused(args: Mapping[str, Any]) -> str | None:
    """A control the role in force may not use (app.safety.session.require)."""
    need, role = str(args.get("need", "")), str(args.get("role", ""))
    if need not in _ROLES or role not in _ROLES:
        return None
    return _tr(_ROLE_REFUSED).format(need=_tr(need), role=_tr(role))


_ROLE_REFUSED = QT_TRANSLATE_NOOP("AuditWords", "needs the {need} role ({role} was logged in)")
