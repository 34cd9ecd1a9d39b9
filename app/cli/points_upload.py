"""``teachpad-cli points upload``: the points go to the controller the way the GUI's upload sends them.

:func:`staged_upload` drives :meth:`app.link.client.RobotClient.upload_points` (one batch per
tool frame): per point its pose (the first of a batch only), GV200-202 and 440, while the
controller creates it the next point's pose goes into the other pose block -- GV6..GV11, or
GV12..GV17 when the restart canary (:data:`app.protocol.registers.CANARY_GV`) sits there
(:func:`app.protocol.registers.stage_gv_for`) -- so the write fills the controller's latency. The
outcome is an :class:`app.points.upload.UploadReport`. The sending and the reading of each
point's result are the one upload driver's (:mod:`app.link.upload_driver`), the GUI's worker's too;
this module is the CLI's reporting around it (the report, Ctrl-C, the restart canary).

**Restarts** (issue 19): the upload watches the restart canary (:class:`BootWatch`, GV99) the way
the GUI's link does -- it is read every :data:`CANARY_EVERY` points and after the last. A point
counts as *confirmed* (``UploadReport.confirmed``, what the upload record of
:mod:`app.points.upload_record` keeps) only when a read after its result still showed the token. A
changed canary ends the upload as a restart (``UploadReport.boot_lost``), never as "uploaded": a
restart clears GV0..GV99, so a point whose staged pose it wiped was created at (0,0,0,0,0,0); the
points tried since the last good read are created again at their poses on the new boot (the same
point at the same pose: safe to repeat) and proven by a fresh token, and the rest is not sent.
"""

from __future__ import annotations

import random
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from typing import Any, Protocol

from app.connection import ConnectionSettings
from app.errors import TeachPadError
from app.link.types import ControllerIdentity
from app.link.upload_driver import Verdict, batch_end, group_by_tool, send_batch, verdict
from app.models import CommandResult
from app.points.point import TempPoint
from app.points.upload import BootLost, UploadOutcome, UploadReport
from app.points.upload_record import UploadRecord
from app.protocol.registers import CANARY_GV

__all__ = ["CANARY_EVERY", "BootWatch", "open_boot", "staged_upload"]

#: points created between two reads of the restart canary during an upload (and one after the last)
CANARY_EVERY = 8
CHANGED_AGAIN = "the restart canary changed again while they were created"


class CanaryClient(Protocol):
    """The part of ``RobotClient`` the restart canary needs."""

    def read_gv(self, n: int, count: int = 1) -> list[float]: ...

    def write_gv(self, n: int, values: Sequence[float]) -> None: ...


@dataclass
class BootWatch:
    """The restart canary of the boot an upload runs on: ``token`` in GV ``gv``."""

    gv: int
    token: float
    every: int = CANARY_EVERY

    def read(self, client: CanaryClient) -> float:
        """The canary's value now (the link's errors as they come)."""
        return client.read_gv(self.gv)[0]


def new_token() -> float:
    return float(random.SystemRandom().randint(1, 1 << 23))  # nonzero, exact in float32


def open_boot(
    client: CanaryClient, settings: ConnectionSettings, record: UploadRecord | None, gv: int = CANARY_GV
) -> tuple[BootWatch, UploadRecord, bool]:
    """The boot an upload begins on: ``(watch, record, resumed)``. ``record`` (the one kept beside the
    project) is resumed only when it is provably this boot: the same endpoint, unit, word order and
    canary GV, and the canary reads its token now (:meth:`UploadRecord.same_boot`). Otherwise a
    fresh, empty record: the canary's token is adopted when one is armed (nonzero: any TeachPad
    writes a fresh random one after a restart, a restart clears it), else a fresh one is written."""
    value = client.read_gv(gv)[0]
    place = ControllerIdentity(settings.endpoint, settings.unit, settings.word_order.value, gv, value)
    if record is not None and value != 0.0 and record.same_boot(place):
        return BootWatch(gv, value), record, True
    if value == 0.0:
        value = new_token()
        client.write_gv(gv, [value])
    return BootWatch(gv, value), UploadRecord(replace(place, boot=value)), False


def _tool(point: TempPoint) -> int:
    return point.tool


