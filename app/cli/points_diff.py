"""``teachpad-cli points diff A B``: what changed between two projects (or a project and a CSV).

Each of A and B is a project (``*.teachpad.json``) or a points CSV (a name ending ``.csv``).
Points are matched by id (:mod:`app.points.diff`); one line per point that differs, then a
summary line::

    A  cell1.teachpad.json: 12 points
    B  export.csv: 13 points
    added    P14 'drop'
    removed  P3 'pick'
    moved    P5 'place'  0.200 mm  0.00°  (dx +0.200 dy +0.000 dz +0.000)
    tool     P7          tool 200 -> 3
    4 differences over 0.1 mm / 0.1° (9 points are the same)

Exit codes (the ``diff`` convention, within :class:`~app.cli.exit_codes.ExitCode`):
0 (OK) the same within the tolerances, 1 (FAILED) they differ, 2 (USAGE) a file that cannot be
read or is malformed, or a bad tolerance: one line on stderr, nothing compared.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from app.cli.context import CliContext
from app.cli.exit_codes import ExitCode
from app.errors import InvalidInput
from app.points.diff import (
    DEFAULT_TOL_DEG,
    DEFAULT_TOL_MM,
    ChangeKind,
    PointChange,
    PointsDiff,
    diff_points,
    load_points_source,
    signed_mm,
)
from app.points.fields import PointLimits
from app.points.point import TempPoint

__all__ = ["change_line", "cmd_points_diff", "register"]

_SOURCE_HELP = "a project (.teachpad.json) or a points CSV (.csv)"


def _tolerance(text: str) -> float:
    """An argparse type: a finite number >= 0 (argparse words the refusal)."""
    import argparse

    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not (math.isfinite(value) and value >= 0):
        raise argparse.ArgumentTypeError(f"{text!r}: a tolerance is a number >= 0")
    return value


def register(psub: Any) -> None:
    """Add ``diff`` to the ``points`` command's actions (``app/cli/points.py`` calls it)."""
    p = psub.add_parser(
        "diff",
        help="compare the points of two projects or CSV files: added, removed, moved (exit 1: they differ)",
    )
    p.add_argument("a", type=Path, metavar="A", help=_SOURCE_HELP)
    p.add_argument("b", type=Path, metavar="B", help=_SOURCE_HELP)
    p.add_argument(
        "--tol-mm",
        type=_tolerance,
        default=DEFAULT_TOL_MM,
        help=f"a point moved farther than this (mm) is listed (default {DEFAULT_TOL_MM:g})",
    )
    p.add_argument(
        "--tol-deg",
        type=_tolerance,
        default=DEFAULT_TOL_DEG,
        help=f"a point turned more than this (degrees) is listed (default {DEFAULT_TOL_DEG:g})",
    )
    p.set_defaults(handler=cmd_points_diff)


def _limits(ctx: CliContext) -> PointLimits:
    lo = getattr(ctx.args, "point_id_min", None)
    hi = getattr(ctx.args, "point_id_max", None)
    settings = ctx.settings
    return PointLimits(
        settings.point_id_min if lo is None else lo, settings.point_id_max if hi is None else hi
    )


def _read(ctx: CliContext, path: Path, limits: PointLimits) -> list[TempPoint] | None:
    """The file's points; None after one error line (a malformed or unreadable file)."""
    try:
        return load_points_source(path, limits)
    except InvalidInput as exc:  # FileFormatError names the file, the row / place and the field
        ctx.error(str(exc))
    except OSError as exc:
        ctx.error(f"{path}: cannot read it ({exc.strerror or exc})")
    return None


def cmd_points_diff(ctx: CliContext) -> ExitCode:
    args = ctx.args
    limits = _limits(ctx)
    a = _read(ctx, args.a, limits)
    b = _read(ctx, args.b, limits) if a is not None else None
    if a is None or b is None:
        return ExitCode.USAGE
    diff = diff_points(a, b, tol_mm=args.tol_mm, tol_deg=args.tol_deg)
    ctx.print(f"A  {args.a}: {len(a)} points")
    ctx.print(f"B  {args.b}: {len(b)} points")
    for change in diff.changes:
        ctx.print(change_line(change))
    ctx.print(summary_line(diff))
    return ExitCode.FAILED if diff.differ else ExitCode.OK


def change_line(change: PointChange) -> str:
    """One point's line: its kind, its label, and how far it moved / which tool it has now."""
    head = f"{change.kind.value:<8} {change.point.label}"
    if change.kind is ChangeKind.MOVED:
        dx, dy, dz = change.delta
        head += (
            f"  {change.distance_mm:.3f} mm  {change.rotation_deg:.2f}°"
            f"  (dx {signed_mm(dx)} dy {signed_mm(dy)} dz {signed_mm(dz)})"
        )
    if change.tool_changed:
        assert change.before is not None and change.after is not None
        head += f"  tool {change.before.tool} -> {change.after.tool}"
    return head


def summary_line(diff: PointsDiff) -> str:
    tolerances = f"{diff.tol_mm:g} mm / {diff.tol_deg:g}°"
    if not diff.differ:
        return f"the same within {tolerances} ({diff.same} points)"
    n, same = len(diff.changes), diff.same
    points = "point is" if same == 1 else "points are"
    return f"{n} difference{'s' if n != 1 else ''} over {tolerances} ({same} {points} the same)"
