"""``teachpad-cli move``'s point guard: the host's copy of the points a move uses.

A temp point cannot be read back from the controller (PROTOCOL.md section 7), the controller
forgets them all when it restarts, and any other master may overwrite one: a move that trusts the
id alone sends the arm to whatever the controller holds under it. The CLI's ledger for ``move``
is a project file, the one ``run`` and ``points upload`` use (``--project FILE``). With it the
move goes through :class:`app.points.guard.PointGuard`, the guard of the plan runs:

1. the end point (and an arc's middle point) is created again from the project's copy right
   before the move (:meth:`PointGuard.before_segment`; a point the controller refuses, or one the
   project does not have, stops the command before anything moves, exit 1 / 2);
2. after the move reports done, the pose is read and compared with the project's end point
   (:func:`check_arrival`, the guard's 1 mm rule): an arm that stopped elsewhere is a failure
   said in words (exit 1), never "done".

The restart canary is not written: a single move has nothing to guard across moves, and a token
written here would read as a controller restart to a TeachPad on the same controller.

Without ``--project`` the CLI holds no copy of the point, so neither its path (the safety
envelope, app/cli/guard.py) nor its arrival can be checked: with a keep-in box or keep-out zones
in the envelope (a fresh install's has a keep-in box) the move is refused before anything is
sent; with none, the arm goes to the controller's copy, the command prints where it stopped and
says on stderr that the point was not checked (a warning; the exit code stays the move's).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from app.cli.context import CliContext
from app.cli.points import _limits
from app.errors import CommandRefused, InvalidInput
from app.link.client import RobotClient
from app.models import Pose
from app.points.guard import PointGuard, PointMismatch, PointNotCreated
from app.points.project import load_project

__all__ = ["UNCHECKED_WARNING", "check_arrival", "move_guard", "prepare_points"]

#: What ``move`` says (stderr) after a move whose point it had no copy of.
UNCHECKED_WARNING = (
    "P{id} was not checked: without --project the arm went to whatever the controller holds under "
    "that id (give the project holding the point to create it from its copy and check the arrival)"
)


def move_guard(ctx: CliContext) -> PointGuard | None:
    """The guard of ``move --project FILE`` (None without it); :class:`InvalidInput` for a
    project that cannot be read (a usage error: nothing is sent)."""
    path: Path | None = getattr(ctx.args, "project", None)
    if path is None:
        return None
    if ctx.args.via == ctx.args.id:  # the client says so too, but only after the creates went out
        raise InvalidInput("the arc's middle point must differ from its end point")
    project = load_project(path, _limits(ctx))
    missing = [f"P{pid}" for pid in point_ids(ctx.args) if project.ledger.get(pid) is None]
    if missing:  # refused before anything is sent
        raise InvalidInput(f"{path}: the project has no point {', '.join(missing)}")
    return PointGuard({p.id: p for p in project.ledger}, canary_gv=None)


def point_ids(args: argparse.Namespace) -> list[int]:
    """The points the move uses: its end point, then an arc's middle point."""
    return [args.id] if args.via is None else [args.id, args.via]


def prepare_points(guard: PointGuard, client: RobotClient, args: argparse.Namespace) -> None:
    """Create the move's points again from the project's copy, right before the move; a point
    the controller refuses is :class:`PointNotCreated` naming it (exit 1, nothing moved)."""
    ids = point_ids(args)
    sent = len(guard.created)
    try:
        guard.before_segment(client, ids)
    except CommandRefused as exc:
        point = guard.point(ids[len(guard.created) - sent])  # the first one not created
        raise PointNotCreated(
            f"the controller refused to create {point.label} before the move: {exc}; the arm was not moved",
            params={"point": point.label, "cause": str(exc)},
        ) from None


def check_arrival(guard: PointGuard, pose: Pose, end_id: int) -> None:
    """:class:`PointMismatch` (exit 1) when ``pose`` is farther than 1 mm from the project's end point."""
    mismatch = guard.check_arrival(pose, end_id)
    if mismatch is not None:
        raise PointMismatch(
            mismatch.point,
            mismatch.pose,
            mismatch.distance,
            then="The move failed; check the point and the robot before moving again",
        )
