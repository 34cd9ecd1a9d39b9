"""``teachpad-cli support-bundle OUT.zip``, ``audit`` and ``roles``: offline commands.

None talks to the controller. ``roles`` lets an administrator set or clear the engineer's and
administrator's passwords (read from the terminal, or one line of stdin; never an argument,
so they stay out of the shell history) and see which are set; once the administrator has a
password, a change needs it (asked for, or ``TEACHPAD_ADMIN_PASSWORD``) and every change and
refusal is audited, as in the GUI. ``support-bundle`` writes the zip of
:mod:`app.safety.bundle` (versions, the CLI's connection settings plus an optional settings
file with secrets removed, the project, the safety profile, the audit trail of the last days,
log files, recorded traffic). ``audit`` prints or exports the audit trail, filtered, and says how
many of the records shown are writes whose outcome is unknown (result ``unknown``: the answer or
the controller's outcome was never recorded, or the controller's outcome could not be told).

Once the administrator has a password, the CLI's writing commands act as a role
(app/cli/guard.py); the role store itself is guarded by the administrator's password here.
"""

from __future__ import annotations

import getpass
import io
import json
import os
import sys
from pathlib import Path
from typing import Any

from app.cli.context import CliContext
from app.cli.exit_codes import ExitCode
from app.cli.format import parse_moment, parse_positive_int
from app.errors import InvalidInput
from app.event_store import EventStore, default_events_dir, export_line
from app.points.atomic import atomic_write_bytes
from app.safety.audit import AuditLog, FsyncPolicy, default_audit_dir
from app.safety.audit_chain import verify_chain
from app.safety.audit_read import AuditFilter, AuditRecord, ReadStats, Result, export_csv, query, result_label
from app.safety.bundle import DEFAULT_DAYS, write_support_bundle
from app.safety.roles import Role, RoleStore, WrongPassword, default_store_path

#: What ``audit --result`` filters by: a command's outcome (done, refused, stopped, unknown), a
#: plain write's answer (ok, failed), blocked (``pending`` exists only inside the file).
AUDIT_RESULTS = (
    Result.DONE,
    Result.REFUSED,
    Result.STOPPED,
    Result.UNKNOWN,
    Result.OK,
    Result.FAILED,
    Result.BLOCKED,
)

ADMIN_NOTE = (
    "Once the administrator has a password, teachpad-cli's writing commands act as a role "
    "(--role, TEACHPAD_ROLE, TEACHPAD_PASSWORD; see teachpad-cli --help); without one it acts as "
    "administrator."
)

ADMIN_PASSWORD_ENV = "TEACHPAD_ADMIN_PASSWORD"
ROLES_NOTE = (
    "Once the administrator has a password, changing the role store needs it: asked for in a "
    f"terminal, or taken from the environment variable {ADMIN_PASSWORD_ENV} (scripts). Every "
    "change, and every refusal, is recorded in the audit trail (never a password). The "
    "administrator's own password can be changed, not removed (anyone could then set a new one)."
)


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "support-bundle",
        help="write a zip for an integrator (offline)",
        description="Write a support bundle. " + ADMIN_NOTE,
    )
    p.add_argument("out", type=Path, metavar="OUT.zip", help="the zip file to write")
    p.add_argument("--project", type=Path, help="the project file to include")
    p.add_argument("--profile", type=Path, help="the safety profile to include")
    p.add_argument("--settings", type=Path, help="a JSON settings file (secrets are removed)")
    p.add_argument("--audit-dir", type=Path, help=f"audit trail folder (default {default_audit_dir()})")
    p.add_argument("--log-dir", type=Path, help="a folder of log files to include")
    p.add_argument(
        "--events-dir", type=Path, help=f"the GUI's saved event log (default {default_events_dir()})"
    )
    p.add_argument("--traffic", type=Path, help="a text file of recorded Modbus traffic")
    p.add_argument(
        "--days",
        type=parse_positive_int,
        default=DEFAULT_DAYS,
        help="how many days of records, counted back from now (default %(default)s)",
    )
    p.set_defaults(handler=cmd_support_bundle)

    p = subparsers.add_parser(
        "audit",
        help="show or export the audit trail (offline)",
        description="Show the audit trail. " + ADMIN_NOTE,
    )
    p.add_argument("--audit-dir", type=Path, help=f"audit trail folder (default {default_audit_dir()})")
    p.add_argument(
        "--from",
        dest="start",
        type=parse_moment,
        metavar="WHEN",
        help="first moment, local time YYYY-MM-DD[THH:MM]",
    )
    p.add_argument(
        "--to",
        dest="end",
        type=parse_moment,
        metavar="WHEN",
        help="last moment, local time YYYY-MM-DD[THH:MM]",
    )
    p.add_argument("--role", help="only records of this role (operator, engineer, administrator)")
    p.add_argument("--command", dest="command_text", metavar="TEXT", help="part of the command text")
    p.add_argument(
        "--result",
        choices=AUDIT_RESULTS,
        help="only records with this result: a command's outcome as the controller told it (done, "
        "refused -- shown refused:CODE with its status code --, stopped, unknown: sent, and what the "
        "controller did is not known), or a plain write's answer (ok, failed), or blocked",
    )
    p.add_argument("--csv", type=Path, metavar="OUT", help="write CSV instead of printing")
    p.add_argument(
        "--verify",
        action="store_true",
        help="check the chain of hashes that links each record to the one before it, across files, "
        "and say where it breaks (a record changed or removed); exit code 1 if it does",
    )
    p.set_defaults(handler=cmd_audit)

    p = subparsers.add_parser(
        "roles",
        help="set or clear the GUI's role passwords (offline)",
        description="Passwords of TeachPad's roles. " + ADMIN_NOTE + " " + ROLES_NOTE,
    )
    p.add_argument("--store", type=Path, help=f"the role store (default {default_store_path()})")
    p.add_argument(
        "--audit-dir",
        type=Path,
        help=f"where the change is audited (default {default_audit_dir()}; with --store: the audit "
        "folder beside it)",
    )
    rsub = p.add_subparsers(dest="roles_command", metavar="ACTION", required=True)
    r = rsub.add_parser("show", help="which roles have a password, and the idle time")
    r.set_defaults(handler=cmd_roles)
    for name, text in (
        ("set-password", "set a role's password (asked for, not an argument)"),
        ("clear-password", "remove a role's password (nobody can log in as it)"),
    ):
        r = rsub.add_parser(name, help=text)
        r.add_argument("role", choices=("engineer", "administrator"), help="the role")
        r.set_defaults(handler=cmd_roles)


