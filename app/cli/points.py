"""``teachpad-cli points ...``: the temp points of a project (list, upload, export, import).

:func:`register` adds ``points`` to the main parser (``app/cli/main.py`` lists it with the other
modules' registrars); ``run`` lives in :mod:`app.cli.run_plan`, which shares this module's
helpers. Handlers are ``cmd_*(ctx: CliContext) -> ExitCode`` like every command's (see
:mod:`app.cli.context`); they report their own errors (one line each, a file's errors can be
several) and return the code. ``ctx.client`` is asked for only by commands that talk to the
controller (``points upload``, ``run`` without ``--check``); the context closes it.

Exit codes: :class:`app.cli.exit_codes.ExitCode` (points not on the controller without
``--upload`` is FAILED; a malformed file is USAGE). Global options read when the main parser
defines them: ``point_id_min``, ``point_id_max`` (accepted temp point ids; default: the register
profile's, else 0..10000).

Commands::

    points list   PROJECT
    points upload PROJECT [--ids 1,2,5-9 | --needed]
    points export PROJECT --csv OUT [--no-bom]
    points import PROJECT --csv IN [--merge] [--allow-empty]   # creates PROJECT if missing
    points diff   A B [--tol-mm 0.1] [--tol-deg 0.1]            # app/cli/points_diff.py

Commands that write the project refuse while another TeachPad has it open
(:mod:`app.points.lock`); ``points upload`` in monitor-only mode refuses before it reads the
file.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import math
import time
import unicodedata
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, TextIO

from app import timing
from app.cli import points_diff
from app.cli.context import CliContext
from app.cli.exit_codes import ExitCode, exit_code_for
from app.cli.points_upload import BootWatch, open_boot, staged_upload
from app.errors import InvalidInput, ModbusExceptionError, TeachPadError
from app.link.upload_driver import group_by_tool
from app.points.fields import PointLimits, tool_text
from app.points.ledger import PointLedger
from app.points.ledger_import import EmptyImport, ImportMode
from app.points.lock import live_owner
from app.points.point import FileFormatError, SyncState, TempPoint
from app.points.project import PROJECT_SUFFIX, load_project, read_points_csv, save_project, write_points_csv
from app.points.project_model import Project
from app.points.project_write import ProjectTooLarge
from app.points.upload import BootLost, UploadReport, apply_upload, parse_id_list
from app.points.upload_record import UploadRecord, load_record, record_path, save_record
from app.protocol.registers import CANARY_GV

# The table's members under the names callers imported before the table existed.
EXIT_OK = ExitCode.OK
EXIT_FAILED = ExitCode.FAILED
EXIT_USAGE = ExitCode.USAGE
EXIT_LINK = ExitCode.LINK
EXIT_INTERRUPTED = ExitCode.INTERRUPTED


_PROJECT_HELP = f"the project file ({PROJECT_SUFFIX}, as TeachPad saves it)"
NAME_WIDTH = 20  # terminal columns of the name in ``points list``


def display_width(text: str) -> int:
    """Terminal columns of ``text``: wide (CJK) characters take two, combining marks none."""
    return sum(
        0 if unicodedata.combining(c) else 2 if unicodedata.east_asian_width(c) in "WF" else 1 for c in text
    )


def fit_width(text: str, width: int) -> str:
    """``text`` cut to ``width`` terminal columns (with "…" when cut) and padded to exactly it."""
    if display_width(text) > width:
        out, used = "", 0
        for c in text:
            w = display_width(c)
            if used + w > width - 1:
                break
            out, used = out + c, used + w
        text = out + "…"
    return text + " " * (width - display_width(text))


def register(subparsers: Any) -> None:
    """Add ``points`` (list / upload / export / import) to the main parser's subcommands."""
    points = subparsers.add_parser("points", help="temp points of a project: list, upload, export, import")
    psub = points.add_subparsers(dest="points_command", metavar="ACTION", required=True)

    p = psub.add_parser("list", help="print the points and plans of a project")
    p.add_argument("project", type=Path, help=_PROJECT_HELP)
    p.set_defaults(handler=cmd_points_list)

    p = psub.add_parser("upload", help="create the project's points on the controller (function 2)")
    p.add_argument("project", type=Path, help=_PROJECT_HELP)
    group = p.add_mutually_exclusive_group()
    group.add_argument("--ids", help="ids to upload, e.g. 1,2,5-9 (default: all)")
    group.add_argument(
        "--needed",
        action="store_true",
        help="only points the upload record of this controller boot does not hold (resume)",
    )
    p.set_defaults(handler=cmd_points_upload)

    p = psub.add_parser("export", help="write the project's points to a CSV file")
    p.add_argument("project", type=Path, help=_PROJECT_HELP)
    p.add_argument(
        "--csv",
        type=Path,
        required=True,
        dest="csv_path",
        metavar="OUT",
        help="the CSV file to write (mm, degrees)",
    )
    p.add_argument("--no-bom", action="store_true", help="write UTF-8 without a byte order mark")
    p.set_defaults(handler=cmd_points_export)

    p = psub.add_parser("import", help="read points from a CSV file into the project")
    p.add_argument("project", type=Path, help=_PROJECT_HELP)
    p.add_argument(
        "--csv",
        type=Path,
        required=True,
        dest="csv_path",
        metavar="IN",
        help="the CSV file to read (mm, degrees)",
    )
    p.add_argument(
        "--merge",
        action="store_true",
        help="update and add points, keep the others (default: replace all points)",
    )
    p.add_argument(
        "--allow-empty",
        action="store_true",
        help="let a CSV without rows replace (delete) all points of the project",
    )
    p.set_defaults(handler=cmd_points_import)

    points_diff.register(psub)