def staged_upload(
    client: Any,
    points: Sequence[TempPoint],
    progress: Callable[[int, int], object] | None = None,
    watch: BootWatch | None = None,
    proven: Callable[[list[TempPoint]], object] | None = None,
) -> UploadReport:
    """Create ``points`` with ``RobotClient.upload_points``, as the GUI's upload does: in
    :func:`~app.link.upload_driver.group_by_tool` order (GV245 once per tool), the next point's pose
    staged in the spare pose block (:func:`~app.protocol.registers.stage_gv_for` the restart
    canary's GV) while the controller creates the current one.

    ``progress(done, total)`` (``done``: points tried, in that order) before each point and once
    at the end; False from it ends the upload there ("stopped on request"). A point the
    controller refuses (a refusal or a Modbus exception; a batch whose tool frame or status read
    is refused: each of its points) is recorded and the upload goes on; a lost link
    (:attr:`CommandResult.link_failed`) or Ctrl-C ends it, the point under way and the rest
    ``not_attempted``. ``watch``: the restart canary of the boot it began on (see the module
    docstring); without it nothing is ``confirmed`` and a restart goes unseen. ``proven(points)``:
    after each good read of the canary, every point confirmed so far (as sent), for a record kept
    while the upload runs.
    """
    return _StagedUpload(client, group_by_tool(points, _tool), progress, watch, proven).run()


class _StagedUpload:
    """One :func:`staged_upload`: the batches, the progress and the canary reads between points."""

    def __init__(
        self,
        client: Any,
        ordered: list[TempPoint],
        progress: Callable[[int, int], object] | None,
        watch: BootWatch | None,
        proven: Callable[[list[TempPoint]], object] | None = None,
    ) -> None:
        self.client, self.ordered, self.progress, self.watch = client, ordered, progress, watch
        self.tools = [p.tool for p in ordered]
        self.on_proven = proven
        self.results: list[CommandResult] = []  # the batch under way's results so far ...
        self.batch_first = 0  # ... and the index of its first point
        self.report = UploadReport()
        self.total, self.done = len(ordered), 0
        self.told, self.go_on = -1, True
        self.proven = 0  # the points before this index were tried before the canary's last good read
        self.changed: float | None = None  # the canary's value when it was not the token any more
        self.canary_error: str | None = None  # the read of the canary failed

    def tell(self, n: int) -> bool:
        """Once per point; False (from ``progress``, a changed canary): end after this one."""
        if n != self.told and self.go_on:
            self.told = n
            if self.progress is not None:
                self.go_on = self.progress(n, self.total) is not False
            watch = self.watch
            if watch is not None and (n - self.proven >= watch.every or (n == self.total > self.proven)):
                self.go_on = self.canary_holds(n) and self.go_on
        return self.go_on

    def canary_holds(self, n: int) -> bool:
        """Read the canary: True (the points tried so far proven) while it holds the token."""
        assert self.watch is not None
        try:
            value = self.watch.read(self.client)
        except TeachPadError as exc:  # the link, a refusal: the boot cannot be proven any more
            self.canary_error = f"the restart canary GV{self.watch.gv} could not be read: {exc}"
            return False
        if value != self.watch.token:
            self.changed = value
            return False
        self.proven = n
        if self.on_proven is not None:
            self.on_proven(self.confirmed())
        return True

    def confirmed(self) -> list[TempPoint]:
        """The points created ("done", not unconfirmed) before the canary's last good read."""
        report, ordered = self.report, self.ordered
        ok = {o.point_id for o in report.outcomes if o.ok and not o.unconfirmed}
        first = self.batch_first
        ok.update(ordered[first + i].id for i, r in enumerate(self.results) if r.ok and not r.unconfirmed)
        return [p for p in ordered[: self.proven] if p.id in ok]

    def stop_here(self, why: str, *, interrupted: bool = False) -> UploadReport:
        report = self.report
        report.aborted, report.interrupted = why, interrupted
        report.not_attempted = [p.id for p in self.ordered[self.done :]]
        return self.finish()

    def finish(self) -> UploadReport:
        """The report, with what the canary proved and (when it changed) the restart."""
        report = self.report
        report.confirmed = [p.id for p in self.confirmed()]
        if self.changed is not None and self.watch is not None:
            report.aborted = report.aborted or self.why_stopped()
            suspects = self.ordered[self.proven : self.done]
            after = self.ordered[self.proven - 1].id if self.proven else None
            report.boot_lost, interrupted = _repair(
                self.client, self.watch, BootLost(self.changed, after), suspects
            )
            report.interrupted = report.interrupted or interrupted
        return report

    def run(self) -> UploadReport:
        ordered, total = self.ordered, self.total
        while self.done < total:
            done = self.done
            end = batch_end(self.tools, done)
            if not self.tell(done):
                return self.stop_here(self.why_stopped())
            stopped = self.batch(ordered[done:end])
            if stopped is not None:
                return stopped
            if not self.go_on and self.done < total:
                return self.stop_here(self.why_stopped())
        self.tell(total)
        if self.changed is not None or self.canary_error is not None:
            return self.stop_here(self.why_stopped())
        return self.finish()

    def why_stopped(self) -> str:
        if self.changed is not None:
            return "the controller restarted" if self.changed == 0.0 else "the restart canary changed"
        return self.canary_error or "stopped on request"

    def batch(self, batch: list[TempPoint]) -> UploadReport | None:
        """One tool frame's points; the final report when the upload ends here, else None."""
        first = self.done
        results: list[CommandResult] = []
        self.results, self.batch_first = results, first
        report = self.report
        try:
            sent = send_batch(
                self.client,
                [(p.id, p.xyzabc) for p in batch],
                batch[0].tool,
                lambda n, _total: self.tell(first + n),
                canary_gv=CANARY_GV,
                results=results,
            )
        except KeyboardInterrupt:  # keep what was done: the caller records it, the ledger stays true
            _record(report, batch, results)
            self.done += len(results)
            return self.stop_here("interrupted", interrupted=True)
        if sent.link_error is not None:  # before its first point (the status read): nothing of it done
            return self.stop_here(sent.link_error)
        link_lost = _record(report, batch, results)
        if link_lost is not None:
            self.done += len(results) - 1  # that point's outcome is unknown: not attempted
            return self.stop_here(link_lost)
        self.done += len(results)
        return None


