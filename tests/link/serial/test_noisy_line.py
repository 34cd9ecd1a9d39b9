"""A noisy RTU serial line (issue 19 section 4): the relay damages one byte in 500, both ways.

What is safe to send again is sent again (app/link/line_retry.py): reads, the value registers of
an upload's point (read back first), the point whole (the same point at the same pose). A motion
command never is. Asserted at the simulator: the points it holds, the writes it received.
"""

from __future__ import annotations

import struct
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from app import timing
from app.cli.exit_codes import ExitCode
from app.cli.main import main
from app.connection import ConnectionSettings
from app.errors import ResponseTimeout, TeachPadError
from app.link.client import RobotClient
from app.link.ops import UploadPoints
from app.link.robot_link import RobotLink
from app.link.types import LinkState, StepFrame
from app.models import CommandResult
from app.protocol import registers
from app.sim.config import SimConfig
from app.sim.server import SimController
from benchmarks.noisy_line import project_points, wrong_points
from tests.link.progress_log import ProgressLog
from tests.link.serial.relay import PtyRelay
from tests.ui.pendant_support import SIGNAL_TIMEOUT_MS, is_state

pytestmark = [
    pytest.mark.skipif(not hasattr(__import__("os"), "openpty"), reason="needs POSIX ptys"),
    pytest.mark.timeout(180),
]

BAUD = 115200
N = 50
DAMAGE = 500  # one byte in 500 damaged, both directions
# s per request: roomy for a loaded machine (the longest answer is 22 ms on the wire); a damaged
# request is never answered, so each of those costs one timeout
TIMEOUT = 0.5


def _line(damage_one_in: int = 0, seed: int = 0) -> tuple[PtyRelay, SimController]:
    relay = PtyRelay(BAUD, damage_one_in=damage_one_in, seed=seed)
    sim = SimController(SimConfig(serial_port=relay.sim_port, baudrate=BAUD))
    sim.start()
    return relay, sim


@pytest.fixture(name="noisy")
def noisy_fixture() -> Iterator[tuple[PtyRelay, SimController]]:
    relay, sim = _line(DAMAGE, seed=19)
    try:
        yield relay, sim
    finally:
        sim.stop()
        relay.close()


@pytest.fixture(name="clean")
def clean_fixture() -> Iterator[tuple[PtyRelay, SimController, RobotClient]]:
    relay, sim = _line()
    client = RobotClient(ConnectionSettings(serial_port=relay.host_port, baudrate=BAUD, timeout=TIMEOUT))
    try:
        client.connect()
        yield relay, sim, client
    finally:
        client.close()
        sim.stop()
        relay.close()


def _write_to(address: int, function: int = 0x10) -> Any:
    """A relay predicate: the request is a write (``function``) starting at ``address``."""
    head = bytes([1, function]) + struct.pack(">H", address)
    return lambda frame: frame[:4] == head


