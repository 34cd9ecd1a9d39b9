"""``teachpad-cli run PROJECT ...``: check a plan, upload its points, run it guarded.

:func:`register` adds ``run`` to the main parser; the helpers are :mod:`app.cli.points`'s, the
exit codes :class:`app.cli.exit_codes.ExitCode`. Segment numbers on the command line and in
messages count from 1. ``run`` checks the plan first (the GUI's checks, reach by the robot model
of ``--robot-profile`` included, and that model against the controller's joints and pose, as in
the GUI): errors refuse to run (USAGE; FAILED when the only errors are points or path samples the
robot model cannot reach, or a model the controller contradicts). A project file cannot know what the
controller holds, so ``run`` creates every point its plan uses before the first move and guards
each segment with :class:`app.points.guard.PointGuard` (restart canary, points re-created right
before the move, arrival verified after it). ``--no-upload`` skips the uploads: the operator
answers for the controller's points; the arrival check stays. A failed or interrupted run prints
the ``--from`` / ``--from-loop`` that resumes it.

    run PROJECT [--plan NAME] [--loops N] [--from K] [--from-loop I] [--single]
                [--no-upload] [--check] [--safety PROFILE] [--robot-profile FILE]
                [--max-speed MM_S]
"""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path
from typing import Any

from app.cli.context import PROG, CliContext, stop_on_a_fresh_link
from app.cli.exit_codes import ExitCode, exit_code_for
from app.cli.points import (
    _PROJECT_HELP,
    _endpoint,
    _fmt_time,
    _limits,
    _link_code,
    _load,
    _monitor_only,
    _ProgressLine,
    _save,
)
from app.errors import CommandRefused, InvalidInput, TeachPadError
from app.link.client import RobotClient
from app.models import CommandResult, Pose
from app.plan.checks import IssueCode, PlanIssue, PlanLimits, ReachCheck, check_plan
from app.plan.estimates import estimate_plan, segment_timeouts
from app.plan.geometry import PointLike
from app.plan.issue_kind import IssueKind
from app.plan.runner import PlanRunner, RunEvent, RunOutcome, RunProgress, RunState
from app.plan.segments import Plan
from app.points.guard import PointGuard, PointMismatch, PointNotCreated
from app.points.ledger import PointLedger
from app.points.lock import live_owner
from app.points.project_model import Project
from app.protocol.enums import MoveStatus
from app.safety.envelope import Envelope
from app.safety.profile import load_profile
from app.view3d.agreement import compare_model, model_issue
from app.view3d.kinematics import ArmModel
from app.view3d.profile import DEFAULT_PROFILE_FILE, default_profile
from app.view3d.profile import load_profile as load_robot_profile
from app.view3d.reach import ReachChecker

#: The checks that say the robot (its model) cannot do the plan: a refusal (FAILED), where the
#: other errors say the plan or the command line is wrong (USAGE). A model the controller
#: contradicts (app/view3d/agreement.py) is one of them: the plan may be fine, the model is not.
REACH_CODES = frozenset({IssueCode.UNREACHABLE, IssueCode.JOINT_LIMIT, IssueCode.MODEL_DISAGREES})