def _read_text_lines(path: Path, what: str) -> list[str]:
    try:
        return path.read_text(encoding="utf-8", errors="replace").splitlines()
    except OSError as exc:
        raise InvalidInput(f"{what} {path.name} cannot be read ({exc.strerror or exc})") from None


def cmd_support_bundle(ctx: CliContext) -> ExitCode:
    args = ctx.args
    settings: dict[str, Any] = {"cli connection": _settings_dict(ctx.settings)}
    if args.settings is not None:
        try:
            settings["settings file"] = json.loads(args.settings.read_text(encoding="utf-8"))
        except (OSError, ValueError) as exc:
            raise InvalidInput(
                f"settings file {args.settings.name} cannot be used ({str(exc)[:80]})"
            ) from None
    for name in ("project", "profile"):
        path = getattr(args, name)
        if path is not None and not path.is_file():
            raise InvalidInput(f"{name} file {str(path)[:60]} does not exist")
    traffic = None if args.traffic is None else _read_text_lines(args.traffic, "traffic file")
    manifest = write_support_bundle(
        args.out,
        settings=settings,
        project=args.project,
        profile=args.profile,
        audit_dir=args.audit_dir or default_audit_dir(),
        events=[export_line(e) for e in EventStore(args.events_dir, keep_days=args.days).recent()],
        log_dir=args.log_dir,
        traffic=traffic,
        days=args.days,
    )
    ctx.print(f"wrote {args.out} ({len(manifest.files)} files)")
    for note in manifest.left_out:
        ctx.print(f"  left out: {note}")
    return ExitCode.OK


def _settings_dict(settings: Any) -> dict[str, Any]:
    fields = getattr(settings, "__dataclass_fields__", {})
    return {name: getattr(settings, name) for name in fields}


def cmd_audit(ctx: CliContext) -> ExitCode:
    """Print (or write as CSV) the records that match, then say how many of them are writes whose
    answer was never recorded (``unknown``: the controller may or may not have acted on them)."""
    args = ctx.args
    if args.verify:
        return _verify(ctx, args.audit_dir or default_audit_dir())
    flt = AuditFilter(
        start=args.start, end=args.end, role=args.role, command=args.command_text, result=args.result
    )
    stats = ReadStats()
    records = query(args.audit_dir or default_audit_dir(), flt, stats)
    unknown = unknown_count(records)
    if args.csv is not None:
        buffer = io.StringIO(newline="")
        n = export_csv(records, buffer)
        # UTF-8 with a BOM: Excel on a Chinese Windows reads it as UTF-8 (without, as GBK)
        try:
            atomic_write_bytes(args.csv, buffer.getvalue().encode("utf-8-sig"))
        except OSError as exc:  # name the file asked for, not the temp file beside it
            raise OSError(exc.errno, exc.strerror, str(args.csv)) from None
        ctx.print(f"wrote {n} records to {args.csv} ({unknown} unknown)")
    else:
        _print_table(ctx, records)
    if unknown and args.result != Result.UNKNOWN:
        ctx.warn(
            f"{unknown} write(s) with result unknown: sent, and what the controller did is not known "
            "(check the robot); list them with --result unknown"
        )
    if stats.skipped:
        ctx.warn(f"{stats.skipped} damaged line(s) skipped")
    return ExitCode.OK


