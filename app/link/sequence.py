"""The worker's sequence of its parts for one poll (worker thread; Qt-free, so the tests' host
runs the same order as :class:`~app.link.worker.RobotWorker`).

The poller reads and returns what it read; this hands it on, in the order docs/DESIGN.md
describes ("The poller"): a failed poll to the supervisor (silence, a failed transaction); a good
one to the supervisor (answering again), then published, the restart canary to the supervisor,
another master's signs, the command it completed (the tracker), the jog's teach watch, the RTT
and the link statistics. What the supervisor decides on the way (the link lost, answering again)
goes on to the other parts through :mod:`app.link.lifecycle`. No part calls another for a poll.
"""

from __future__ import annotations

import time
from typing import Protocol

from app.link import lifecycle
from app.link.poller import Polled, PollFailed
from app.link.supervisor import LinkSupervisor

__all__ = ["PollParts", "poll"]


class PollParts(lifecycle.LinkParts, Protocol):
    """The parts one poll goes through (a failed or silent one may change the link:
    :mod:`app.link.lifecycle`), and where a completed command's result goes."""

    @property
    def link_up(self) -> bool: ...


def poll(parts: PollParts) -> None:
    """One poll, its outcome handed to the parts in order."""
    supervisor = parts.supervisor
    outcome = parts.poller.poll_once(
        parts.jog, settle=supervisor.answering, canary_gv=lambda: _canary_gv(supervisor)
    )
    if isinstance(outcome, PollFailed):
        _failed(parts, outcome)
    elif outcome is not None:
        _answered(parts, outcome)


def _canary_gv(supervisor: LinkSupervisor) -> int | None:
    """The restart canary's GV to read now (None: not checking)."""
    return supervisor.canary_gv if supervisor.canary_token is not None else None


def _failed(parts: PollParts, outcome: PollFailed) -> None:
    """A failed poll: reported once per distinct error, the command in flight told; silence and
    a failed transaction go to the supervisor."""
    parts.poller.failed(outcome.error)
    if outcome.silent:
        lifecycle.silent(parts, outcome.error, time.monotonic())
    elif outcome.transport_failed:
        # A malformed answer is a failed poll: the transport counted it and resynchronised
        # (a TCP link is reopened by the next request); none of its values are published;
        # LINK_LOSS_POLLS of them in a row take the link down like any failed transaction.
        lifecycle.link_failed(parts, outcome.error)
    else:
        return
    parts.poller.report_stats()


def _answered(parts: PollParts, polled: Polled) -> None:
    """A good poll: published, then the canary, another master's signs, the command in flight,
    the jog, the RTT and the link statistics."""
    poller, tracker = parts.poller, parts.motion
    poller.answered()
    lifecycle.answered(parts)
    if not parts.link_up:
        return
    status, pose = poller.publish_reading(polled)
    canary = polled.reading.canary
    if canary is not None:
        failure = parts.supervisor.canary_read(canary)
        if failure is not None:  # the rearm's write failed on the link
            lifecycle.link_failed(parts, failure)
    poller.report_foreign(polled.client)
    done = tracker.update(status, pose, polled.answered)
    if done is not None:
        parts.emit_result(*done)
    parts.jog.after_status(status, polled.answered, idle=tracker.active is None)
    poller.report_rtt(polled)
