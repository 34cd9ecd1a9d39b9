"""The link's operations as data: one frozen dataclass per request the GUI can make of the link.

``RobotLink.submit(op)`` queues one of these and returns its ticket (the request id every
``CommandResult`` / ``WorkerError`` it causes carries; ``link.track(ticket)`` gives its
:class:`~app.link.link_port.Pending`). The worker runs it through one table, operation type ->
handler (:class:`Handlers`, the worker's, filled by its parts).

Each class says what the queue needs of it (class attributes, not fields):

* ``operation`` -- its name in results and errors (:class:`~app.link.types.Operation`);
* ``kind`` -- the priority class (:class:`JobKind`): URGENT goes before every
  queued job and also between two transactions of a running one (Stop, Pause, Resume, the jog
  release, cancel upload); MOTION is cancelled by a Stop queued after it; PLAIN is neither;
* ``coalesce`` -- a newer op with the same key takes the place of a queued one (the jog press,
  the live jog speed); ``cancels`` -- the coalesce keys an urgent op drops from the queue (a
  release drops a press not yet started);
* ``needs_link`` -- refused with "not connected" when the link is down (a Stop is not: it goes
  over a fresh connection; a release and a cancel need nothing of the link);
* ``tracks_motion`` -- a motion whose outcome RobotLink keeps in ``motions_in_flight``.

Adding an operation: its class here, and its handler in the worker's part that runs it, added to
the table by that part's ``register`` (:class:`~app.link.commands.WorkerCommands`,
:class:`~app.link.motion.MotionCommands`); the caller submits it. Nothing else restates it:
not RobotLink, not the port panels use, not the tests' fake link.
"""

from __future__ import annotations

import dataclasses
import enum
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar, TypeVar

from app.link.types import JogRequest, Operation, StepFrame
from app.protocol import registers
from app.protocol.enums import ProgramMotionMode, TeachFrame, WorkMode
from app.watchlist.entry import WatchEntry

__all__ = [
    "JOG_PRESS",
    "JOG_RATIO",
    "WATCH_LIST",
    "CancelUpload",
    "CreatePoint",
    "GoZero",
    "Handlers",
    "JobKind",
    "JogPress",
    "JogRelease",
    "LinkOp",
    "MoveToPoint",
    "Pause",
    "ReadRegisters",
    "Resume",
    "RunProgram",
    "SetJogRatio",
    "SetMode",
    "SetWatchList",
    "Step",
    "Stop",
    "UploadItem",
    "UploadPoints",
    "WriteWatched",
]

JOG_PRESS = "jog press"  # coalesce key of the jog press
JOG_RATIO = "jog ratio"  # coalesce key of the live jog speed
WATCH_LIST = "watch list"  # coalesce key of the watch list (the newest list is the one read)


class JobKind(enum.Enum):
    """An operation's priority class in the worker's queue (:mod:`app.link.jobs`)."""

    URGENT = "urgent"  # stop / pause / resume / jog release / cancel upload: ahead of everything
    MOTION = "motion"  # cancelled by a stop queued after it
    PLAIN = "plain"


#: One point of an upload: id, pose (x y z a b c), tool frame.
UploadItem = tuple[int, tuple[float, ...], int]


@dataclass(frozen=True)
class LinkOp:
    """The base of every operation (see the module docstring for the class attributes)."""

    operation: ClassVar[str] = "request"
    kind: ClassVar[JobKind] = JobKind.PLAIN
    coalesce: ClassVar[str | None] = None
    cancels: ClassVar[tuple[str, ...]] = ()
    needs_link: ClassVar[bool] = True
    tracks_motion: ClassVar[bool] = False


@dataclass(frozen=True)
class Stop(LinkOp):
    """The operator's Stop (441): written at once on the stop line when there is one, then first
    in the queue; without a link it goes over a fresh connection to the last controller."""

    operation: ClassVar[str] = Operation.STOP
    kind: ClassVar[JobKind] = JobKind.URGENT
    needs_link: ClassVar[bool] = False