def register(subparsers: Any) -> None:
    """Add ``run`` to the main parser's subcommands."""
    r = subparsers.add_parser("run", help="run a plan of a project on the controller (function 3)")
    r.add_argument("project", type=Path, help=_PROJECT_HELP)
    r.add_argument("--plan", help="plan name (needed when the project has several)")
    r.add_argument("--loops", type=int, help="loop count (default: the plan's; 0 = until stopped)")
    r.add_argument(
        "--from",
        type=int,
        default=1,
        dest="from_segment",
        metavar="K",
        help="start at segment K (counting from 1)",
    )
    r.add_argument("--from-loop", type=int, default=1, metavar="I", help="start in loop I (to resume)")
    r.add_argument("--single", action="store_true", help="run segment K only")
    r.add_argument(
        "--no-upload",
        action="store_true",
        help="do not create the plan's points on the controller before and during the run: "
        "the operator is responsible for the controller holding exactly the project's "
        "points (the arrival pose is still checked after each segment)",
    )
    r.add_argument("--upload", action="store_true", help=argparse.SUPPRESS)  # the default now (old scripts)
    r.add_argument("--check", action="store_true", help="check and estimate only; do not connect or move")
    r.add_argument(
        "--safety",
        metavar="PROFILE",
        help="a safety profile (.safety.json): the plan must stay in its envelope (default: the "
        "envelope in force, the GUI's)",
    )
    r.add_argument(
        "--robot-profile",
        type=Path,
        metavar="FILE",
        help="the robot model (.json, as the GUI's 3D view loads it) whose reach every point "
        "and the sampled path must stay in (default: the simulator's arm, "
        f"{DEFAULT_PROFILE_FILE}); a model whose kinematics disagree with the controller's "
        "joints and pose refuses the run",
    )
    r.add_argument(
        "--max-speed",
        type=float,
        default=PlanLimits().max_speed,
        metavar="MM_S",
        help="highest speed a segment may have (default %(default)g mm/s)",
    )
    r.set_defaults(handler=cmd_run)


def _pick_plan(ctx: CliContext, project: Project, name: str | None) -> Plan | None:
    if name is not None:
        try:
            return project.plan(name)
        except InvalidInput as exc:
            ctx.error(str(exc))
            return None
    if len(project.plans) == 1:
        return project.plans[0]
    if not project.plans:
        ctx.error("the project has no plans")
    else:
        ctx.error(
            f"the project has {len(project.plans)} plans ({', '.join(project.plan_names())}): "
            "choose one with --plan"
        )
    return None


def _upload_plan_points(
    ctx: CliContext,
    args: argparse.Namespace,
    project: Project,
    guard: PointGuard,
    plan_ids: list[int],
    client: Any,
) -> ExitCode:
    """Create the plan's points before the first move; records the history in the project."""
    ctx.print(f"uploading the plan's {len(plan_ids)} point(s): {', '.join(map(str, plan_ids))}")
    try:
        guard.ensure(client, plan_ids)
    except KeyboardInterrupt:
        ctx.error("interrupted while uploading: not running")
        return ExitCode.INTERRUPTED
    except PointNotCreated as exc:
        ctx.error(f"{exc}: not running")
        return ExitCode.FAILED
    except TeachPadError as exc:
        return _link_code(ctx, exc, "cannot upload the plan's points")
    finally:
        project.record_upload(sorted(guard.uploaded), _endpoint(client))
    owner = live_owner(args.project)
    if owner is None:
        _save(ctx, project, args.project)  # the upload history; a failed save does not stop the run
    ctx.print(f"uploaded {len(guard.uploaded)} point(s)")
    return ExitCode.OK


def _points_lost(error: BaseException | None) -> bool:
    return isinstance(error, CommandRefused) and error.status.code == MoveStatus.BAD_END_POINT


def _run_numbers(args: argparse.Namespace, plan: Plan) -> tuple[PlanLimits, int, int]:
    """The run's limits, loop count and 0-based start segment from the command line; numbers
    the plan cannot take raise :class:`InvalidInput`."""
    loops = plan.loops if args.loops is None else args.loops
    start = args.from_segment - 1
    limits = PlanLimits(max_speed=args.max_speed)
    if loops < 0:
        raise InvalidInput("--loops must be >= 0 (0 = until stopped)")
    if not 0 <= start < len(plan):
        raise InvalidInput(f"--from {args.from_segment}: the plan has segments 1..{len(plan)}")
    if args.from_loop < 1 or (loops and args.from_loop > loops):
        raise InvalidInput(f"--from-loop {args.from_loop}: the run has loops 1..{loops}")
    return limits, loops, start