# --- helpers ------------------------------------------------------------------------------------


def _limits(ctx: CliContext) -> PointLimits:
    """The accepted temp point ids: the global options when a parser defines them, else the
    connection settings' (the register profile's, or the defaults)."""
    lo = getattr(ctx.args, "point_id_min", None)
    hi = getattr(ctx.args, "point_id_max", None)
    settings = ctx.settings
    return PointLimits(
        settings.point_id_min if lo is None else lo, settings.point_id_max if hi is None else hi
    )


def _load(ctx: CliContext, path: Path, limits: PointLimits) -> Project | None:
    try:
        return load_project(path, limits)
    except FileFormatError as exc:
        ctx.error(str(exc))
        return None


def _endpoint(client: Any) -> str:
    settings = getattr(client, "settings", None)
    endpoint = getattr(settings, "endpoint", None)
    return endpoint if isinstance(endpoint, str) else "controller"


def _monitor_only(ctx: CliContext, args: argparse.Namespace, what: str) -> bool:
    """True (after saying so) when --monitor-only forbids ``what``; checked before any file I/O."""
    if getattr(args, "monitor_only", False):
        ctx.error(f"{what} writes to the controller: refused in monitor-only mode (nothing read or written)")
        return True
    return False


def _save(ctx: CliContext, project: Project, path: Path) -> bool:
    problem = _save_problem(project, path)
    if problem is not None:
        ctx.error(f"{path}: {problem}")
    return problem is None


def _save_problem(project: Project, path: Path) -> str | None:
    """Save ``project`` to ``path``; None when it was saved, else why not ("not saved: ...")."""
    owner = live_owner(path)
    if owner is not None:
        return (
            f"not saved: the project is open in a TeachPad ({owner.text}); "
            "close it there or make the change there"
        )
    try:
        save_project(project, path)
    except ProjectTooLarge as exc:  # refused before the write: never a file TeachPad cannot open
        return f"not saved: {exc}"
    except OSError as exc:
        return f"could not save: {exc}"
    return None


def _link_code(ctx: CliContext, exc: TeachPadError, what: str) -> ExitCode:
    ctx.error(f"{what}: {exc}")
    return exit_code_for(exc)


def _fmt_time(seconds: float) -> str:
    if math.isinf(seconds):
        return "until stopped"
    if math.isnan(seconds):
        return "unknown"
    minutes, sec = divmod(round(seconds), 60)
    return f"{minutes} min {sec:02d} s" if minutes else f"{seconds:.1f} s"


class _ProgressLine:
    """One self-overwriting line on a terminal, one line per report otherwise."""

    def __init__(self, stream: TextIO) -> None:
        self.stream = stream
        self.tty = bool(getattr(stream, "isatty", lambda: False)())
        self.width = 0

    def show(self, text: str) -> None:
        if self.tty:
            self.stream.write("\r" + text + " " * max(0, self.width - len(text)))
            self.width = len(text)
        else:
            self.stream.write(text + "\n")
        self.stream.flush()

    def done(self) -> None:
        if self.tty and self.width:
            self.stream.write("\n")
            self.stream.flush()
        self.width = 0