def _print_table(ctx: CliContext, records: list[AuditRecord]) -> None:
    """One line per record, the role and result columns as wide as their widest entry (the
    CLI's own role, "administrator (cli)", is wider than the GUI's)."""
    labels = [result_label(r) for r in records]
    role_width = max((len(r.role) for r in records), default=0)
    result_width = max((len(label) for label in labels), default=0)
    for r, label in zip(records, labels, strict=True):
        extra = f" - {r.detail}" if r.detail else ""
        ctx.print(f"{r.host_time}  {r.role:<{role_width}}  {label:<{result_width}}  {r.command}{extra}")


def _verify(ctx: CliContext, directory: Path) -> ExitCode:
    """``audit --verify``: where the chain of hashes breaks (every file, whatever the filters)."""
    report = verify_chain(directory)
    for chain_break in report.breaks:
        ctx.print(f"chain broken at {chain_break}")
    ctx.print(f"{directory}: {report.summary()}")
    return ExitCode.OK if report.intact else ExitCode.FAILED


def unknown_count(records: list[AuditRecord]) -> int:
    """Writes among ``records`` sent whose answer was never recorded (the reader's
    ``ReadStats.unknown`` counts them in every file read; this, in the records shown)."""
    return sum(1 for r in records if r.result == Result.UNKNOWN)


def _read_password() -> str:
    if sys.stdin.isatty():
        first = getpass.getpass("new password: ")
        if getpass.getpass("again: ") != first:
            raise InvalidInput("the two passwords differ; nothing changed")
        return first
    return sys.stdin.readline().rstrip("\r\n")


def _admin_password() -> str | None:
    """The administrator's password for a change: the environment variable, else asked for in a
    terminal; None: neither (a script without the variable)."""
    given = os.environ.get(ADMIN_PASSWORD_ENV)
    if given is not None:
        return given
    if sys.stdin.isatty():
        return getpass.getpass("administrator password: ")
    return None


def _roles_audit(args: Any) -> AuditLog:
    directory = args.audit_dir or (default_audit_dir() if args.store is None else args.store.parent / "audit")
    return AuditLog(directory, role="administrator (cli)", fsync=FsyncPolicy.ALWAYS)


def _change_roles(store: RoleStore, role: Role, action: str, audit: AuditLog) -> None:
    """Change the role store as :class:`app.safety.session.SafetySession` does in the GUI: the
    administrator's password first (when one is set), audited either way."""
    what = f"{'clear' if action == 'clear-password' else 'set'} the {role.text} password"
    if store.has_password(Role.ADMINISTRATOR):
        password = _admin_password()
        if password is None:
            why = f"the administrator password is needed: run it in a terminal, or set {ADMIN_PASSWORD_ENV}"
            audit.record_refused(what, why)
            raise WrongPassword(f"{what}: not done; {why}")
        if not store.verify(Role.ADMINISTRATOR, password):
            audit.record_refused(what, "wrong administrator password")
            raise WrongPassword(f"{what}: not done; wrong administrator password")
    if action == "clear-password":
        if role is Role.ADMINISTRATOR:
            why = "the administrator password can be changed, not removed (anyone could then set it)"
            audit.record_refused(what, why)
            raise InvalidInput(f"{what}: not done; {why}")
        store.clear_password(role, by=Role.ADMINISTRATOR)
        audit.record("action", what)
        return
    changed = store.has_password(role)
    store.set_password(role, _read_password(), by=Role.ADMINISTRATOR)
    audit.record("action", f"{'change' if changed else 'set'} the {role.text} password")


def cmd_roles(ctx: CliContext) -> ExitCode:
    args = ctx.args
    store = RoleStore(args.store or default_store_path())
    if args.roles_command == "show":
        for role in (Role.ENGINEER, Role.ADMINISTRATOR):
            ctx.print(f"{role.text:<13} {'password set' if store.has_password(role) else 'no password'}")
        ctx.print(f"idle lock     {store.idle_timeout:g} s")
        return ExitCode.OK
    role = Role.parse(args.role)
    with _roles_audit(args) as audit:
        _change_roles(store, role, args.roles_command, audit)
        if audit.last_error is not None:
            ctx.warn(f"the change is not in the audit trail: {audit.last_error}")
    done = "removed" if args.roles_command == "clear-password" else "set"
    ctx.print(f"password of the {role.text} role {done}")
    return ExitCode.OK