def _envelope(ctx: CliContext, args: argparse.Namespace) -> Envelope | None:
    """``--safety``'s envelope, else the envelope in force (the GUI's, app/cli/guard.py), else none."""
    if getattr(args, "safety", None):
        return load_profile(args.safety).envelope
    if ctx.safety is not None:
        return ctx.safety.envelope
    return None


def _connect_for_run(ctx: CliContext) -> tuple[RobotClient, Pose] | ExitCode:
    """The controller's client and its pose (the plan's checks start from it), or the exit code
    of a link that failed."""
    try:
        client = ctx.client
        return client, client.read_pose()
    except TeachPadError as exc:
        return _link_code(ctx, exc, "cannot read the robot's pose")


def cmd_run(ctx: CliContext) -> ExitCode:
    """``run PROJECT [--plan NAME] ...``: check, upload, run guarded with a progress line."""
    args = ctx.args
    if not args.check and _monitor_only(ctx, args, "run"):
        return ExitCode.FAILED
    project = _load(ctx, args.project, _limits(ctx))
    if project is None:
        return ExitCode.USAGE
    plan = _pick_plan(ctx, project, args.plan)
    if plan is None:
        return ExitCode.USAGE
    try:
        limits, loops, start = _run_numbers(args, plan)
    except InvalidInput as exc:
        ctx.error(str(exc))
        return ExitCode.USAGE
    try:
        envelope = _envelope(ctx, args)
        model = robot_model(getattr(args, "robot_profile", None))
    except TeachPadError as exc:
        ctx.error(str(exc))
        return ExitCode.USAGE
    client: RobotClient | None = None
    pose: Pose | None = None
    if not args.check:
        connected = _connect_for_run(ctx)
        if isinstance(connected, ExitCode):
            return connected
        client, pose = connected
    reach = reach_check(model, pose)
    if ctx.caps is not None:
        plan = _capped(ctx, plan, ctx.caps.speed)
    return _run(ctx, args, project, plan, client, pose, limits, loops, start, envelope, reach)


def robot_model(path: Path | str | None) -> ArmModel:
    """The robot model in ``path`` (the default profile when None). A file that cannot be used
    raises :class:`~app.view3d.profile.ProfileError` (InvalidInput), naming the file."""
    return ArmModel(default_profile() if path is None else load_robot_profile(path))


def reach_check(model: ArmModel, pose: Pose | None = None) -> ReachCheck:
    """The planner's reach check (``check_plan(..., reach=...)``) of ``model``, as the GUI's 3D
    view builds it; with the controller's ``pose`` (and its joints), the model is compared with
    it first, as in the GUI: a model that disagrees is an error of the whole plan."""
    checker = ReachChecker(model)
    joints = pose.joints if pose is not None else None
    agreement = None if pose is None or joints is None else compare_model(model, joints, pose.xyzabc)
    if agreement is None or agreement.agrees:
        return checker.plan_issues
    disagrees = model_issue(agreement)

    def checks(plan: Plan, ledger: PointLedger, current_pose: PointLike | None) -> list[PlanIssue]:
        return [disagrees, *checker.plan_issues(plan, ledger, current_pose)]

    return checks


class _HaltOnFreshLink:
    """The client the plan runner drives. Its ``stop`` (the runner's halt after Ctrl-C, a
    segment's timeout or an error) is :func:`~app.cli.context.stop_on_a_fresh_link`, as after
    Ctrl-C in ``step`` / ``move``: Ctrl-C may cut the request under way in half, and its late
    answer, on the same link, was read as the stop's ("malformed answer ... an answer to another
    request": the stop said to have failed although it went out)."""

    def __init__(self, client: Any) -> None:
        self._client = client

    def __getattr__(self, name: str) -> Any:  # what the point guard uses: uploads, reads
        return getattr(self._client, name)

    def move_to_point(self, *args: Any, **kwargs: Any) -> CommandResult:
        result: CommandResult = self._client.move_to_point(*args, **kwargs)
        return result

    def stop(self) -> None:
        stop_on_a_fresh_link(self._client)


