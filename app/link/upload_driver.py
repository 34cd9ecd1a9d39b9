"""The one upload driver: how an upload's points go to the controller, the GUI's and the CLI's.

Both uploads -- the GUI's (:class:`app.link.upload.Uploader`, run in chunks by the worker) and
``teachpad-cli points upload`` (:func:`app.cli.points_upload.staged_upload`) -- send their points
through this module, and only their reporting differs (the worker publishes each point and the
count under the upload's ticket, :mod:`app.link.progress`, and one final result; the CLI builds an
:class:`app.points.upload.UploadReport` and watches the restart canary between points):

* :func:`group_by_tool`: the order (GV245, the tool frame, written once per tool);
* :func:`batch_end`: where a batch of one tool frame ends (the worker's chunks are also bounded);
* :func:`send_batch`: one call of :meth:`~app.link.client.RobotClient.upload_points` -- the
  poses in GV0..GV5, the next pose staged in the spare block (:func:`stage_gv_for` the restart
  canary's GV), the controller's *busy* answers retried by the client's line
  (:mod:`app.link.line_retry`) -- with the two ways a batch ends before its first point: the link
  failed (:data:`LINK_ERRORS`: the upload ends) or the controller refused its tool frame or status
  read (a Modbus exception: each of its points refused in the controller's words, the upload goes
  on);
* :func:`verdict` and :class:`UploadCounts`: each point's result read one way -- created, the link
  failed during it (its outcome unknown, the upload ends), stopped by the operator, refused (the
  controller said no), or failed (its result never showed) -- and the refusal tally.
"""

from __future__ import annotations

import enum
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Any, TypeVar

from app.errors import LinkError, MalformedResponse, ModbusExceptionError, ResponseTimeout, TeachPadError
from app.models import CommandResult
from app.protocol.enums import CommandKind, RunCommand
from app.protocol.registers import UPLOAD_POSE_GV, stage_gv_for

__all__ = [
    "LINK_ERRORS",
    "REFUSAL_CODES",
    "Batch",
    "UploadCounts",
    "Verdict",
    "batch_end",
    "group_by_tool",
    "refused_before_the_first",
    "send_batch",
    "verdict",
]

T = TypeVar("T")

#: the errors that say the link failed (lost, no answer in time, a malformed answer): not to be trusted
LINK_ERRORS: tuple[type[TeachPadError], ...] = (LinkError, ResponseTimeout, MalformedResponse)
REFUSAL_CODES = frozenset({"command_refused", "modbus_exception"})  # the controller answered no


def group_by_tool(items: Iterable[T], tool: Callable[[T], int]) -> list[T]:
    """The order points are uploaded in (GV245 is written once per tool frame), the GUI's and the
    CLI's: grouped by ``tool(item)``, stable -- the tools in order of first appearance, each tool's
    points in input order."""
    groups: dict[int, list[T]] = {}
    for item in items:
        groups.setdefault(tool(item), []).append(item)
    return [item for group in groups.values() for item in group]


def batch_end(tools: Sequence[int], first: int, limit: int | None = None) -> int:
    """Where the batch that begins at ``first`` ends: the points of ``first``'s tool frame that
    follow it (``tools``: each point's, in upload order), at most ``limit`` of them."""
    tool, last = tools[first], first
    while last < len(tools) and (limit is None or last - first < limit) and tools[last] == tool:
        last += 1
    return last


def refused_before_the_first(point_ids: Iterable[int], exc: ModbusExceptionError) -> list[CommandResult]:
    """A batch the controller refused before its first point (a Modbus exception on its tool frame
    GV245 or its status read): every point of it refused in the controller's words -- not a link
    failure (:attr:`CommandResult.link_failed` is False), the upload goes on with the next batch."""
    return [
        CommandResult(
            RunCommand.CREATE_POINT,
            CommandKind.CREATE_POINT,
            None,
            False,
            str(exc),
            {"point_id": float(pid)},
            reason=exc.as_reason(),
        )
        for pid in point_ids
    ]


@dataclass(frozen=True)
class Batch:
    """What :func:`send_batch` gave: one result per point tried, in order, and the link's failure
    before the first point (None: none; a failure during a point is that point's result)."""

    results: list[CommandResult]
    link_error: str | None = None


def send_batch(
    client: Any,
    points: Sequence[tuple[int, Sequence[float]]],
    tool: int,
    progress: Callable[[int, int], bool] | None,
    *,
    canary_gv: int | None,
    halted: Callable[[], bool] | None = None,
    between: Callable[[], None] | None = None,
    results: list[CommandResult] | None = None,
) -> Batch:
    """One batch of one tool frame: ``client.upload_points`` with the poses in GV0..GV5 and the
    next one staged in the spare block beside the restart canary ``canary_gv``. ``progress``,
    ``halted`` and ``between`` as :meth:`~app.link.client.RobotClient.upload_points` takes them;
    ``results`` (a list the caller keeps) fills as the points are tried, for a caller interrupted
    meanwhile (Ctrl-C). The client's other errors (a bad input...) go to the caller."""
    out: list[CommandResult] = [] if results is None else results
    try:
        client.upload_points(
            points,
            tool,
            progress,
            gv_start=UPLOAD_POSE_GV,
            stage_gv=stage_gv_for(canary_gv),
            halted=halted,
            between=between,
            results=out,
        )
    except LINK_ERRORS as exc:  # before its first point (the status read, the mode): nothing of it done
        return Batch(out, str(exc) or type(exc).__name__)
    except ModbusExceptionError as exc:  # refused before its first point (GV245, the status read)
        out.extend(refused_before_the_first((pid for pid, _ in points[len(out) :]), exc))
    return Batch(out)


class Verdict(enum.Enum):
    """How one point's result reads."""

    CREATED = "created"
    LINK_FAILED = "link failed"  # its outcome unknown, the link not to be trusted: the upload ends
    STOPPED = "stopped"  # ended by the operator's stop (the host sent it): not the controller's no
    REFUSED = "refused"  # the controller said no (a refused status, a Modbus exception)
    FAILED = "failed"  # its result never showed (no acknowledgement, a timeout, an alarm)


def verdict(result: CommandResult) -> Verdict:
    """The one rule (:attr:`CommandResult.link_failed`): only a failed link ends an upload; a
    point refused or failed is that point's, the next one goes on in a fresh call (its pose written
    anew, whatever was staged before)."""
    if result.ok:
        return Verdict.CREATED
    if result.link_failed:
        return Verdict.LINK_FAILED
    if result.stopped_by_operator:
        return Verdict.STOPPED
    code = result.reason.code if result.reason is not None else ""
    return Verdict.REFUSED if code in REFUSAL_CODES else Verdict.FAILED


@dataclass
class UploadCounts:
    """The points counted: created, refused, failed; the first refused or failed point's words."""

    good: int = 0
    refused: int = 0
    failed: int = 0
    first_failure: str = ""

    def count(self, result: CommandResult) -> Verdict:
        """Count ``result`` and say how it reads."""
        seen = verdict(result)
        if seen is Verdict.CREATED:
            self.good += 1
        elif seen is Verdict.REFUSED or seen is Verdict.FAILED:
            if seen is Verdict.REFUSED:
                self.refused += 1
            else:
                self.failed += 1
            self.first_failure = self.first_failure or result.message
        return seen