def _repair(
    client: Any, watch: BootWatch, lost: BootLost, suspects: Sequence[TempPoint]
) -> tuple[BootLost, bool]:
    """After the canary changed: create the points tried since its last good read again, at their
    poses, on the new boot (a restart may have wiped a staged pose: that point is at zeros), and
    prove them with a token of this boot (a fresh one after a restart, else the value now there).
    They go the way every upload goes (:func:`staged_upload`, the one upload driver's batches: per
    tool frame, a refused point that point's only, a lost link or Ctrl-C the end); the second
    value is True when Ctrl-C ended it."""
    lost = replace(lost, suspects=tuple(p.id for p in suspects))
    if not suspects:
        return lost, False
    token = lost.value
    client.invalidate_cache()  # GV245 (the tool frame) was cleared with the rest: written anew
    try:
        if token == 0.0:
            token = new_token()
            client.write_gv(watch.gv, [token])
        again = _StagedUpload(client, group_by_tool(suspects, _tool), None, None).run()
    except TeachPadError as exc:
        return replace(lost, repair_error=str(exc)), False
    repaired = tuple(o.point_id for o in again.outcomes if o.ok and not o.unconfirmed)
    if again.aborted is not None:  # the link failed, Ctrl-C: the rest not created again
        return replace(lost, repaired=repaired, repair_error=again.aborted), again.interrupted
    try:
        if watch.read(client) != token:
            return replace(lost, repair_error=CHANGED_AGAIN), False
    except TeachPadError as exc:
        return replace(lost, repaired=repaired, repair_error=str(exc)), False
    missing = len(suspects) - len(repaired)
    return replace(lost, repaired=repaired, repair_error=f"{missing} refused" if missing else ""), False


def _record(report: UploadReport, batch: Sequence[TempPoint], results: Sequence[CommandResult]) -> str | None:
    """Each result as an outcome; the text of a link failure (the batch's last result, the point's
    outcome unknown: not recorded) or None. The rule is the GUI upload's
    (:attr:`CommandResult.link_failed`): a Modbus exception or a refused command is that point's
    failure, the link is fine and the upload goes on."""
    for point, result in zip(batch, results, strict=False):
        reason = (result.message or "").removeprefix(f"point {point.id}: ")
        seen = verdict(result)
        if seen is Verdict.CREATED:
            report.outcomes.append(UploadOutcome(point.id, True, sent=point, unconfirmed=result.unconfirmed))
        elif seen is Verdict.LINK_FAILED:  # the one rule (CommandResult.link_failed), as the GUI's upload
            return reason or "the link failed"
        else:
            report.outcomes.append(UploadOutcome(point.id, False, reason or "failed"))
    return None
