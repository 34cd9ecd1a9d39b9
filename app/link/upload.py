"""An upload of many temp points (case 2.2), run in chunks on the worker thread.

Items ``(id, pose6, tool)`` are checked before the first write and grouped by tool frame (GV245
written once per group). The poses alternate between GV0..GV5 and GV6..GV11 (GV12..GV17 when the
restart canary sits there): :meth:`~app.link.client.RobotClient.upload_points` writes the next
pose while the controller creates the current point. Each chunk is at most
:data:`app.timing.UPLOAD_CHUNK_POINTS` points of one tool or
:data:`app.timing.UPLOAD_CHUNK_SECONDS`; the worker queues the next chunk behind whatever arrived
meanwhile, so polls and queued calls keep flowing. Between two points the
urgent jobs run (stop, cancel, jog release) and a poll goes out when one is due; between two
status reads of the point in flight they run too, so a Stop never waits for a point's result:
its 441 on the main link ends the point in flight as stopped (the host sent the stop itself,
PROTOCOL.md section 7; reported failed, never "created" -- the controller may hold it, as the
point's result was not seen) and the upload ends with its final result at once. A cancel lets
the point in flight finish (no controller stop). From the moment
a stop or a cancel is asked for (the worker's ``halt_count`` grows: the stop line counts the
Stop before it writes 441) until that job runs, nothing more is written: no staging write of the
next pose, no next point; only the point whose writes already went out is waited for.

A failed point ends the upload only when the link failed during it
(:attr:`~app.models.CommandResult.link_failed`: link lost, no answer in time, a malformed
answer -- its outcome is unknown and the link is declared failed). A point the controller
refused (a refused status, or a Modbus exception, which ends that call of ``upload_points``), or
whose result never showed (no acknowledgement, a timeout, an alarm), is reported failed in its own
words and counted as refused or failed; the next chunk goes on with the next point (the CLI's
``points upload`` follows the same rule).
"""

from __future__ import annotations

import functools
import math
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import TypeVar

from app import timing
from app.errors import (
    InvalidInput,
    LinkError,
    ModbusExceptionError,
    ResponseTimeout,
    TeachPadError,
    WriteBlocked,
)
from app.link.client import RobotClient
from app.link.host import WorkerHost
from app.link.types import Operation
from app.models import CommandResult
from app.protocol import registers
from app.protocol.enums import CommandKind, RunCommand
from app.protocol.registers import UPLOAD_POSE_GV, stage_gv_for

__all__ = [
    "UploadItem",
    "Uploader",
    "WorkerUpload",
    "check_upload_items",
    "group_by_tool",
    "refused_before_the_first",
]

_FLOAT32_MAX = 3.4028234663852886e38

UploadItem = tuple[int, tuple[float, ...], int]  # (point id, pose X Y Z A B C, tool frame)
RawItem = tuple[object, tuple[object, ...], object]
T = TypeVar("T")


@dataclass
class WorkerUpload:
    """An upload the worker is sending: its items and how far it got."""

    request_id: int | None
    items: list[UploadItem]  # grouped by tool frame: GV245 is written once per group
    index: int = 0  # items attempted so far
    good: int = 0
    end: str | None = None  # why it ends early ("cancelled", "stopped", "link lost: ..."), once set
    progress_at: float = 0.0  # when uploadProgress was last emitted
    progress_done: int = -1  # the ``done`` it carried
    halts_at_start: int = 0  # the host's count of stops and cancels requested when it began
    refused: int = 0  # points the controller refused (a refused status, a Modbus exception): link kept
    failed: int = 0  # points whose result never showed (no acknowledgement, timeout, alarm): link kept
    first_failure: str = ""  # the first refused or failed point's words, for the final result


def group_by_tool(items: Iterable[T], tool: Callable[[T], int]) -> list[T]:
    """The order points are uploaded in (GV245 is written once per tool frame), the GUI's and the
    CLI's: grouped by ``tool(item)``, stable -- the tools in order of first appearance, each tool's
    points in input order."""
    groups: dict[int, list[T]] = {}
    for item in items:
        groups.setdefault(tool(item), []).append(item)
    return [item for group in groups.values() for item in group]


REFUSAL_CODES = frozenset({"command_refused", "modbus_exception"})  # the controller answered no


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


