"""The chunked upload run (no Qt): checks, grouping, chunks, cancel."""

from __future__ import annotations

import itertools
import re
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from pymodbus.constants import ExcCodes

import app
from app import timing
from app.errors import (
    InvalidInput,
    LinkError,
    MalformedResponse,
    ModbusExceptionError,
    Reason,
    ResponseTimeout,
    TeachPadError,
)
from app.link.jobs import Job, JobQueue
from app.link.ops import CancelUpload, JogRelease, Stop, UploadPoints
from app.link.types import LinkState
from app.link.upload import RawItem, Uploader, check_upload_items
from app.link.upload_driver import group_by_tool
from app.models import LINK_FAILURE_CODES, CommandResult
from app.protocol import registers
from app.protocol.enums import CommandKind, CommandStatus, RunCommand
from app.protocol.registers import UPLOAD_STAGE_GV, stage_gv_for
from tests.link.harness import PartsHost

POSE = (100.0, 0.0, 300.0, 180.0, 0.0, 0.0)


def test_grouping_keeps_tools_in_first_seen_order() -> None:
    items = [(1, POSE, 5), (2, POSE, 3), (3, POSE, 5)]
    assert [pid for pid, _, _ in group_by_tool(items, lambda item: item[2])] == [1, 3, 2]


def test_every_item_is_checked_and_bad_values_are_quoted_short(sim: Any, make_client: Any) -> None:
    client = make_client(sim)
    with pytest.raises(InvalidInput, match="finite float32"):
        check_upload_items(client, [(100, (float("nan"),) * 6, 0)])
    with pytest.raises(InvalidInput) as info:
        check_upload_items(client, [("x" * 500, POSE, 0)])
    assert len(str(info.value)) < 120