def _upload(
    ctx: CliContext,
    points: Sequence[TempPoint],
    client: Any,
    watch: BootWatch | None,
    proven: Callable[[list[TempPoint]], object] | None,
) -> UploadReport:
    line = _ProgressLine(ctx.out)
    ordered = group_by_tool(points, lambda p: p.tool)

    def progress(done: int, total: int) -> None:
        if done < total:
            line.show(f"uploading {done + 1}/{total}: {ordered[done].label}")

    try:
        return staged_upload(client, ordered, progress=progress, watch=watch, proven=proven)
    finally:
        line.done()


def _say_upload(ctx: CliContext, report: UploadReport, total: int) -> None:
    """What happened on the controller, in the order it happened (what was kept comes after)."""
    lost = report.boot_lost
    if lost is None:
        ctx.print(
            f"uploaded {report.ok_count} point(s)" + (f" of {total}" if report.ok_count != total else "")
        )
    unconfirmed = [o.point_id for o in report.outcomes if o.ok and o.unconfirmed]
    if unconfirmed:
        shown = ",".join(map(str, unconfirmed[:20])) + (",..." if len(unconfirmed) > 20 else "")
        ctx.print(
            f"{len(unconfirmed)} of them unconfirmed: the controller reported no error but its "
            f"command status did not change (GV291 not writable): {shown}"
        )
    for outcome in report.failed:
        ctx.error(f"P{outcome.point_id}: {outcome.reason}")
    if lost is not None:
        ctx.error(boot_lost_text(lost, report, total))
    elif report.aborted:
        left = ",".join(str(i) for i in report.not_attempted)
        ctx.error(f"upload stopped ({report.aborted}); not attempted: {left}")


def _id_text(ids: Sequence[int]) -> str:
    return ",".join(f"P{i}" for i in ids[:20]) + (",..." if len(ids) > 20 else "")


def boot_lost_text(lost: BootLost, report: UploadReport, total: int) -> str:
    """The words for an upload the controller restarted under (or whose canary changed)."""
    if lost.restarted:
        what = "the controller restarted during the upload"
        gone = "it forgot every temp point"
    else:
        what = (
            f"the restart canary GV{CANARY_GV} changed during the upload (another host wrote it: "
            "another master, or a restart it armed again)"
        )
        gone = "what was uploaded before cannot be proven on the controller"
    where = f" (after P{lost.after})" if lost.after is not None else ""
    text = f"{what}{where}: {gone}, the {len(report.confirmed)} point(s) uploaded before it among them"
    if lost.suspects:  # sent around it: one may have been created at a wiped (zero) pose
        text += f"; {_id_text(lost.suspects)}, sent around it, "
        if lost.repaired and not lost.repair_error:
            text += "were created again at their poses after it"
        else:
            text += (
                f"were created again after it: {_id_text(lost.repaired) or 'none'} "
                f"({lost.repair_error}; the others may be at wrong poses on the controller)"
            )
    left = report.not_attempted
    text += f"; not sent after it: {_id_text(left)}" if left else "; nothing else was left to send"
    return text + f". Upload the {total} again: the upload record of the old boot is void, --needed sends all"


def _upload_code(report: UploadReport) -> ExitCode:
    if report.interrupted:
        return ExitCode.INTERRUPTED
    if report.boot_lost is not None:
        return ExitCode.FAILED
    if report.aborted:
        return ExitCode.LINK
    return ExitCode.OK if report.all_ok else ExitCode.FAILED


# --- points ------------------------------------------------------------------------------------


def cmd_points_list(ctx: CliContext) -> ExitCode:
    """``points list PROJECT``."""
    args = ctx.args
    project = _load(ctx, args.project, _limits(ctx))
    if project is None:
        return ExitCode.USAGE
    ctx.print(f"{project.name}: {len(project.ledger)} point(s), {len(project.plans)} plan(s)")
    for p in project.ledger:
        pose = " ".join(f"{v:9.3f}" for v in p.xyzabc)
        state = p.sync.text + (f" ({p.sync_error})" if p.sync_error else "")
        last = project.upload_history.get(p.id)
        if last is not None:  # history: what this host did, not what the controller holds now
            state += f" (last uploaded {last.time} to {last.endpoint})"
        ctx.print(f"{p.id:6d}  {fit_width(p.name, NAME_WIDTH)} {pose}  {tool_text(p.tool):14s} {state}")
    for plan in project.plans:
        ctx.print(f"plan {plan.name!r}: {len(plan)} segment(s), loops {plan.loops or 'until stopped'}")
    return ExitCode.OK