@dataclass(frozen=True)
class Pause(LinkOp):
    operation: ClassVar[str] = Operation.PAUSE
    kind: ClassVar[JobKind] = JobKind.URGENT


@dataclass(frozen=True)
class Resume(LinkOp):
    operation: ClassVar[str] = Operation.RESUME
    kind: ClassVar[JobKind] = JobKind.URGENT


@dataclass(frozen=True)
class JogPress(LinkOp):
    """A held jog button (the panel's :class:`~app.link.types.JogRequest`, as it is)."""

    operation: ClassVar[str] = Operation.JOG
    kind: ClassVar[JobKind] = JobKind.MOTION
    coalesce: ClassVar[str | None] = JOG_PRESS

    request: JogRequest

    def __post_init__(self) -> None:
        request = self.request  # a frame given as its number becomes the enum, as the wire needs it
        object.__setattr__(self, "request", dataclasses.replace(request, frame=TeachFrame(request.frame)))


@dataclass(frozen=True)
class JogRelease(LinkOp):
    """The dead-man: speed 0, retried every poll until the controller confirms it."""

    operation: ClassVar[str] = Operation.JOG_RELEASE
    kind: ClassVar[JobKind] = JobKind.URGENT
    cancels: ClassVar[tuple[str, ...]] = (JOG_PRESS, JOG_RATIO)
    needs_link: ClassVar[bool] = False


@dataclass(frozen=True)
class SetJogRatio(LinkOp):
    """The live jog speed (%) of the jog being held."""

    operation: ClassVar[str] = Operation.JOG_SPEED
    kind: ClassVar[JobKind] = JobKind.MOTION
    coalesce: ClassVar[str | None] = JOG_RATIO

    ratio: float


@dataclass(frozen=True)
class Step(LinkOp):
    """An incremental move (function 1)."""

    operation: ClassVar[str] = Operation.STEP
    kind: ClassVar[JobKind] = JobKind.MOTION
    tracks_motion: ClassVar[bool] = True

    frame: StepFrame
    offsets: Sequence[float]
    ext_offsets: Sequence[float] = (0.0,) * registers.NUM_EXTERNAL_AXES
    speed: float = 10.0

    def __post_init__(self) -> None:  # copied now: the caller's list may change after the submit
        object.__setattr__(self, "offsets", tuple(self.offsets))
        object.__setattr__(self, "ext_offsets", tuple(self.ext_offsets))


@dataclass(frozen=True)
class SetMode(LinkOp):
    """Manual / auto / remote (manual ends the jog and teach mode first)."""

    operation: ClassVar[str] = Operation.SET_MODE

    mode: WorkMode


@dataclass(frozen=True)
class GoZero(LinkOp):
    """Go to the zero position: one axis, or all (``axis`` None)."""

    operation: ClassVar[str] = Operation.GO_ZERO
    kind: ClassVar[JobKind] = JobKind.MOTION
    tracks_motion: ClassVar[bool] = True

    axis: int | None
    switch_to_auto: bool = False


@dataclass(frozen=True)
class RunProgram(LinkOp):
    operation: ClassVar[str] = Operation.RUN_PROGRAM
    kind: ClassVar[JobKind] = JobKind.MOTION
    tracks_motion: ClassVar[bool] = True

    program_id: int
    mode: ProgramMotionMode = ProgramMotionMode.SINGLE_RUN
    cycles: int = 1
    speed_ratio: int = 100
    switch_to_auto: bool = False


@dataclass(frozen=True)
class CreatePoint(LinkOp):
    """Case 2.2 for one point: from ``pose`` (None: the current pose)."""

    operation: ClassVar[str] = Operation.CREATE_POINT

    point_id: int
    pose: Sequence[float] | None = None
    tool: int = registers.TOOL_NONE

    def __post_init__(self) -> None:
        if self.pose is not None:
            object.__setattr__(self, "pose", tuple(self.pose))