#: The checks that refuse a valid plan (FAILED): the robot's reach, and the safety envelope (a
#: step or a move out of it is refused with the same code).
REFUSAL_CODES = REACH_CODES | {IssueCode.OUTSIDE_ENVELOPE}


def _refusal_code(errors: list[PlanIssue]) -> ExitCode:
    """Only reach and envelope errors: the robot or the envelope refuses a valid plan (FAILED);
    any other: USAGE."""
    return ExitCode.FAILED if all(i.code in REFUSAL_CODES for i in errors) else ExitCode.USAGE


def _refusal_why(errors: list[PlanIssue], code: ExitCode) -> str:
    if code is not ExitCode.FAILED:
        return ""
    if any(i.code is IssueCode.MODEL_DISAGREES for i in errors):
        return " (the robot model disagrees with the controller)"
    if all(i.code is IssueCode.OUTSIDE_ENVELOPE for i in errors):
        return " (outside the safety envelope)"
    return " (out of the robot model's reach)"


def _capped(ctx: CliContext, plan: Plan, cap: float) -> Plan:
    """``--reduced-speed``: the plan with every segment at most ``cap`` mm/s (said per segment),
    so that its estimates and wait timeouts are the capped run's (the client caps the writes too)."""
    segments = []
    for i, seg in enumerate(plan.segments):
        if seg.speed > cap:
            ctx.warn(
                f"segment {i + 1}: runs at {cap:g} mm/s, the reduced-speed cap (planned {seg.speed:g} mm/s)"
            )
            seg = dataclasses.replace(seg, speed=cap)
        segments.append(seg)
    return dataclasses.replace(plan, segments=segments)


def _refused(
    ctx: CliContext,
    plan: Plan,
    ledger: PointLedger,
    limits: PlanLimits,
    pose: Pose | None,
    start: int,
    loops: int,
    envelope: Envelope | None,
    reach: ReachCheck | None,
) -> ExitCode | None:
    """Check the plan as the GUI does: warnings are said; errors are said and refuse the run
    (the exit code returned), None when the plan may run."""
    issues = check_plan(
        plan, ledger, limits, pose, start_index=start, loops=loops, envelope=envelope, reach=reach
    )
    for issue in issues:
        if issue.kind is IssueKind.WARNING:
            ctx.warn(issue.message)
    errors = [i for i in issues if i.kind is IssueKind.ERROR]
    if not errors:
        return None
    for issue in errors:
        ctx.error(issue.message)
    code = _refusal_code(errors)
    ctx.error(f"plan {plan.name!r} has {len(errors)} error(s){_refusal_why(errors, code)}: not running it")
    return code


def _say_check_only(ctx: CliContext, args: argparse.Namespace, plan_ids: list[int]) -> ExitCode:
    """``--check``: what a run would upload, and that nothing runs."""
    if args.no_upload:
        ctx.print("--no-upload: the controller must already hold the plan's points")
    else:
        ctx.print(f"would upload: {', '.join(map(str, plan_ids))}")
    ctx.print("check only: not running")
    return ExitCode.OK


def _prepare_points(
    ctx: CliContext,
    args: argparse.Namespace,
    project: Project,
    guard: PointGuard,
    plan_ids: list[int],
    client: Any,
) -> ExitCode:
    """Create the plan's points before the first move, or (``--no-upload``) say whose
    responsibility they are."""
    if not args.no_upload:
        return _upload_plan_points(ctx, args, project, guard, plan_ids, client)
    ctx.warn(
        f"--no-upload: nothing is uploaded; the controller must hold exactly this project's points "
        f"{', '.join(map(str, plan_ids))} (the operator's responsibility)"
    )
    return ExitCode.OK