def cmd_points_upload(ctx: CliContext) -> ExitCode:
    """``points upload PROJECT [--ids ... | --needed]``; saves the upload history and the upload
    record (:mod:`app.points.upload_record`) the next ``--needed`` resumes from."""
    args = ctx.args
    if _monitor_only(ctx, args, "points upload"):
        return ExitCode.FAILED
    project = _load(ctx, args.project, _limits(ctx))
    if project is None:
        return ExitCode.USAGE
    points = _chosen(ctx, project.ledger, args)
    if isinstance(points, ExitCode):
        return points
    if not points and not args.needed:
        ctx.print("nothing to upload")
        return ExitCode.OK
    where = record_path(args.project)
    old = _load_record(ctx, where)
    try:
        client = ctx.client
        watch, record, resumed = _open_boot(ctx, client, old)
        if args.needed:
            points = _needed(ctx, project.ledger, record if resumed else None)
        if not points:
            ctx.print("nothing to upload")
            return ExitCode.OK
        keeper = None if record is None else _RecordKeeper(where, record, points)
        report = _upload(ctx, points, client, watch, None if keeper is None else keeper.proven)
        project.record_upload([o.point_id for o in report.outcomes if o.ok], _endpoint(client))
    except TeachPadError as exc:
        return _link_code(ctx, exc, "cannot upload")
    apply_upload(project.ledger, report)
    record_problem = _keep_record(where, keeper, report)
    project_problem = _save_problem(project, args.project)
    _say_upload(ctx, report, len(points))
    return _say_kept(ctx, report, args.project, project_problem, record_problem) or _upload_code(report)


def _chosen(ctx: CliContext, ledger: PointLedger, args: argparse.Namespace) -> list[TempPoint] | ExitCode:
    """The points ``--ids`` names (USAGE after saying why when it is bad), else all of them (also
    for ``--needed``: which of them are needed is known once the controller's boot is)."""
    if not args.ids:
        return list(ledger)
    try:
        ids = parse_id_list(args.ids)
    except InvalidInput as exc:
        ctx.error(str(exc))
        return ExitCode.USAGE
    missing = [i for i in ids if i not in ledger]
    if missing:
        ctx.error(f"no point with id {', '.join(map(str, missing))} in {args.project}")
        return ExitCode.USAGE
    return [ledger.point(i) for i in ids]


def _needed(ctx: CliContext, ledger: PointLedger, record: UploadRecord | None) -> list[TempPoint]:
    """``--needed``: the points the upload record of this very boot does not hold at their present
    pose and tool frame (those it holds are "on controller"); all of them without such a record."""
    if record is not None:
        held = [p.id for p in ledger if record.holds(p)]
        for point_id in held:
            ledger.set_sync(point_id, SyncState.ON_CONTROLLER)
        if held:
            ctx.print(
                f"{len(held)} point(s) already on the controller (the upload record of this boot of it): "
                "not sent again"
            )
    return ledger.needing_upload()


def _load_record(ctx: CliContext, where: Path) -> UploadRecord | None:
    try:
        return load_record(where)
    except FileFormatError as exc:
        ctx.warn(f"{exc}; it is not used (every point is sent)")
        return None


class _RecordKeeper:
    """The upload record while the upload runs: the points about to be sent leave it first (the
    controller's copy of them is about to change), each good read of the canary adds what it
    proved, written every :data:`app.timing.UPLOAD_RECORD_PERIOD` at most -- so even a killed
    upload resumes from what the controller confirmed."""

    def __init__(self, where: Path, record: UploadRecord, points: Sequence[TempPoint]) -> None:
        self.where, self.record = where, record
        self.before = {p.id: held for p in points if (held := record.points.pop(p.id, None)) is not None}
        self.saved_at = time.monotonic()

    def proven(self, confirmed: list[TempPoint]) -> None:
        self.record.confirm(confirmed)
        now = time.monotonic()
        if now - self.saved_at >= timing.UPLOAD_RECORD_PERIOD:
            self.saved_at = now
            with contextlib.suppress(OSError):  # said at the end, when the last write fails too
                save_record(self.where, self.record)

    def finish(self, report: UploadReport) -> None:
        """The record after ``report``: the confirmed points as sent, the points not sent as they
        were; after a restart nothing of it holds any more (no token: void)."""
        record = self.record
        if report.boot_lost is not None:
            record.points.clear()
            record.identity = dataclasses.replace(record.identity, boot=None)
            return
        sent = {o.point_id: o.sent for o in report.outcomes if o.sent is not None}
        record.confirm([point for i in report.confirmed if (point := sent.get(i)) is not None])
        # the first one not attempted (under way at Ctrl-C or a lost link) may have gone out
        for point_id in report.not_attempted[1:]:
            held = self.before.get(point_id)
            if held is not None:
                record.points[point_id] = held


