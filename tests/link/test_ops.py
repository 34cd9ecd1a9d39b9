"""The link's operations as data (app/link/ops.py): what each one tells the queue, the worker's one
table, and ``RobotLink.submit`` as the only way in (the per-operation methods are gone)."""

from __future__ import annotations

import inspect
from dataclasses import FrozenInstanceError, dataclass
from typing import Any, ClassVar

import pytest

from app.link import ops
from app.link.jobs import Job, JobQueue
from app.link.link_port import LinkPort
from app.link.ops import (
    JOG_PRESS,
    JOG_RATIO,
    CancelUpload,
    CreatePoint,
    GoZero,
    JobKind,
    JogPress,
    JogRelease,
    LinkOp,
    MoveToPoint,
    Pause,
    ReadRegisters,
    Resume,
    RunProgram,
    SetJogRatio,
    SetMode,
    SetWatchList,
    Step,
    Stop,
    UploadPoints,
    WriteWatched,
)
from app.link.robot_link import RobotLink
from app.link.types import JogRequest, StepFrame
from app.models import CommandResult
from app.protocol.enums import TeachFrame, WorkMode
from app.watchlist.entry import Source, WatchEntry
from tests.ui.fake_link import FakeLink
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    SIGNAL_TIMEOUT_MS,
    connect,
    fast_reconnect_fixture,
    gv_writes,
    link_fixture,
)

pytestmark = pytest.mark.timeout(60)

#: Every operation RobotLink offers, one instance each.
EVERY_OP: tuple[LinkOp, ...] = (
    Stop(),
    Pause(),
    Resume(),
    JogPress(JogRequest(TeachFrame.BASE, 0, 1, 20.0)),
    JogRelease(),
    SetJogRatio(30.0),
    Step(StepFrame.JOINT, [1.0, 0, 0, 0, 0, 0]),
    SetMode(WorkMode.MANUAL),
    GoZero(None),
    RunProgram(1),
    CreatePoint(7),
    MoveToPoint(7),
    UploadPoints.of([(7, (400.0, 0.0, 300.0, 180.0, 0.0, 0.0))]),
    CancelUpload(),
    ReadRegisters(((412, 12), (560, 24))),
    SetWatchList((WatchEntry.make(Source.GV, 10),), generation=1),
    WriteWatched(WatchEntry.make(Source.GV, 10), 1.5),
)


def test_every_operation_class_is_listed_here() -> None:
    classes = {
        obj
        for obj in vars(ops).values()
        if inspect.isclass(obj) and issubclass(obj, LinkOp) and obj is not LinkOp
    }
    assert classes == {type(op) for op in EVERY_OP}


def test_each_operation_says_its_priority_class_and_coalescing() -> None:
    urgent = {type(op) for op in EVERY_OP if op.kind is JobKind.URGENT}
    assert urgent == {Stop, Pause, Resume, JogRelease, CancelUpload}
    motion = {type(op) for op in EVERY_OP if op.kind is JobKind.MOTION}
    assert motion == {JogPress, SetJogRatio, Step, GoZero, RunProgram, MoveToPoint, UploadPoints}
    assert (JogPress.coalesce, SetJogRatio.coalesce) == (JOG_PRESS, JOG_RATIO)
    assert set(JogRelease.cancels) == {JOG_PRESS, JOG_RATIO}
    no_link = {Stop, JogRelease, CancelUpload, SetWatchList}
    assert {type(op) for op in EVERY_OP if not op.needs_link} == no_link
    assert {type(op) for op in EVERY_OP if op.tracks_motion} == {Step, GoZero, RunProgram, MoveToPoint}


def test_the_queue_reads_what_it_needs_from_the_op() -> None:
    queue = JobQueue(halting=(Stop.operation, CancelUpload.operation))
    queue.put(Job(JogPress(JogRequest(TeachFrame.BASE, 0, 1, 20.0))))
    queue.put(Job(MoveToPoint(3)))
    queue.put(Job(JogPress(JogRequest(TeachFrame.BASE, 1, 1, 20.0))))  # takes the first press's place
    queue.put(Job(Stop()))
    order = [job.op for job in iter(queue.pop, None)]
    assert order == [Stop(), JogPress(JogRequest(TeachFrame.BASE, 1, 1, 20.0)), MoveToPoint(3)]
    assert queue.halts == 1


def test_operations_are_frozen_values_that_copy_what_they_are_given() -> None:
    offsets = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    step = Step(StepFrame.JOINT, offsets)
    offsets[0] = 50.0  # the caller's list changes after the submit: the op does not
    assert step.offsets == (1.0, 0.0, 0.0, 0.0, 0.0, 0.0) and step == Step(
        StepFrame.JOINT, [1.0, 0, 0, 0, 0, 0]
    )
    with pytest.raises(FrozenInstanceError):
        step.speed = 99.0  # type: ignore[misc]
    assert len({op for op in EVERY_OP}) == len(EVERY_OP)  # hashable, one key each
    upload = UploadPoints.of([(1, [1.0, 2, 3, 4, 5, 6]), (2, (0.0,) * 6, 4)], tool=3)
    assert upload.items == ((1, (1.0, 2.0, 3.0, 4.0, 5.0, 6.0), 3), (2, (0.0,) * 6, 4))
    press = JogPress(JogRequest(0, 0, 1, 10.0))  # type: ignore[arg-type]  # a frame given by its number
    assert press.request.frame is TeachFrame.BASE


def test_the_worker_has_one_handler_for_every_operation(link: RobotLink) -> None:
    handlers = link._worker.handlers
    assert all(type(op) in handlers for op in EVERY_OP)


def test_the_link_is_one_port_submit_and_track() -> None:
    gone: tuple[str, ...] = ("stop", "pause", "resume", "jog_press", "jog_release", "set_jog_ratio", "step")
    gone += (
        "set_mode",
        "go_zero",
        "run_program",
        "create_point",
        "move_to_point",
        "upload_points",
        "cancel_upload",
    )
    assert [name for name in gone if hasattr(RobotLink, name) or hasattr(LinkPort, name)] == []
    fake = FakeLink()
    tickets = [fake.submit(op) for op in EVERY_OP]
    assert fake.kinds() == [type(op) for op in EVERY_OP] and len(set(tickets)) == len(tickets)
    assert fake.named(MoveToPoint) == [MoveToPoint(7)] and fake.last_id(MoveToPoint) == tickets[11]
    assert fake.state.stops_requested == 1


@dataclass(frozen=True)
class _WriteSpare(LinkOp):
    """A test's own operation: one class and one handler are all an operation needs."""

    operation: ClassVar[str] = "write spare"
    gv: int
    value: float


def test_a_new_operation_is_a_class_and_a_handler(qtbot: Any, sim: Any, link: RobotLink) -> None:
    connect(qtbot, link, sim)
    worker = link._worker

    def write_spare(op: _WriteSpare) -> None:
        worker.client_or_raise().write_gv(op.gv, [op.value])
        worker.emit_result(CommandResult(None, None, None, True, f"{op.operation}: sent"))

    worker.handlers.add(_WriteSpare, write_spare)
    pending = link.track(link.submit(_WriteSpare(60, 12.5)))
    with qtbot.waitSignal(pending.finished, timeout=SIGNAL_TIMEOUT_MS) as done:
        pass
    assert done.args[0].ok and done.args[0].request_id == pending.request_id
    assert [value for _, value in gv_writes(sim, 60)] == [12.5]  # at the simulator