def test_cli_points_upload_over_a_noisy_line_completes_with_no_wrong_point(
    noisy: tuple[PtyRelay, SimController], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    relay, sim = noisy
    points = project_points(N)
    csv = tmp_path / "points.csv"
    rows = [f"{p.id},{p.name},{p.x},{p.y},{p.z},{p.a},{p.b},{p.c},0,0,0,0,0,{p.tool}," for p in points]
    csv.write_text(
        "id,name,x,y,z,a,b,c,e1,e2,e3,e4,e5,tool,note\n" + "\n".join(rows) + "\n", encoding="utf-8"
    )
    project = tmp_path / "noisy.teachpad.json"
    assert main(["points", "import", str(project), "--csv", str(csv)]) == ExitCode.OK, capsys.readouterr()
    capsys.readouterr()
    link = ["--rtu", relay.host_port, "--baud", str(BAUD), "--timeout", str(TIMEOUT)]
    code = main([*link, "points", "upload", str(project)])
    out, err = capsys.readouterr()
    assert code == ExitCode.OK, err
    assert f"uploaded {N} point(s)" in out
    assert wrong_points(sim, points) == 0  # at the controller: every point there, at its pose and tool
    assert sum(relay.damaged.values()) > 0  # (the line was noisy indeed)


def test_the_gui_upload_over_a_noisy_line_completes_with_no_wrong_point(
    qtbot: Any, noisy: tuple[PtyRelay, SimController]
) -> None:
    relay, sim = noisy
    points = project_points(N)
    link = RobotLink(poll_hz=timing.POLL_HZ_DEFAULT, canary_gv=None)
    try:
        with qtbot.waitSignal(
            link.connectionChanged, check_params_cb=is_state(LinkState.CONNECTED), timeout=SIGNAL_TIMEOUT_MS
        ):
            settings = ConnectionSettings(
                serial_port=relay.host_port, baudrate=BAUD, timeout=TIMEOUT, poll_timeout=TIMEOUT
            )  # roomy polls too: a loaded machine's late answer is not the subject
            link.connect_to(settings)
        states: list[LinkState] = []
        link.connectionChanged.connect(lambda s: states.append(s.state))
        log = ProgressLog(link)
        finished: list[CommandResult] = []
        link.commandFinished.connect(finished.append)
        request = link.submit(UploadPoints.of([(p.id, p.xyzabc, p.tool) for p in points]))
        qtbot.waitUntil(lambda: any(r.request_id == request for r in finished), timeout=150_000)
        result = next(r for r in finished if r.request_id == request)
        assert result.ok, result.message
        assert result.message.startswith(f"uploaded {N} of {N} points")
        assert [p.point_id for p in log.points(request) if p.ok] == [p.id for p in points]
        # never lost for a damaged frame (a poll whose every try was damaged may show "not answering"
        # until the next good poll: a pose answer is 205 bytes, a third of them damaged at 1 in 500)
        assert LinkState.DOWN not in states and LinkState.DISCONNECTED not in states, states
    finally:
        link.shutdown()
    assert wrong_points(sim, points) == 0
    assert sum(relay.damaged.values()) > 0


def test_a_damaged_read_is_sent_again(clean: tuple[PtyRelay, SimController, RobotClient]) -> None:
    relay, sim, client = clean
    relay.corrupt_next_answer = True
    assert client.read_pose().xyzabc == pytest.approx(sim.state().pose, abs=1e-3)
    relay.corrupt_next_request = True  # never answered: a timeout, then the read again
    assert client.read_status().mode == 1
    assert sim.bad_frame_counts() == {"bad CRC": 1}
    assert (client.stats.malformed, client.stats.timeouts) == (1, 1)


def test_a_silent_controller_is_not_waited_for_through_every_retry(
    clean: tuple[PtyRelay, SimController, RobotClient],
) -> None:
    relay, _, client = clean
    relay.drop_requests = True
    with pytest.raises(ResponseTimeout):
        client.read_status()
    assert client.stats.timeouts == 1 + timing.LINE_TIMEOUT_RETRIES  # once more, not the whole budget
    relay.drop_requests = False
    assert client.read_status().mode == 1


def test_a_pose_write_whose_answer_was_damaged_is_read_back_not_written_twice(
    clean: tuple[PtyRelay, SimController, RobotClient],
) -> None:
    relay, sim, client = clean
    pose_reg = registers.gv_reg(0)
    relay.corrupt_answer_to = _write_to(pose_reg)
    pose = (400.0, -20.0, 350.0, 180.0, 0.0, 45.0)
    results = client.upload_points([(7, pose)], gv_start=0)
    assert [r.ok for r in results] == [True]
    assert sim.state().points[7] == pytest.approx(pose)
    assert client.stats.malformed >= 1
    assert len(sim.writes_to(pose_reg)) == 1  # it took: read back, not sent again


def test_a_create_whose_command_answer_was_damaged_is_sent_whole_again(
    clean: tuple[PtyRelay, SimController, RobotClient],
) -> None:
    relay, sim, client = clean
    damaged = iter([True])  # the first 440 only
    command = _write_to(registers.REG_RUN_COMMAND, 0x06)
    relay.corrupt_answer_to = lambda frame: command(frame) and next(damaged, False)
    pose = (410.0, 10.0, 360.0, 180.0, 0.0, 30.0)
    results = client.upload_points([(8, pose)], gv_start=0)
    assert [r.ok for r in results] == [True], results
    assert sim.state().points[8] == pytest.approx(pose)
    creates = [w for w in sim.writes_to(registers.REG_RUN_COMMAND) if w.values == (0xE0,)]
    assert len(creates) == 2  # the same point at the same pose, again: idempotent


def test_a_motion_command_whose_answer_was_damaged_is_never_sent_again(
    clean: tuple[PtyRelay, SimController, RobotClient],
) -> None:
    relay, sim, client = clean
    relay.corrupt_answer_to = _write_to(registers.REG_RUN_COMMAND, 0x06)
    start = sim.state().pose
    with pytest.raises(TeachPadError):
        client.step(StepFrame.BASE, (5.0, 0.0, 0.0, 0.0, 0.0, 0.0), speed=50.0)
    assert len(sim.writes_to(registers.REG_RUN_COMMAND)) == 1  # sent once: its outcome is unknown
    assert sim.wait_for(lambda s: not s.moving and abs(s.pose[0] - start[0] - 5.0) < 1e-3, 10.0)