def check_upload_items(client: RobotClient, raw: Sequence[RawItem]) -> list[UploadItem]:
    """Every item checked (id range, tool, six finite float32 values) before anything is written."""
    lo, hi = client.settings.point_id_min, client.settings.point_id_max
    items: list[UploadItem] = []
    for pid, pose, tool in raw:
        if isinstance(pid, bool) or not isinstance(pid, int) or not lo <= pid <= hi:
            raise InvalidInput(f"point id must be an integer in {lo}..{hi}, got {str(pid)[:20]!r}")
        if isinstance(tool, bool) or not isinstance(tool, int) or not 0 <= tool <= registers.TOOL_NONE:
            raise InvalidInput(
                f"tool frame of point {pid} must be 0..{registers.TOOL_NONE}, got {str(tool)[:20]!r}"
            )
        if len(pose) != 6:
            raise InvalidInput(f"pose of point {pid} needs 6 values, got {len(pose)}")
        values: list[float] = []
        for v in pose:
            if (
                isinstance(v, bool)
                or not isinstance(v, (int, float))
                or not math.isfinite(v)
                or abs(v) > _FLOAT32_MAX
            ):
                raise InvalidInput(f"pose of point {pid}: {str(v)[:20]!r} is not a finite float32")
            values.append(float(v))
        items.append((pid, tuple(values), tool))
    return items


def _chunk_end(items: Sequence[UploadItem], first: int) -> int:
    """Where the chunk that begins at ``first`` ends: at most :data:`app.timing.UPLOAD_CHUNK_POINTS`
    points, all of one tool."""
    tool = items[first][2]
    last = first
    while last < len(items) and last - first < timing.UPLOAD_CHUNK_POINTS and items[last][2] == tool:
        last += 1
    return last


def _count_failure(upload: WorkerUpload, result: CommandResult) -> None:
    """A point that failed on a sound link: the next chunk goes on with the next point in a
    fresh call (its pose written anew, whatever was staged before). Refused only when the
    controller said no (a refused status, a Modbus exception, which ended the batch there); a
    point whose result never showed (no acknowledgement, a timeout, an alarm) failed, its words
    say how."""
    code = result.reason.code if result.reason is not None else ""
    if code in REFUSAL_CODES:
        upload.refused += 1
    else:
        upload.failed += 1
    upload.first_failure = upload.first_failure or result.message