def _drive(
    ctx: CliContext,
    args: argparse.Namespace,
    plan: Plan,
    ledger: PointLedger,
    client: Any,
    pose: Pose | None,
    loops: int,
    start: int,
    guard: PointGuard,
) -> RunOutcome:
    """Run the plan through the guard with a progress line of the segment under way."""
    line = _ProgressLine(ctx.out)

    def progress(p: RunProgress) -> None:
        if p.event is RunEvent.SEGMENT_STARTED:
            line.show(f"{p.text}: {p.message}")

    runner = PlanRunner(
        plan,
        loops=loops,
        start=start,
        start_loop=args.from_loop,
        single=args.single,
        timeouts=segment_timeouts(plan, ledger, pose),
        progress=progress,
    )
    try:
        return runner.run(_HaltOnFreshLink(client), guard)
    finally:
        line.done()


def _resume_command(
    args: argparse.Namespace, project: Project, plan: Plan, loops: int, outcome: RunOutcome
) -> str | None:
    """The command line that resumes a run that ended early, None when it cannot be resumed."""
    if outcome.resume_from is None:
        return None
    resume = f"--from {outcome.resume_from + 1}"
    if outcome.resume_loop and outcome.resume_loop > 1:
        resume += f" --from-loop {outcome.resume_loop}"
    plan_arg = f" --plan {plan.name!r}" if len(project.plans) > 1 else ""
    loops_arg = f" --loops {loops}" if args.loops is not None else ""
    return f"{PROG} run {args.project}{plan_arg} {resume}{loops_arg}"


def _say_why_stopped(ctx: CliContext, outcome: RunOutcome) -> None:
    """A run that did not finish: its state and message, and what the error means for the points."""
    ctx.error(f"{outcome.state.value}: {outcome.message}")
    if _points_lost(outcome.error):
        # "bad end point id": the controller does not hold the segment's points (restarted?)
        ctx.error(
            "the controller does not hold the plan's points (restarted?); resume without "
            "--no-upload so that they are created first"
        )
    if isinstance(outcome.error, PointMismatch | PointNotCreated):
        ctx.error("nothing further was sent; the robot is where the message above says")


def _unfinished_code(outcome: RunOutcome) -> ExitCode:
    if outcome.interrupted:
        return ExitCode.INTERRUPTED
    if isinstance(outcome.error, TeachPadError):
        return exit_code_for(outcome.error)
    return ExitCode.FAILED


def _run(
    ctx: CliContext,
    args: argparse.Namespace,
    project: Project,
    plan: Plan,
    client: Any,
    pose: Pose | None,
    limits: PlanLimits,
    loops: int,
    start: int,
    envelope: Envelope | None = None,
    reach: ReachCheck | None = None,
) -> ExitCode:
    ledger = project.ledger
    refused = _refused(ctx, plan, ledger, limits, pose, start, loops, envelope, reach)
    if refused is not None:
        return refused
    est = estimate_plan(plan, ledger, pose, loops=loops)
    ctx.print(
        f"plan {plan.name!r}: {len(plan)} segment(s), {est.loop_length:.1f} mm per loop, "
        f"loops {loops or 'until stopped'}, about {_fmt_time(est.total_time)}"
    )
    plan_ids = list(dict.fromkeys(pid for seg in plan.segments for pid in seg.point_ids))
    if args.check:
        return _say_check_only(ctx, args, plan_ids)
    guard = PointGuard({p.id: p for p in ledger}, refresh=not args.no_upload)
    code = _prepare_points(ctx, args, project, guard, plan_ids, client)
    if code != ExitCode.OK:
        return code
    outcome = _drive(ctx, args, plan, ledger, client, pose, loops, start, guard)
    if outcome.state is RunState.FINISHED:
        ctx.print(f"done: {outcome.segments_done} segment(s)")
        return ExitCode.OK
    _say_why_stopped(ctx, outcome)
    resume = _resume_command(args, project, plan, loops, outcome)
    if resume is not None:
        ctx.print(f"to resume: {resume}")
    return _unfinished_code(outcome)