def _open_boot(
    ctx: CliContext, client: Any, old: UploadRecord | None
) -> tuple[BootWatch | None, UploadRecord | None, bool]:
    """:func:`~app.cli.points_upload.open_boot`; a controller that refuses the restart canary's GV
    (a Modbus exception) gets the upload without it, said: no restart seen, no record kept."""
    try:
        return open_boot(client, ctx.settings, old)
    except ModbusExceptionError as exc:
        ctx.warn(
            f"the restart canary GV{CANARY_GV} cannot be used ({exc}): a controller restart during the "
            "upload would go unseen"
        )
        return None, None, False


def _keep_record(where: Path, keeper: _RecordKeeper | None, report: UploadReport) -> str | None:
    """The record after ``report``, written; why it was not (None: it was)."""
    if keeper is None:
        return f"without the restart canary GV{CANARY_GV} nothing proves what the controller holds"
    keeper.finish(report)
    try:
        save_record(where, keeper.record)
    except OSError as exc:
        return exc.strerror or str(exc)
    return None


def _say_kept(
    ctx: CliContext, report: UploadReport, path: Path, project_problem: str | None, record_problem: str | None
) -> ExitCode | None:
    """What was kept of the upload on this computer, after what happened on the controller; FAILED
    when the project could not be saved (None: the upload's own code stands)."""
    held = f"the {report.ok_count} point(s) uploaded are on the controller"
    if record_problem is None:
        record = "the upload record beside it was kept (--needed will not send them again)"
    else:
        record = (
            f"the upload record could not be kept either ({record_problem}): --needed will send them again"
        )
    if project_problem is not None:
        ctx.error(
            f"{path}: {project_problem}. {held.capitalize()}, but the project file is as it was "
            f"before this upload (its upload history does not show it); {record}"
        )
        return ExitCode.FAILED
    if record_problem is not None:
        ctx.warn(
            f"{record_path(path)}: no upload record was kept ({record_problem}): {held} "
            "and the project was saved, but a later --needed will send them again"
        )
    return None


def cmd_points_export(ctx: CliContext) -> ExitCode:
    """``points export PROJECT --csv OUT``."""
    args = ctx.args
    project = _load(ctx, args.project, _limits(ctx))
    if project is None:
        return ExitCode.USAGE
    try:
        write_points_csv(args.csv_path, project.ledger, bom=not args.no_bom)
    except OSError as exc:
        ctx.error(f"{args.csv_path}: could not write: {exc}")
        return ExitCode.FAILED
    ctx.print(f"wrote {len(project.ledger)} point(s) to {args.csv_path}")
    return ExitCode.OK


def cmd_points_import(ctx: CliContext) -> ExitCode:
    """``points import PROJECT --csv IN [--merge] [--allow-empty]``; the project is saved only if
    all rows are good; a CSV without rows does not replace all points unless ``--allow-empty``."""
    args = ctx.args
    limits = _limits(ctx)
    if args.project.exists():
        project = _load(ctx, args.project, limits)
        if project is None:
            return ExitCode.USAGE
    else:
        name = args.project.name.removesuffix(".json").removesuffix(".teachpad")
        project = Project(name=name, ledger=PointLedger((), limits))
    try:
        points = read_points_csv(args.csv_path, limits)
        report = project.ledger.import_points(
            points,
            ImportMode.MERGE if args.merge else ImportMode.REPLACE,
            allow_empty=getattr(args, "allow_empty", False),
        )
    except EmptyImport as exc:
        ctx.error(f"{args.csv_path}: {exc}; nothing changed (pass --allow-empty to do it)")
        return ExitCode.USAGE
    except InvalidInput as exc:
        ctx.error(str(exc))
        return ExitCode.USAGE
    if not _save(ctx, project, args.project):
        return ExitCode.FAILED
    ctx.print(f"imported {len(points)} point(s) into {args.project}: {report.text}")
    for plan in project.plans:
        missing = sorted(i for i in plan.point_ids() if i not in project.ledger)
        if missing:
            ctx.warn(f"plan {plan.name!r} uses points that are gone: {', '.join(map(str, missing))}")
    return ExitCode.OK