class Uploader:
    """The running upload (one at a time)."""

    def __init__(self, host: WorkerHost, halt_count: Callable[[], int] = lambda: 0) -> None:
        """``halt_count`` (any thread's stops and cancels so far, growing): once it has grown
        since the upload began, a stop or cancel is on its way and nothing more is written."""
        self._host = host
        self._halt_count = halt_count
        self.run: WorkerUpload | None = None
        self._busy = False  # inside a chunk (client.upload_points is running)

    def start(self, raw: list[RawItem]) -> bool:
        """Check and begin; True when chunks are to follow (the worker queues :meth:`step`)."""
        host = self._host
        client = host.client_or_raise()
        if client.settings.monitor_only:
            raise WriteBlocked(f"monitor-only mode: {Operation.UPLOAD_POINTS} was not sent")
        items = group_by_tool(check_upload_items(client, raw), lambda item: item[2])
        if not items:
            host.emit_result(
                CommandResult(
                    RunCommand.CREATE_POINT,
                    None,
                    None,
                    True,
                    "uploaded 0 of 0 points",
                    {"uploaded": 0.0, "total": 0.0},
                )
            )
            return False
        host.jog.leave_teach(host.poller.last_status)
        self.run = WorkerUpload(host.request_id, items, halts_at_start=self._halt_count())
        self._note_progress(self.run, force=True)
        return True

    def step(self) -> bool:
        """One chunk; True if another chunk should be queued."""
        host = self._host
        upload = self.run
        if upload is None or host.closed:
            return False
        if upload.end is None and upload.index < len(upload.items) and host.link_up:
            host.poll_if_due()  # keep the monitor live even if the event loop favours queued calls
            host.run_urgent()
            if upload.end is None and self._halted(upload):
                # a stop that did not end it (refused on the main link) or whose job is not queued
                # yet: ended all the same, the operator asked for a stop
                upload.end = "stopped"
            if upload.end is None and host.link_up and self.run is upload:
                self._chunk(upload)
        if self.run is not upload:
            return False  # ended meanwhile (link lost, closed)
        if upload.end is not None or upload.index >= len(upload.items) or not host.link_up:
            self.finish()
            return False
        return True

    def _chunk(self, upload: WorkerUpload) -> None:
        host = self._host
        client = host.client_or_raise()
        start = time.monotonic()
        first = upload.index
        last = _chunk_end(upload.items, first)
        results, transport_error = self._send_chunk(client, upload, upload.items[first:last], start)
        transport_error = self._tally(upload, first, results, transport_error)
        if transport_error is not None:
            upload.end = upload.end or transport_error
            if host.link_up:  # a link already lost or closed (an urgent job meanwhile) counts no more
                host.supervisor.transport_failed(transport_error)
        self._note_progress(upload)

    def _send_chunk(
        self, client: RobotClient, upload: WorkerUpload, items: Sequence[UploadItem], start: float
    ) -> tuple[list[CommandResult], str | None]:
        """One call of ``upload_points`` for ``items`` (one tool), under the upload's request id:
        its results, and the link's failure before the first point (None: none)."""
        host = self._host
        tool = items[0][2]
        transport_error: str | None = None
        self._busy = True
        outer_id, host.request_id = host.request_id, upload.request_id
        try:
            chunk = [(pid, pose) for pid, pose, _ in items]
            stage_gv = stage_gv_for(host.supervisor.canary_gv)
            results = client.upload_points(
                chunk,
                tool,
                functools.partial(self._between_points, upload, start),
                gv_start=UPLOAD_POSE_GV,
                stage_gv=stage_gv,
                halted=functools.partial(self._halted, upload),  # no staging write, no next point
                between=self._between_reads,
            )
        except (LinkError, ResponseTimeout) as exc:  # before the first point (status read, mode)
            results, transport_error = [], str(exc)
        except ModbusExceptionError as exc:  # refused before the first point (tool frame, status read)
            results = refused_before_the_first((pid for pid, _ in chunk), exc)
        except TeachPadError as exc:
            results = []
            upload.end = upload.end or str(exc)
        finally:
            self._busy = False
            host.request_id = outer_id
        return results, transport_error

    def _between_points(self, upload: WorkerUpload, start: float, done: int, total: int) -> bool:
        """``upload_points``'s progress: the urgent jobs and a due poll run between two points;
        False ends the chunk (the upload ended, the link is down, or the chunk's time is up)."""
        host = self._host
        host.run_urgent()  # stop / pause / cancel / jog release between two points
        if upload.end is not None or not host.link_up or host.closed:
            return False
        host.poll_if_due()
        return host.link_up and time.monotonic() - start < timing.UPLOAD_CHUNK_SECONDS

    def _between_reads(self) -> None:
        """Between two reads of the point in flight (see the module docstring)."""
        host = self._host
        host.run_urgent()  # a stop's main-link 441 ends the point in flight as stopped
        if not host.link_up or host.closed:  # lost or closed by an urgent job: no more reads
            raise LinkError("the link went down while a point was in flight; its outcome is unknown")

    def _tally(
        self, upload: WorkerUpload, first: int, results: list[CommandResult], transport_error: str | None
    ) -> str | None:
        """Each point's result (the chunk began at ``first``) published and counted (good,
        refused, failed); ``transport_error``, or the words of the last point whose link failed
        (its outcome unknown)."""
        host = self._host
        for (point_id, _, _), result in zip(upload.items[first:], results, strict=False):
            upload.index += 1
            if result.ok:
                upload.good += 1
                host.publish_point_uploaded(point_id, True, "", result.unconfirmed)
                continue
            host.publish_point_uploaded(point_id, False, result.message or "failed")
            if result.link_failed:  # its outcome is unknown, the link not to be trusted
                transport_error = result.message
            elif not result.stopped_by_operator:
                _count_failure(upload, result)
        return transport_error

    def _halted(self, upload: WorkerUpload) -> bool:
        """Ending, or a stop or cancel asked for since it began (its job may not have run yet)."""
        return upload.end is not None or self._halt_count() != upload.halts_at_start

    def _note_progress(self, upload: WorkerUpload, *, force: bool = False) -> None:
        now = time.monotonic()
        due = force or now - upload.progress_at >= timing.UPLOAD_PROGRESS_PERIOD
        if upload.index != upload.progress_done and due:
            upload.progress_at = now
            upload.progress_done = upload.index
            self._host.publish_upload_progress(upload.index, len(upload.items))

    def end(self, reason: str) -> None:
        """Ask the running upload to end before its next point (at once when between chunks)."""
        upload = self.run
        if upload is None:
            return
        if upload.end is None:
            upload.end = reason
        if not self._busy:
            self.finish()

    def finish(self) -> None:
        """The batch's final commandFinished (after every pointUploaded), with the upload's request id."""
        upload, self.run = self.run, None
        if upload is None:
            return
        total = len(upload.items)
        self._note_progress(upload, force=True)
        text = f"uploaded {upload.good} of {total} points"
        if upload.refused:
            text += f", {upload.refused} refused"
        if upload.failed:
            text += f", {upload.failed} failed"
        if upload.first_failure and upload.end is None and upload.index >= total:
            # the first failure's words only when every point was tried: one that ended early
            # keeps its "(why)" last, where the GUI reads it (ui/controllers point_sync_state)
            text += f": {upload.first_failure}"
        text += f" ({upload.end})" if upload.end else ""
        details = {
            "uploaded": float(upload.good),
            "attempted": float(upload.index),
            "refused": float(upload.refused),
            "failed": float(upload.failed),
            "total": float(total),
        }
        result = CommandResult(RunCommand.CREATE_POINT, None, None, upload.good == total, text, details)
        self._host.emit_result(result, upload.request_id)