def test_chunks_until_done_with_one_final_result(
    host: PartsHost, sim: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(timing, "UPLOAD_CHUNK_POINTS", 2)
    host.connect(sim)
    host.request_id = 9
    assert host.uploader.start([(100 + i, POSE, 200) for i in range(5)])
    host.request_id = None
    steps = 1
    while host.uploader.step():
        steps += 1
    assert steps >= 3  # 5 points in chunks of at most 2
    assert [p[0] for p in host.of("pointUploaded")] == [100, 101, 102, 103, 104]
    result = host.of("commandFinished")[-1]
    assert result.ok and result.request_id == 9 and result.message == "uploaded 5 of 5 points"
    assert host.of("uploadProgress")[-1] == (5, 5)


def test_cancel_between_chunks_ends_it_at_once(
    host: PartsHost, sim: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(timing, "UPLOAD_CHUNK_POINTS", 1)
    host.connect(sim)
    assert host.uploader.start([(100 + i, POSE, 200) for i in range(4)])
    assert host.uploader.step()
    host.uploader.end("cancelled")
    assert host.uploader.run is None
    result = host.of("commandFinished")[-1]
    assert not result.ok and result.message == "uploaded 1 of 4 points (cancelled)"


def test_the_second_pose_block_steps_aside_for_the_restart_canary(sim: Any) -> None:
    assert stage_gv_for(None) == UPLOAD_STAGE_GV == 6
    assert stage_gv_for(99) == 6 and stage_gv_for(5) == 6
    assert stage_gv_for(8) == 12  # the canary in GV6..GV11: the poses alternate with GV12..GV17
    host = PartsHost(canary_gv=8)
    try:
        host.connect(sim)
        assert host.uploader.start([(100 + i, (100.0 + i, 0.0, 300.0, 0.0, 0.0, 0.0), 200) for i in range(6)])
        while host.uploader.step():
            pass
        assert host.of("commandFinished")[-1].ok
    finally:
        host.close()
    pose_blocks = {w.address for w in sim.writes if w.address < 400 and len(w.values) == 12}
    assert pose_blocks == {0, 24}  # GV0..GV5 and GV12..GV17
    assert sim.state().points[105] == (105.0, 0.0, 300.0, 0.0, 0.0, 0.0)


def test_a_stop_on_its_way_writes_nothing_more_than_the_point_in_flight(
    host: PartsHost, sim_factory: Any
) -> None:
    """From the moment a stop (or cancel) is counted -- here: once the first point's 440 reached
    the controller -- the upload writes no staged pose and starts no next point, and it ends
    "stopped" even when no stop job comes to end it (a stop refused on the main link)."""
    sim = sim_factory(command_latency=0.02)  # the controller works a while on each point: room to stage
    host.uploader = Uploader(host, lambda: len(sim.writes_to(440)))
    host.connect(sim)
    assert host.uploader.start([(100 + i, (100.0 + i, 0.0, 300.0, 0.0, 0.0, 0.0), 200) for i in range(4)])
    steps = 0
    while host.uploader.step():
        steps += 1
        assert steps < 10  # no busy loop of empty chunks
    result = host.of("commandFinished")[-1]
    assert not result.ok and result.message == "uploaded 1 of 4 points (stopped)"
    first = next(i for i, w in enumerate(sim.writes) if w.address == 440)
    assert [w.address for w in sim.writes[first + 1 :] if w.address != 2 * 291] == []  # (GV291: completion)
    assert set(sim.state().points) == {100}


def test_without_a_stop_the_next_pose_is_staged(host: PartsHost, sim_factory: Any) -> None:
    """The counterpart: the same upload, nothing asked, stages every next pose while the
    controller works on the point before it."""
    sim = sim_factory(command_latency=0.05)
    host.uploader = Uploader(host, lambda: 0)
    host.connect(sim)
    assert host.uploader.start([(100 + i, (100.0 + i, 0.0, 300.0, 0.0, 0.0, 0.0), 200) for i in range(4)])
    while host.uploader.step():
        pass
    assert host.of("commandFinished")[-1].message == "uploaded 4 of 4 points"
    order = [w.address for w in sim.writes if w.address in (0, 12, 400, 440)]
    # a pose right after a 440: the next point's, staged while the controller works (GV0.. / GV6..)
    assert any(a == 440 and b in (0, 12) for a, b in itertools.pairwise(order)), order


def _queue_when_in_flight(
    host: PartsHost, sim: Any, job: Callable[[], None], nth: int = 1
) -> threading.Thread:
    """From another thread (like the GUI's Stop): queue ``job`` as an urgent job once the
    ``nth`` point's 440 reached the simulator, i.e. while that point is in flight."""

    def post() -> None:
        assert sim.wait_for(lambda _s: len(sim.writes_to(440)) >= nth, 10.0)
        host.urgent.append(job)

    thread = threading.Thread(target=post, daemon=True)
    thread.start()
    return thread


def _long_point_timeouts(monkeypatch: pytest.MonkeyPatch) -> None:
    """A point in flight ends by its own timeouts only after 10 s (acknowledged or not)."""
    monkeypatch.setattr(timing, "ACK_TIMEOUT", 10.0)
    monkeypatch.setattr(timing, "CREATE_POINT_TIMEOUT", 10.0)


def _run_upload(host: PartsHost, count: int) -> float:
    """Start an upload of ``count`` points and step it to its end; the seconds the steps took."""
    items: list[RawItem] = [(100 + i, (100.0 + i, 0.0, 300.0, 0.0, 0.0, 0.0), 200) for i in range(count)]
    assert host.uploader.start(items)
    start = time.monotonic()
    steps = 0
    while host.uploader.step():
        steps += 1
        assert steps < 20  # no busy loop of empty chunks
    return time.monotonic() - start


def test_a_stop_ends_the_point_in_flight_at_once_when_its_result_never_shows(
    host: PartsHost, sim_factory: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The controller shows no create-point result for 60 s (and a stop resets GV291 to 0, so it
    never will): the stop job, queued while the point is in flight, runs between two of the
    point's status reads; its 441 on this link ends the point as stopped, and the upload returns
    its results at once -- not after the point's timeout (here 10 s, as the old code did)."""
    _long_point_timeouts(monkeypatch)
    sim = sim_factory(command_latency=60.0)
    host.connect(sim)

    def stop() -> None:  # what the worker's stop job does first (app/link/halt.py)
        host.client_or_raise().stop()
        host.uploader.end("stopped")

    poster = _queue_when_in_flight(host, sim, stop)
    elapsed = _run_upload(host, 4)
    poster.join(1.0)
    assert elapsed < 2.0  # ms on an idle machine; the old code waited the point's 10 s timeout
    result = host.of("commandFinished")[-1]
    assert not result.ok and result.message == "uploaded 0 of 4 points (stopped)"
    [(pid, ok, reason, unconfirmed)] = host.of("pointUploaded")
    assert (pid, ok, unconfirmed) == (100, False, False)
    assert "stopped by the operator" in reason and "not confirmed" in reason  # never "created"
    # at the simulator: one point started, the stop after its 440, nothing of the batch after it
    writes = [w.address for w in sim.writes if w.address != 2 * 291]  # (GV291: the completion rule)
    assert writes.count(440) == 1 and writes.index(440) < writes.index(441)
    assert set(writes[writes.index(441) :]) == {441}


def test_a_cancel_lets_the_point_in_flight_finish(host: PartsHost, sim_factory: Any) -> None:
    """A cancel is no controller stop: urgent jobs run between the reads of the point in
    flight, but only a stop ends it; the point's own result (created) is waited for."""
    sim = sim_factory(command_latency=0.2)
    host.connect(sim)
    poster = _queue_when_in_flight(host, sim, lambda: host.uploader.end("cancelled"))
    _run_upload(host, 4)
    poster.join(1.0)
    assert host.of("commandFinished")[-1].message == "uploaded 1 of 4 points (cancelled)"
    assert host.of("pointUploaded") == [(100, True, "", False)]
    assert sim.writes_to(441) == [] and len(sim.writes_to(440)) == 1
    assert set(sim.state().points) == {100}


def test_a_link_lost_between_two_reads_ends_the_point_without_another_read(
    host: PartsHost, sim_factory: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    """An urgent job that finds the link gone (here: declared lost) ends the wait: the point's
    outcome is unknown, and no read goes out on the closed link (it would reconnect)."""
    _long_point_timeouts(monkeypatch)
    sim = sim_factory(command_latency=60.0)
    host.connect(sim)
    poster = _queue_when_in_flight(host, sim, lambda: host.link_lost("the test cut it"))
    elapsed = _run_upload(host, 3)
    poster.join(1.0)
    assert elapsed < 2.0
    [(pid, ok, reason, _)] = host.of("pointUploaded")
    assert (pid, ok) == (100, False) and "outcome is unknown" in reason
    result = host.of("commandFinished")[-1]
    assert not result.ok and "link lost" in result.message
    assert not host.link_up and sim.wait_for(lambda _s: sim.connections_count == 0, 2.0)


def test_the_queue_counts_the_jobs_that_end_an_upload() -> None:
    jobs = JobQueue(halting=("stop", "cancel upload"))
    jobs.put(Job(JogRelease()))
    jobs.put(Job(UploadPoints(())))
    assert jobs.halts == 0
    jobs.put(Job(Stop()))
    jobs.put(Job(CancelUpload()))
    assert jobs.halts == 2
    jobs.clear()
    assert jobs.halts == 2  # a count of requests, never lowered: an upload compares it with its start


# --- "the link failed" vs "the controller refused": one rule (CommandResult.link_failed) ------------

#: Every reason code a failed command result may carry, and whether it means the link failed.
_LINK_FAILED_BY_CODE = {
    # the link is gone or could not be made (LinkError and the codes it is raised with)
    "link_lost": True,
    "link_closed": True,
    "not_connected": True,
    "connect_failed": True,
    "connect_timeout": True,
    "connection_refused": True,
    "host_unresolved": True,
    "host_invalid": True,
    "serial_open_failed": True,
    "no_answer": True,  # ResponseTimeout: no answer in time
    "malformed_answer": True,  # the byte stream may be out of step: only a new connection is trusted
    "stop_unreachable": True,  # a Stop's fresh connection failed too: the controller's state is unknown
    # the controller answered (or the host refused before the wire): the link is fine
    "modbus_exception": False,
    "command_refused": False,
    "refused_unconfirmed": False,
    "command_timeout": False,
    "not_acknowledged": False,
    "result_unknown": False,
    "alarm_while_waiting": False,
    "stopped_by_operator": False,
    "stopped_by_controller": False,
    "monitor_only": False,
    "invalid_input": False,
    "envelope_refused": False,
    "point_mismatch": False,
    "point_not_created": False,
    "file_format": False,
    "empty_import": False,
    "project_too_large": False,  # a project TeachPad could not read back: not written
    "jog_not_answering": False,  # the jog's own check before it starts: nothing was sent
    "outcome_unknown": False,  # taken, then its status could not be read: counted by the reads that failed
    "controller_busy": False,  # not sent: the controller runs a program
    "foreign_master": False,  # not sent: another master wrote moments ago (the link is fine)
    "manual_mode": False,  # go to zero / run program in manual mode, no switch allowed: nothing sent
    "reduced_speed_refused": False,  # go to zero in reduced-speed mode: nothing sent
    "audit_unavailable": False,  # its audit record could not be written: refused, nothing sent
    "envelope_unchecked": False,  # the CLI's move with no host copy under a box: refused, nothing sent
    "profile_invalid": False,  # a robot model file that cannot be used: a file problem, not the link
    "error": False,
}


def _error_classes(base: type[TeachPadError] = TeachPadError) -> list[type[TeachPadError]]:
    found = [base]
    for sub in base.__subclasses__():
        found += _error_classes(sub)
    return found


def test_the_link_failed_rule_over_every_error_code() -> None:
    """Every code of every typed error (app/errors.py, the LinkError variants raised in app/) is
    classified: True only where the link's state is unknown; a result with a controller status
    (the tracker's) never; a success never; no reason (an older producer): only without a status."""
    class_codes = {cls.code for cls in _error_classes() if cls.__module__.startswith("app.")}
    assert class_codes <= set(_LINK_FAILED_BY_CODE), class_codes - set(_LINK_FAILED_BY_CODE)
    link_raises = set()
    for path in Path(app.__file__).parent.rglob("*.py"):
        text = path.read_text(encoding="utf-8")
        for match in re.finditer(r"\b(LinkError|ResponseTimeout|MalformedResponse)\(", text):
            call = re.split(r"\braise\b|\bdef\b|\n\s*\n", text[match.end() : match.end() + 300])[0]
            found = re.search(r'code="(\w+)"', call)
            if found is not None:
                link_raises.add(found.group(1))
    assert link_raises <= LINK_FAILURE_CODES, link_raises - LINK_FAILURE_CODES
    assert {code for code, failed in _LINK_FAILED_BY_CODE.items() if failed} == LINK_FAILURE_CODES
    status = CommandStatus(CommandKind.CREATE_POINT, 2)
    for code, failed in _LINK_FAILED_BY_CODE.items():
        reason = Reason(code, {})
        upload_like = CommandResult(
            RunCommand.CREATE_POINT, CommandKind.CREATE_POINT, None, False, code, reason=reason
        )
        assert upload_like.link_failed is failed, code
        done = CommandResult(
            RunCommand.CREATE_POINT, CommandKind.CREATE_POINT, None, True, code, reason=reason
        )
        assert not done.link_failed, code
    # from the errors themselves, as RobotClient.upload_points builds a point's failed result
    for error, failed in (
        (LinkError("gone"), True),
        (ResponseTimeout("late"), True),
        (MalformedResponse("bad", field="CRC"), True),
        (ModbusExceptionError(16, 3, "illegal data value"), False),
    ):
        result = CommandResult(
            RunCommand.CREATE_POINT, None, None, False, str(error), reason=error.as_reason()
        )
        assert result.link_failed is failed, error
    answered = CommandResult(RunCommand.CREATE_POINT, CommandKind.CREATE_POINT, status, False, "refused")
    assert not answered.link_failed  # no reason, but the controller's status: it answered
    assert CommandResult(RunCommand.CREATE_POINT, None, None, False, "?").link_failed  # nothing known


def _refusal_upload(host: PartsHost, sim: Any, count: int = 6) -> list[RawItem]:
    items: list[RawItem] = [
        (100 + i, (100.0 + i, -float(i), 300.0, 0.0, 0.0, float(i)), 200) for i in range(count)
    ]
    assert host.uploader.start(items)
    steps = 0
    while host.uploader.step():
        steps += 1
        assert steps < 20  # no busy loop of empty chunks
    return items


def test_a_point_whose_result_never_shows_is_counted_failed_not_refused(
    host: PartsHost, sim_factory: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The controller keeps every create-point result back (60 s) past the point's timeout: nobody
    said no, the points' outcome is not known -- the final result counts them *failed* with the
    words of the first ("did not complete ..."), never "refused"; the link is kept."""
    monkeypatch.setattr(timing, "CREATE_POINT_TIMEOUT", 0.3)
    monkeypatch.setattr(timing, "ACK_TIMEOUT", 0.3)
    sim = sim_factory(command_latency=60.0)
    host.connect(sim)
    _refusal_upload(host, sim, count=2)
    assert [ok for _, ok, _, _ in host.of("pointUploaded")] == [False, False]
    result = host.of("commandFinished")[-1]
    assert re.match(r"uploaded 0 of 2 points, 2 failed: point 100: ", result.message), result.message
    assert "refused" not in result.message
    assert result.details["failed"] == 2.0 and result.details["refused"] == 0.0
    assert host.link_up and host.reconnect_delays == []


def test_a_point_the_controller_refuses_with_a_modbus_exception_is_failed_and_the_upload_goes_on(
    host: PartsHost, sim_factory: Any
) -> None:
    """Point 102's parameters (GV200-202) are answered with exception 3: that point is reported
    failed in the controller's words, the link is not declared failed (no reconnect, one
    connection all along), the points after it are created with their own poses -- the next
    pose is written anew, whatever was staged before the refusal -- and the final result says
    how many were refused."""
    sim = sim_factory(command_latency=0.02)  # the controller works a while: the poses are staged
    host.connect(sim)
    connections = sim.connections_count
    sim.refuse_point_write(102)
    items = _refusal_upload(host, sim)
    uploaded = host.of("pointUploaded")
    assert [(pid, ok) for pid, ok, _, _ in uploaded] == [(100 + i, i != 2) for i in range(6)]
    reason = uploaded[2][2]
    assert reason.startswith("controller refused write") and "illegal data value" in reason, reason
    result = host.of("commandFinished")[-1]
    assert not result.ok
    assert result.message.startswith("uploaded 5 of 6 points, 1 refused: "), result.message
    assert result.details["refused"] == 1.0 and result.details["attempted"] == 6.0
    # the link stayed up: never away from connected, no reconnect scheduled, the same connection
    assert host.link_up and host.reconnect_delays == []
    assert all(state is LinkState.CONNECTED for state in host.states()[1:]), host.states()
    assert sim.connections_count == connections == 1
    held = sim.state().points
    assert set(held) == {100, 101, 103, 104, 105}
    assert all(held[pid] == pose for pid, pose, _ in items if pid != 102)


def test_a_refused_first_point_of_a_chunk_and_its_retry_next_time(host: PartsHost, sim_factory: Any) -> None:
    """Chunks of one point: the refused point's chunk ends with it, the next chunk goes on; the
    knob refuses only once, so a second upload of the same point is created."""
    sim = sim_factory()
    host.connect(sim)
    sim.refuse_point_write(101)
    _refusal_upload(host, sim, 3)
    assert [(pid, ok) for pid, ok, _, _ in host.of("pointUploaded")] == [
        (100, True),
        (101, False),
        (102, True),
    ]
    assert host.link_up and set(sim.state().points) == {100, 102}
    _refusal_upload(host, sim, 3)
    assert host.of("commandFinished")[-1].message == "uploaded 3 of 3 points"
    assert set(sim.state().points) == {100, 101, 102} and sim.connections_count == 1


def test_a_tool_frame_the_controller_refuses_refuses_its_points_and_the_upload_goes_on(
    host: PartsHost, sim: Any
) -> None:
    """GV245 answered with exception 3 (the controller has no such tool): the batch of that tool
    never gets to its first point -- each of its points is refused in the controller's words, the
    link stays up, and the points of the next tool are created."""
    host.connect(sim)
    tool_regs = 2 * registers.GV_TOOL_FRAME
    sim.set_exception(ExcCodes.ILLEGAL_VALUE, range(tool_regs, tool_regs + 2))
    items: list[RawItem] = [
        (100 + i, (100.0 + i, 0.0, 300.0, 0.0, 0.0, 0.0), 7 if i < 3 else 200) for i in range(5)
    ]
    # tool 200 (none) is the controller's default: the cached GV245 is written all the same, refused
    # too -- so lift the refusal for the second tool once the first tool's points are reported
    assert host.uploader.start(items)
    while host.uploader.step():
        if len(host.of("pointUploaded")) >= 3:
            sim.set_exception(None)
    uploaded = host.of("pointUploaded")
    assert [(pid, ok) for pid, ok, _, _ in uploaded] == [
        (100, False),
        (101, False),
        (102, False),
        (103, True),
        (104, True),
    ]
    assert all("illegal data value" in reason for _, _, reason, _ in uploaded[:3])
    assert host.of("commandFinished")[-1].message.startswith("uploaded 2 of 5 points, 3 refused: ")
    assert host.link_up and host.reconnect_delays == [] and set(sim.state().points) == {103, 104}
