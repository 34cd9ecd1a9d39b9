"""A Stop is serviced whatever the worker is doing (RobotLink + worker against the real simulator,
no widgets): during an upload it ends the point in flight at once, and when its own write on the
main link fails, nothing queued before it runs after it."""

from __future__ import annotations

import time
from typing import Any

import pytest

from app import timing
from app.link.ops import GoZero, JogPress, RunProgram, Stop, UploadPoints
from app.link.robot_link import RobotLink
from app.link.types import JogRequest, WorkerError
from app.models import CommandResult
from app.protocol import registers
from tests.link.progress_log import ProgressLog
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    SIGNAL_TIMEOUT_MS,
    connect,
    fast_reconnect_fixture,
    link_fixture,
)

pytestmark = pytest.mark.timeout(60)


def _poses(sim: Any, ids: range) -> list[tuple[int, tuple[float, ...], int]]:
    x, y, z, a, b, c = sim.state().pose
    return [(pid, (x + pid * 0.01, y, z, a, b, c), 200) for pid in ids]


def test_a_stop_ends_an_upload_at_once_even_when_the_point_in_flight_never_gets_its_result(
    qtbot: Any, sim_factory: Any, link: RobotLink, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The CI flake of the test above, made certain: the Stop lands while a point is in flight and
    the controller never shows that point's result (60 s of 0 in GV291, and its stop resets it).
    The worker's stop job runs between two of the point's status reads, its 441 on the main link
    ends the point as stopped, and the batch's final result follows the Stop's at once -- the old
    code waited for the point's timeout (10 s here) before the upload could end."""
    monkeypatch.setattr(timing, "ACK_TIMEOUT", 10.0)
    monkeypatch.setattr(timing, "CREATE_POINT_TIMEOUT", 10.0)
    sim = sim_factory(command_latency=60.0)
    connect(qtbot, link, sim)
    log = ProgressLog(link)
    results: list[CommandResult] = []
    link.commandFinished.connect(results.append)
    upload_id = link.submit(UploadPoints.of(_poses(sim, range(1, 6))))
    assert sim.wait_for(lambda _s: len(sim.writes_to(440)) == 1, 5.0)  # point 1 is in flight
    with qtbot.waitSignal(
        link.commandFinished,
        check_params_cb=lambda r: isinstance(r, CommandResult) and r.request_id == upload_id,
        timeout=SIGNAL_TIMEOUT_MS,
    ) as done:
        t0 = time.monotonic()
        stop_id = link.submit(Stop())
    elapsed = time.monotonic() - t0
    assert elapsed < 1.0  # ms on an idle machine
    assert done.args[0].message == "uploaded 0 of 5 points (stopped)" and not done.args[0].ok
    assert any(r.request_id == stop_id and r.ok for r in results)  # the Stop's own result
    [point] = log.points(upload_id)  # the point in flight: failed, stopped, never "created"
    pid, ok, reason = point.point_id, point.ok, point.reason
    assert (pid, ok) == (1, False) and "stopped by the operator" in reason and "not confirmed" in reason
    # at the simulator: one point started (its next pose may have been staged meanwhile), then
    # the stop(s) -- the line's and the main link's -- and nothing more of the upload
    writes = [w.address for w in list(sim.writes) if w.address != 2 * 291]  # (GV291: completion rule)
    assert writes.count(440) == 1 and writes.index(440) < writes.index(441)
    assert set(writes[writes.index(441) :]) == {441}


def test_a_stop_whose_main_link_write_gets_no_answer_still_cancels_the_motions_queued_before_it(
    qtbot: Any, sim: Any, main_only_link: RobotLink
) -> None:
    """The simulator answers after 0.4 s, beyond the link's 0.25 s request timeout: the main
    link's 441 gets no answer in time (an error for the Stop). The motions queued before the Stop
    are cancelled all the same -- the old code then sent them, after the operator's Stop."""
    connect(qtbot, main_only_link, sim, timeout=0.25, poll_timeout=None)
    sim.set_response_delay(0.4)
    seen = sim.requests_count
    qtbot.waitUntil(lambda: sim.requests_count > seen, timeout=SIGNAL_TIMEOUT_MS)  # a read in flight
    results: list[CommandResult] = []
    errors: list[WorkerError] = []
    main_only_link.commandFinished.connect(results.append)
    main_only_link.errorOccurred.connect(errors.append)
    writes_before = len(sim.writes)
    queued = [main_only_link.submit(GoZero(0)), main_only_link.submit(RunProgram(1))]
    stop_id = main_only_link.submit(Stop())
    qtbot.waitUntil(lambda: any(e.request_id == stop_id for e in errors), timeout=SIGNAL_TIMEOUT_MS)
    qtbot.waitUntil(
        lambda: {r.request_id for r in results if "cancelled by Stop" in r.message} == set(queued),
        timeout=SIGNAL_TIMEOUT_MS,
    )
    sim.set_response_delay(0.0)
    qtbot.waitUntil(lambda: bool(sim.writes_to(441)), timeout=SIGNAL_TIMEOUT_MS)  # stored after its delay
    assert not any(e.request_id in queued for e in errors)  # never sent (no "did not answer" for them)
    # at the simulator: the stop(s), never a go-to-zero (430) or a program run (440) after it
    after = {w.address for w in list(sim.writes)[writes_before:]}
    assert 441 in after and not after & {registers.REG_GO_ZERO, registers.REG_RUN_COMMAND}


def test_a_stop_the_controller_refuses_still_ends_the_held_jog(qtbot: Any, sim: Any, link: RobotLink) -> None:
    """The operator holds a jog and presses Stop; the controller refuses the stop (a Modbus
    exception on 441, on the stop line and the main link alike). The Stop fails, but the jog it was
    pressed against ends all the same: speed 0 goes out and the arm stands. The old code ended the
    jog only after a stop that succeeded: the arm went on jogging after the Stop."""
    from pymodbus.constants import ExcCodes

    from app.protocol.enums import TeachFrame
    from tests.ui.pendant_support import jogging, ratio_writes

    connect(qtbot, link, sim)
    link.submit(JogPress(JogRequest(TeachFrame.BASE, 1, 1, 20.0)))
    qtbot.waitUntil(lambda: jogging(sim), timeout=SIGNAL_TIMEOUT_MS)
    ratios_before = len(ratio_writes(sim))
    results: list[CommandResult] = []
    link.commandFinished.connect(results.append)
    sim.set_exception(ExcCodes.ILLEGAL_VALUE, range(registers.REG_STOP, registers.REG_STOP + 1))
    stop_id = link.submit(Stop())
    qtbot.waitUntil(lambda: any(r.request_id == stop_id for r in results), timeout=SIGNAL_TIMEOUT_MS)
    stop = next(r for r in results if r.request_id == stop_id)
    assert not stop.ok and "refused" in stop.message
    assert sim.writes_to(441) == []  # the controller took no stop
    # at the simulator: speed 0 after the refused stop, and the arm standing
    qtbot.waitUntil(lambda: not jogging(sim), timeout=SIGNAL_TIMEOUT_MS)
    assert ratio_writes(sim)[ratios_before:] == [0.0]
    sim.set_exception(None)
    pose = sim.state().pose
    seen = sim.requests_count  # a few polls later: the arm has not moved, no speed went out
    qtbot.waitUntil(lambda: sim.requests_count > seen + 5, timeout=SIGNAL_TIMEOUT_MS)
    assert sim.state().pose == pytest.approx(pose, abs=1e-6) and not jogging(sim)
    assert ratio_writes(sim)[ratios_before:] == [0.0]