@dataclass(frozen=True)
class MoveToPoint(LinkOp):
    """Case 3: to temp point ``end_id``, through ``via_id`` when given."""

    operation: ClassVar[str] = Operation.MOVE_TO_POINT
    kind: ClassVar[JobKind] = JobKind.MOTION
    tracks_motion: ClassVar[bool] = True

    end_id: int
    via_id: int | None = None
    orientation_changes: bool = True
    ignore_middle: bool = False
    speed: float = 50.0
    tool: int = registers.TOOL_NONE


@dataclass(frozen=True)
class UploadPoints(LinkOp):
    """Create many temp points, grouped by tool (GV245 once per tool), in chunks; each point is
    reported under its ticket (:mod:`app.link.progress`), the batch by one result. Stop or
    :class:`CancelUpload` end it between two points. ``items`` are (id, pose6, tool), copied here
    and checked in the worker before the first write; :meth:`of` also takes (id, pose6) items with
    one tool for them all."""

    operation: ClassVar[str] = Operation.UPLOAD_POINTS
    kind: ClassVar[JobKind] = JobKind.MOTION

    items: tuple[UploadItem, ...]

    def __post_init__(self) -> None:
        object.__setattr__(self, "items", tuple((pid, tuple(pose), tool) for pid, pose, tool in self.items))

    @classmethod
    def of(
        cls,
        points: Iterable[tuple[int, Sequence[float], int] | tuple[int, Sequence[float]]],
        tool: int = registers.TOOL_NONE,
    ) -> UploadPoints:
        return cls(tuple((p[0], tuple(p[1]), p[2] if len(p) > 2 else tool) for p in points))


@dataclass(frozen=True)
class CancelUpload(LinkOp):
    """End the running upload after the point in progress, without a controller stop."""

    operation: ClassVar[str] = Operation.CANCEL_UPLOAD
    kind: ClassVar[JobKind] = JobKind.URGENT
    needs_link: ClassVar[bool] = False


@dataclass(frozen=True)
class ReadRegisters(LinkOp):
    """Read whole register blocks (start, count) with 0x03, nothing written; the worker's
    ``progressed`` carries what was read, under its ticket (:class:`~app.link.progress.RegisterBlocks`).
    A block the controller refuses is kept as refused; the others are still read."""

    operation: ClassVar[str] = Operation.READ_REGISTERS

    blocks: tuple[tuple[int, int], ...]

    def __post_init__(self) -> None:
        object.__setattr__(self, "blocks", tuple((int(a), int(n)) for a, n in self.blocks))


@dataclass(frozen=True)
class SetWatchList(LinkOp):
    """The GVs and registers the poller reads after the pose (app/watchlist/plan.py: the fast
    lane every poll, the rest on a slower clock); empty: none, at no cost. ``generation`` is
    carried by every reading of this list (the caller tells old readings from new ones)."""

    operation: ClassVar[str] = "watch list"
    coalesce: ClassVar[str | None] = WATCH_LIST
    needs_link: ClassVar[bool] = False

    entries: tuple[WatchEntry, ...]
    generation: int = 0

    def __post_init__(self) -> None:
        object.__setattr__(self, "entries", tuple(self.entries))


@dataclass(frozen=True)
class WriteWatched(LinkOp):
    """An engineer's write of one watched value (through the client's one write guard: refused
    in monitor-only mode, recorded in the audit trail), read back after."""

    operation: ClassVar[str] = "write watched value"

    entry: WatchEntry
    value: float | int


_Op = TypeVar("_Op", bound=LinkOp)


class Handlers:
    """Operation type -> the function that runs it (worker thread); one entry per class."""

    def __init__(self) -> None:
        self._table: dict[type[LinkOp], Callable[[Any], None]] = {}

    def add(self, op_type: type[_Op], handler: Callable[[_Op], None]) -> None:
        self._table[op_type] = handler

    def __contains__(self, op_type: type[LinkOp]) -> bool:
        return op_type in self._table

    def run(self, op: LinkOp) -> None:
        handler = self._table.get(type(op))
        if handler is None:
            raise TypeError(f"the link has no handler for {type(op).__name__}")
        handler(op)
