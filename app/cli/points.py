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

Commands that write the project refuse while another TeachPad has it open
(:mod:`app.points.lock`); ``points upload`` in monitor-only mode refuses before it reads the
file.
"""

from __future__ import annotations

import argparse
import math
import unicodedata
from collections.abc import Sequence
from pathlib import Path
from typing import Any, TextIO

from app.cli.context import CliContext
from app.cli.exit_codes import ExitCode, exit_code_for
from app.cli.points_upload import by_tool, staged_upload
from app.errors import InvalidInput, TeachPadError
from app.points.ledger import EmptyImport, ImportMode, PointLedger
from app.points.lock import live_owner
from app.points.point import FileFormatError, PointLimits, TempPoint, tool_text
from app.points.project import (
    PROJECT_SUFFIX,
    Project,
    ProjectTooLarge,
    load_project,
    read_points_csv,
    save_project,
    write_points_csv,
)
from app.points.upload import UploadReport, apply_upload, parse_id_list

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
    group.add_argument("--needed", action="store_true", help="only points not known to be on the controller")
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
    owner = live_owner(path)
    if owner is not None:
        ctx.error(
            f"{path}: not saved: the project is open in a TeachPad ({owner.text}); "
            "close it there or make the change there"
        )
        return False
    try:
        save_project(project, path)
    except ProjectTooLarge as exc:  # refused before the write: never a file TeachPad cannot open
        ctx.error(f"{path}: not saved: {exc}")
        return False
    except OSError as exc:
        ctx.error(f"{path}: could not save: {exc}")
        return False
    return True


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


def _upload(ctx: CliContext, project: Project, points: Sequence[TempPoint], client: Any) -> UploadReport:
    line = _ProgressLine(ctx.out)
    ordered = by_tool(points)

    def progress(done: int, total: int) -> None:
        if done < total:
            line.show(f"uploading {done + 1}/{total}: {ordered[done].label}")

    try:
        report = staged_upload(client, ordered, progress=progress)
    finally:
        line.done()
    apply_upload(project.ledger, report)
    ctx.print(f"uploaded {report.ok_count} point(s)")
    unconfirmed = [o.point_id for o in report.outcomes if o.ok and o.unconfirmed]
    if unconfirmed:
        shown = ",".join(map(str, unconfirmed[:20])) + (",..." if len(unconfirmed) > 20 else "")
        ctx.print(
            f"{len(unconfirmed)} of them unconfirmed: the controller reported no error but its "
            f"command status did not change (GV291 not writable): {shown}"
        )
    for outcome in report.failed:
        ctx.error(f"P{outcome.point_id}: {outcome.reason}")
    if report.aborted:
        left = ",".join(str(i) for i in report.not_attempted)
        ctx.error(f"upload stopped ({report.aborted}); not attempted: {left}")
    return report


def _upload_code(report: UploadReport) -> ExitCode:
    if report.interrupted:
        return ExitCode.INTERRUPTED
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
    """``points upload PROJECT [--ids ... | --needed]``; saves the upload history."""
    args = ctx.args
    if _monitor_only(ctx, args, "points upload"):
        return ExitCode.FAILED
    project = _load(ctx, args.project, _limits(ctx))
    if project is None:
        return ExitCode.USAGE
    ledger = project.ledger
    if args.ids:
        try:
            ids = parse_id_list(args.ids)
        except InvalidInput as exc:
            ctx.error(str(exc))
            return ExitCode.USAGE
        missing = [i for i in ids if i not in ledger]
        if missing:
            ctx.error(f"no point with id {', '.join(map(str, missing))} in {args.project}")
            return ExitCode.USAGE
        points = [ledger.point(i) for i in ids]
    elif args.needed:
        points = ledger.needing_upload()
    else:
        points = list(ledger)
    if not points:
        ctx.print("nothing to upload")
        return ExitCode.OK
    try:
        client = ctx.client
        report = _upload(ctx, project, points, client)
        project.record_upload([o.point_id for o in report.outcomes if o.ok], _endpoint(client))
    except TeachPadError as exc:
        return _link_code(ctx, exc, "cannot upload")
    if not _save(ctx, project, args.project):
        return ExitCode.FAILED
    return _upload_code(report)


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
