"""``teachpad-cli points upload``: the points go to the controller the way the GUI's upload sends them.

:func:`staged_upload` drives :meth:`app.link.client.RobotClient.upload_points` (one batch per
tool frame): per point its pose (the first of a batch only), GV200-202 and 440, while the
controller creates it the next point's pose goes into the other pose block -- GV6..GV11, or
GV12..GV17 when the restart canary (:data:`app.points.guard.CANARY_GV`) sits there
(:func:`app.link.upload.stage_gv_for`) -- so the write fills the controller's latency. The
outcome is an :class:`app.points.upload.UploadReport`, as the point-by-point upload gave.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from app.cli.exit_codes import LINK_ERRORS
from app.errors import ModbusExceptionError
from app.link.upload import UPLOAD_POSE_GV, refused_before_the_first, stage_gv_for
from app.models import CommandResult
from app.points.guard import CANARY_GV
from app.points.point import TempPoint
from app.points.upload import UploadOutcome, UploadReport

__all__ = ["by_tool", "staged_upload"]


def by_tool(points: Sequence[TempPoint]) -> list[TempPoint]:
    """``points`` grouped by tool frame, stable: the tools in order of first appearance."""
    groups: dict[int, list[TempPoint]] = {}
    for p in points:
        groups.setdefault(p.tool, []).append(p)
    return [p for group in groups.values() for p in group]


def staged_upload(
    client: Any, points: Sequence[TempPoint], progress: Callable[[int, int], object] | None = None
) -> UploadReport:
    """Create ``points`` with ``RobotClient.upload_points``, as the GUI's upload does: in
    :func:`by_tool` order (GV245 once per tool), the next point's pose staged in the spare pose
    block (:func:`~app.link.upload.stage_gv_for` the restart canary's GV) while the controller
    creates the current one.

    ``progress(done, total)`` (``done``: points tried, in that order) before each point and once
    at the end; False from it ends the upload there ("stopped on request"). A point the
    controller refuses (a refusal or a Modbus exception; a batch whose tool frame or status read
    is refused: each of its points) is recorded and the upload goes on; a lost link
    (:attr:`CommandResult.link_failed`) or Ctrl-C ends it, the point under way and the rest
    ``not_attempted``.
    """
    ordered = by_tool(points)
    report = UploadReport()
    total, done = len(ordered), 0
    stage_gv = stage_gv_for(CANARY_GV)
    told, go_on = -1, True

    def tell(n: int) -> bool:  # once per point; False (from ``progress``): end after this one
        nonlocal told, go_on
        if progress is not None and n != told and go_on:
            told = n
            go_on = progress(n, total) is not False
        return go_on

    def stop_here(why: str, *, interrupted: bool = False) -> UploadReport:
        report.aborted, report.interrupted = why, interrupted
        report.not_attempted = [p.id for p in ordered[done:]]
        return report

    while done < total:
        end = done
        while end < total and ordered[end].tool == ordered[done].tool:
            end += 1
        batch, first = ordered[done:end], done
        results: list[CommandResult] = []
        if not tell(done):
            return stop_here("stopped on request")
        try:
            client.upload_points(
                [(p.id, p.xyzabc) for p in batch],
                batch[0].tool,
                lambda n, _total, first=first: tell(first + n),
                gv_start=UPLOAD_POSE_GV,
                stage_gv=stage_gv,
                results=results,
            )
        except LINK_ERRORS as exc:  # before its first point (the status read): nothing of it done
            return stop_here(str(exc) or type(exc).__name__)
        except ModbusExceptionError as exc:  # refused before its first point (GV245, the status read)
            results.extend(refused_before_the_first((p.id for p in batch[len(results) :]), exc))
        except KeyboardInterrupt:  # keep what was done: the caller records it, the ledger stays true
            _record(report, batch, results)
            done += len(results)
            return stop_here("interrupted", interrupted=True)
        link_lost = _record(report, batch, results)
        if link_lost is not None:
            done += len(results) - 1  # that point's outcome is unknown: not attempted
            return stop_here(link_lost)
        done += len(results)
        if not go_on and done < total:
            return stop_here("stopped on request")
    tell(total)
    return report


def _record(report: UploadReport, batch: Sequence[TempPoint], results: Sequence[CommandResult]) -> str | None:
    """Each result as an outcome; the text of a link failure (the batch's last result, the point's
    outcome unknown: not recorded) or None. The rule is the GUI upload's
    (:attr:`CommandResult.link_failed`): a Modbus exception or a refused command is that point's
    failure, the link is fine and the upload goes on."""
    for point, result in zip(batch, results, strict=False):
        reason = (result.message or "").removeprefix(f"point {point.id}: ")
        if result.ok:
            report.outcomes.append(UploadOutcome(point.id, True, sent=point, unconfirmed=result.unconfirmed))
        elif result.link_failed:  # the one rule (CommandResult.link_failed), as the GUI's upload
            return reason or "the link failed"
        else:
            report.outcomes.append(UploadOutcome(point.id, False, reason or "failed"))
    return None
