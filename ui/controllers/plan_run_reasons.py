"""Why a plan run ended, in the operator's words: the run's own sentences and the error a link
change means for the segment under way.

:class:`~ui.controllers.plan_run_controller.PlanRunController` drives the run and keeps the
reason of its last end (``end_reason``, one translated sentence); these functions turn that
reason and the runner's :class:`~app.plan.runner.RunOutcome` into what the planner shows
("Failed at segment 2: ..."). Nothing here holds state or talks to the link. The texts keep
the ``PlanRunController`` translation context they had when they lived there (literal
``QCoreApplication.translate`` calls: lupdate collects only those).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from PySide6.QtCore import QCoreApplication

from app.errors import LinkError, ResponseTimeout, TeachPadError
from app.link.types import ConnectionState, LinkState
from ui.foreign_words import foreign_sign_text

if TYPE_CHECKING:  # app.plan.runner is imported where a run starts, after the first paint
    from app.plan.runner import RunOutcome

__all__ = [
    "connection_error",
    "foreign_pause_text",
    "foreign_resume_refused_text",
    "outcome_text",
    "stopped_by_operator",
]


def stopped_by_operator() -> str:
    """The end reason of a run the operator stopped, translated."""
    return QCoreApplication.translate("PlanRunController", "stopped by the operator")


def outcome_text(outcome: RunOutcome, end_reason: str = "", *, by_operator: bool = False) -> str:
    """How a stopped or failed run ended, one sentence: ``end_reason`` (the controller's
    translated reason) if there is one, else the runner's own message; a run the operator
    stopped (``by_operator``) reads where it stood, in the language shown now."""
    from app.plan.runner import RunState  # lazy: not before the first paint

    failed = outcome.state is RunState.FAILED
    if not failed and by_operator and outcome.resume_from is not None:
        return _stopped_at(outcome)
    reason = end_reason or outcome.message
    if outcome.resume_from is None:
        text = (
            QCoreApplication.translate("PlanRunController", "Failed: {reason}")
            if failed
            else QCoreApplication.translate("PlanRunController", "Stopped: {reason}")
        )
        return text.format(reason=reason)
    text = (
        QCoreApplication.translate("PlanRunController", "Failed at segment {n}: {reason}")
        if failed
        else QCoreApplication.translate("PlanRunController", "Stopped at segment {n}: {reason}")
    )
    return text.format(n=outcome.resume_from + 1, reason=reason)


def _stopped_at(outcome: RunOutcome) -> str:
    """The operator's Stop, where the run stood: not a failure, and the loop is named when the
    plan has more than one ("Stopped by the operator at segment 2, loop 2 of 20")."""
    assert outcome.resume_from is not None
    n, loop, loops = outcome.resume_from + 1, outcome.resume_loop or 1, outcome.loops
    if loops == 1:
        return QCoreApplication.translate(
            "PlanRunController", "Stopped by the operator at segment {n}"
        ).format(n=n)
    if loops == 0:
        return QCoreApplication.translate(
            "PlanRunController", "Stopped by the operator at segment {n}, loop {loop} (endless)"
        ).format(n=n, loop=loop)
    return QCoreApplication.translate(
        "PlanRunController", "Stopped by the operator at segment {n}, loop {loop} of {loops}"
    ).format(n=n, loop=loop, loops=loops)


def connection_error(state: ConnectionState) -> TeachPadError:
    """Why a run ends when the link leaves CONNECTED: a controller that went silent while the
    connection stays open (``NOT_ANSWERING``) is not a lost link, and is not said as one."""
    where = {"endpoint": state.endpoint} if state.endpoint else {}
    if state.state is LinkState.NOT_ANSWERING:
        return ResponseTimeout(
            f"the controller is not answering: {state.message or 'no answer'}",
            code="run_not_answering",
            params=where,
        )
    return LinkError(f"link lost: {state.message or 'link lost'}", params=where)


def foreign_pause_text(what: str, value: float) -> str:
    """Why a run paused itself: a sign of another master (``what``, ``value``: app/link/foreign.py)."""
    return QCoreApplication.translate(
        "PlanRunController", "Paused: another master wrote to the controller ({sign})"
    ).format(sign=foreign_sign_text(what, value))


def foreign_resume_refused_text(hold: float, left: float) -> str:
    """Why Resume did nothing: another master was seen less than ``hold`` s ago (``left`` s to go)."""
    return QCoreApplication.translate(
        "PlanRunController",
        "Not resumed: another master wrote to the controller less than {hold} s ago. "
        "Make sure no other master is commanding the robot; Resume is possible in {left} s.",
    ).format(hold=f"{hold:g}", left=f"{max(left, 0.1):.1f}")
