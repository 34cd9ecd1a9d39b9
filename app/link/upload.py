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

The per-batch sending and the reading of each point's result are the one upload driver's
(:mod:`app.link.upload_driver`), shared with the CLI; this module is the worker's reporting around
it (chunks, urgent jobs between points, its progress -- each point, the count -- under the
upload's ticket, the final result).
"""

from __future__ import annotations

import functools
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

from app import timing
from app.errors import InvalidInput, LinkError, TeachPadError, WriteBlocked
from app.link.client import RobotClient
from app.link.host import UploadLink
from app.link.progress import PointUploaded, UploadProgress
from app.link.types import Operation
from app.link.upload_driver import UploadCounts, Verdict, batch_end, group_by_tool, send_batch
from app.models import CommandResult
from app.protocol import registers
from app.protocol.enums import RunCommand

__all__ = [
    "UploadItem",
    "Uploader",
    "WorkerUpload",
    "check_upload_items",
]

_FLOAT32_MAX = 3.4028234663852886e38

UploadItem = tuple[int, tuple[float, ...], int]  # (point id, pose X Y Z A B C, tool frame)
RawItem = tuple[object, tuple[object, ...], object]


@dataclass
class WorkerUpload:
    """An upload the worker is sending: its items and how far it got."""

    request_id: int | None
    items: list[UploadItem]  # grouped by tool frame: GV245 is written once per group
    index: int = 0  # items attempted so far
    end: str | None = None  # why it ends early ("cancelled", "stopped", "link lost: ..."), once set
    progress_at: float = 0.0  # when its UploadProgress was last published
    progress_done: int = -1  # the ``done`` it carried
    halts_at_start: int = 0  # the host's count of stops and cancels requested when it began
    #: created, refused (a refused status, a Modbus exception) and failed (no acknowledgement,
    #: timeout, alarm) points, link kept; the first refused or failed point's words
    tally: UploadCounts = field(default_factory=UploadCounts)


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


class Uploader:
    """The running upload (one at a time)."""

    def __init__(self, host: UploadLink, halt_count: Callable[[], int] = lambda: 0) -> None:
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
        host.leave_teach()
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
        last = batch_end([tool for _, _, tool in upload.items], first, timing.UPLOAD_CHUNK_POINTS)
        results, transport_error = self._send_chunk(client, upload, upload.items[first:last], start)
        transport_error = self._tally(upload, first, results, transport_error)
        if transport_error is not None:
            upload.end = upload.end or transport_error
            if host.link_up:  # a link already lost or closed (an urgent job meanwhile) counts no more
                host.link_failed(transport_error)
        self._note_progress(upload)

    def _send_chunk(
        self, client: RobotClient, upload: WorkerUpload, items: Sequence[UploadItem], start: float
    ) -> tuple[list[CommandResult], str | None]:
        """One call of ``upload_points`` for ``items`` (one tool), under the upload's request id:
        its results, and the link's failure before the first point (None: none)."""
        host = self._host
        self._busy = True
        outer_id, host.request_id = host.request_id, upload.request_id
        try:
            batch = send_batch(
                client,
                [(pid, pose) for pid, pose, _ in items],
                items[0][2],
                functools.partial(self._between_points, upload, start),
                canary_gv=host.canary_gv,
                halted=functools.partial(self._halted, upload),  # no staging write, no next point
                between=self._between_reads,
            )
        except TeachPadError as exc:
            upload.end = upload.end or str(exc)
            return [], None
        finally:
            self._busy = False
            host.request_id = outer_id
        return batch.results, batch.link_error

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
            seen = upload.tally.count(result)
            if seen is Verdict.CREATED:
                point = PointUploaded(point_id, True, "", result.unconfirmed)
            else:
                point = PointUploaded(point_id, False, result.message or "failed")
            host.publish_progress(upload.request_id, point)
            if seen is Verdict.LINK_FAILED:  # its outcome is unknown, the link not to be trusted
                transport_error = result.message
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
            self._host.publish_progress(upload.request_id, UploadProgress(upload.index, len(upload.items)))

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
        """The batch's final commandFinished (after every PointUploaded), with the upload's request id."""
        upload, self.run = self.run, None
        if upload is None:
            return
        total, tally = len(upload.items), upload.tally
        self._note_progress(upload, force=True)
        text = f"uploaded {tally.good} of {total} points"
        if tally.refused:
            text += f", {tally.refused} refused"
        if tally.failed:
            text += f", {tally.failed} failed"
        if tally.first_failure and upload.end is None and upload.index >= total:
            # the first failure's words only when every point was tried: one that ended early
            # keeps its "(why)" last, where the GUI reads it (ui/controllers point_sync_state)
            text += f": {tally.first_failure}"
        text += f" ({upload.end})" if upload.end else ""
        details = {
            "uploaded": float(tally.good),
            "attempted": float(upload.index),
            "refused": float(tally.refused),
            "failed": float(tally.failed),
            "total": float(total),
        }
        result = CommandResult(RunCommand.CREATE_POINT, None, None, tally.good == total, text, details)
        self._host.emit_result(result, upload.request_id)
