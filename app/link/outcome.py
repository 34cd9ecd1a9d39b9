"""A command's outcome as the controller said it: done, refused, stopped or unknown.

A write the controller answered says only that it arrived. What the command then did is told by
GV291 (:class:`~app.link.tracker.CommandTracker`: moves, create point, teach) or, for the
commands without a GV291 result (run program, go to zero), by motion
(:class:`~app.link.watch.MotionWatch`). Both end in a :class:`~app.models.CommandResult`;
:func:`outcome_of` sorts it into the four words the CLI's exit codes, the audit trail and the
GUI's command results share (one rule for all three):

* ``done``: the controller reported it done (0xFF), or it was seen done (moved and stood still);
* ``refused``: the controller said no, or did not finish it and said why: a GV291 error code (its
  meaning in words), an alarm, nothing moved for a command that is told only by motion;
* ``stopped``: a stop ended it (the operator's, or the controller's own);
* ``unknown``: sent and answered, but what it did cannot be told: its status reads failed, it did
  not finish within its time, the controller never acknowledged it, the link went down. The robot
  may have acted on it: check it before sending it again (:data:`UNKNOWN_ADVICE`).

:func:`outcome_note` gives the completion its audit hook: the command's write(s) were recorded as
awaiting an outcome (:meth:`~app.link.register_client.RegisterClient.judged_writes`), and the
outcome is recorded against them once the command ends (:meth:`AuditLog.record_result`).
"""

from __future__ import annotations

import enum
from collections.abc import Callable, Sequence
from typing import Any

from app.models import LINK_FAILURE_CODES, CommandResult
from app.safety.audit import AuditLog
from app.safety.audit_read import AuditRecord

__all__ = ["UNKNOWN_ADVICE", "Outcome", "OutcomeHook", "outcome_args", "outcome_note", "outcome_of"]

#: What an unknown outcome tells the operator (CLI, audit; the GUI says it in its own words).
UNKNOWN_ADVICE = "sent; the outcome is unknown \u2014 check the robot before sending it again"

#: Called once with a command's result when it ends (the audit's hook).
OutcomeHook = Callable[[CommandResult], None]


class Outcome(enum.Enum):
    """What the controller made of a command (the audit's result word)."""

    DONE = "done"
    REFUSED = "refused"
    STOPPED = "stopped"
    UNKNOWN = "unknown"


#: Reason codes of a command that ended without its outcome being told.
UNKNOWN_CODES = frozenset(
    {
        "outcome_unknown",
        "outcome_unknown_link_lost",
        "outcome_unknown_link_closed",
        "result_unknown",
        "not_acknowledged",
        "command_timeout",
        "sent",
        *LINK_FAILURE_CODES,
    }
)
#: Reason codes of a command a stop ended (the operator's, or the controller's own).
STOPPED_CODES = frozenset({"stopped_by_operator", "stopped_by_controller", "zero_stopped_short"})


def outcome_of(result: CommandResult) -> Outcome:
    """The four-word outcome of ``result`` (see the module docstring)."""
    code = result.reason.code if result.reason is not None else None
    if code == "sent":  # sent and not waited for: ``ok`` says only that the write was answered
        return Outcome.UNKNOWN
    if result.ok:
        return Outcome.DONE
    if code in STOPPED_CODES:
        return Outcome.STOPPED
    if code in UNKNOWN_CODES or (code is None and result.status is None):
        return Outcome.UNKNOWN
    return Outcome.REFUSED


def outcome_args(result: CommandResult) -> dict[str, Any]:
    """What the audit keeps beside the word: the GV291 code (refused:<code>) and the reason."""
    args: dict[str, Any] = {}
    if result.reason is not None:
        args["reason"] = result.reason.code
        # its arguments, for the viewer's words (ui/audit_words.py): plain values only (the
        # record is JSON), nested causes left out
        kept = {
            k: v
            for k, v in result.reason.args.items()
            if v is None or isinstance(v, str | int | float | bool)
        }
        if kept:
            args["reason_args"] = kept
    if result.status is not None and result.status.is_error:  # the controller's refusal code
        args["status"] = result.status.code
    if result.ok and result.unconfirmed:
        args["unconfirmed"] = True
    return args


def outcome_note(audit: AuditLog | None, writes: Sequence[AuditRecord]) -> OutcomeHook | None:
    """The hook that records a command's outcome against its ``writes`` (None without a trail)."""
    if audit is None or not writes:
        return None
    kept = tuple(writes)

    def note(result: CommandResult) -> None:
        outcome, args = outcome_of(result), outcome_args(result)
        for write in kept:
            audit.record_result(write, outcome.value, result.message, args)

    return note
