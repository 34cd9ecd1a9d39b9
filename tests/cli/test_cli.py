"""teachpad-cli against the simulator: output, exit codes and one-line errors."""

from __future__ import annotations

import json
import os
import socket
import subprocess
import sys
import time
from typing import Any

import pytest
from pymodbus.constants import ExcCodes

from app.cli.exit_codes import ExitCode
from app.cli.main import main
from app.protocol.enums import Alarm, WorkMode
from tests.cli.ctrl_c import CHILD_TIMEOUT, ROOT, interrupt_cli

SCAN = 0.02  # see tests/link/test_client_sim.py
# `status` and `watch` read with the poll timeout (0.15 s on TCP). The simulator answers from this
# test process, which a loaded machine (coverage, a CI neighbour) can hold that long: the CLI would
# rightly say "did not answer" in a test about something else. Roomy here; the silence test keeps
# its own short one.
ROOMY_POLL = ("--poll-timeout", "1.0")


def run(sim: Any, capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(["--port", str(sim.port), *argv])
    out, err = capsys.readouterr()
    return code, out, err


def one_line_error(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("teachpad-cli: error: ")
    assert "Traceback" not in err
    return lines[0]


@pytest.fixture
def csim(sim_factory: Any) -> Any:
    return sim_factory(command_latency=SCAN)


def test_status_json_and_text(csim: Any, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(csim, capsys, *ROOMY_POLL, "status", "--json")
    assert code == ExitCode.OK and err == ""
    data = json.loads(out)
    state = csim.state()
    assert data["pose"]["x"] == pytest.approx(state.pose[0], abs=1e-3)
    assert len(data["external_axes"]) == 5 and len(data["joints"]) == 6
    assert data["mode"] == {"value": 1, "name": "auto"}
    assert data["program_state"] == {"value": 0, "name": "stopped"}
    assert data["alarms"] == {"value": 0, "names": []}
    assert data["command_status"] == {"code": 0, "text": "initial"}
    assert data["clock"]["iso"] and len(data["clock"]["raw"]) == 4
    csim.set_alarm(Alarm.ESTOP, True)
    code, out, _ = run(csim, capsys, *ROOMY_POLL, "status")
    assert code == ExitCode.OK
    assert "mode      auto (1)" in out and "program   stopped (0)" in out
    assert "alarms    emergency stop (1)" in out and "command   0 initial" in out
    assert "clock     " in out and "raw " in out


def test_status_json_shows_a_live_pose_during_a_jog(csim: Any, capsys: pytest.CaptureFixture[str]) -> None:
    """`jog` runs in another process; `status --json` here sees the pose change meanwhile."""
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "app.cli.main",
            "--port",
            str(csim.port),
            "jog",
            "--frame",
            "base",
            "--axis",
            "Y",
            "--dir",
            "+",
            "--ratio",
            "5",
            "--for",
            "4",
        ],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert csim.wait_for(lambda s: s.jogging, CHILD_TIMEOUT)
        ys: list[float] = []
        deadline = time.monotonic() + 4.0
        # three reads while it moves, however long a read takes on a loaded machine (0.8 s of jog
        # gave two reads with the suite on both cores beside other test runs)
        while csim.state().jogging and time.monotonic() < deadline and len(ys) < 3:
            code, out, _ = run(csim, capsys, *ROOMY_POLL, "status", "--json")
            assert code == ExitCode.OK
            data = json.loads(out)
            if data["mode"]["name"] == "Modbus teach":  # the jog may end between two reads
                ys.append(data["pose"]["y"])
        assert len(ys) >= 3 and ys == sorted(ys) and ys[-1] > ys[0]
        out, err = proc.communicate(timeout=CHILD_TIMEOUT)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate(timeout=CHILD_TIMEOUT)
    assert proc.returncode == ExitCode.OK, err
    assert "teach enable: success" in out and out.strip().splitlines()[-1].startswith("pose ")
    state = csim.state()
    assert not state.teach_enabled and state.teach_ratio == 0 and not state.jogging


def test_jog_interrupted_still_stops_and_disables(csim: Any) -> None:
    code, err = interrupt_cli(
        csim,
        ["jog", "--frame", "joint", "--axis", "J1", "--dir", "-", "--ratio", "20", "--seconds", "30"],
        lambda s: s.jogging,
    )
    assert code == ExitCode.INTERRUPTED
    assert one_line_error(err) == "teachpad-cli: error: interrupted"
    state = csim.state()
    assert not state.teach_enabled and not state.jogging and state.teach_ratio == 0
    # ratio 0 (GV203 = regs 406-407) was written after the jog started, then 440 <- 0x81
    assert csim.writes[-1].address == 440 and csim.writes[-1].values == (0x81,)


def test_jog_killed_mid_jog_is_stopped_by_the_simulator_watchdog(csim: Any) -> None:
    """kill -9 leaves no chance to clean up: the simulator's watchdog sees the connection close."""
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "app.cli.main",
            "--port",
            str(csim.port),
            "jog",
            "--frame",
            "base",
            "--axis",
            "X",
            "--dir",
            "-",
            "--ratio",
            "30",
            "--seconds",
            "30",
        ],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert csim.wait_for(lambda s: s.jogging, CHILD_TIMEOUT)
        start = csim.state()
        assert csim.wait_for(lambda s: s.pose != start.pose, 5.0)  # the arm moves
        killed = time.monotonic()
        proc.kill()  # SIGKILL
        proc.communicate(timeout=CHILD_TIMEOUT)
        assert csim.wait_for(lambda s: not s.jogging, 2.0)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate(timeout=CHILD_TIMEOUT)
    (event,) = csim.watchdog_events()
    assert event.t - killed < 0.25, f"stopped {event.t - killed:.3f} s after the kill"
    assert csim.state().teach_ratio == 0
    # the CLI never wrote ratio 0: only its start of the jog is in the write log
    ratio_writes = csim.writes_to(407)  # GV203's high word (30.0 = 0x41F0 0000)
    assert ratio_writes and ratio_writes[-1].values == (0x41F0,) and ratio_writes[-1].t < killed
    before = csim.state()
    assert csim.wait_for(lambda s: s.t > before.t + 0.1, 5.0)
    assert csim.state().pose == before.pose


def test_jog_is_bounded_in_time(csim: Any, capsys: pytest.CaptureFixture[str]) -> None:
    from app.cli.controller import JOG_SECONDS_DEFAULT
    from app.cli.format import JOG_SECONDS_MAX
    from app.cli.main import build_parser

    args = build_parser().parse_args(["jog", "--axis", "X", "--dir", "+", "--ratio", "10"])
    assert args.duration == JOG_SECONDS_DEFAULT == 2.0 and JOG_SECONDS_MAX == 30.0
    code, _, err = run(csim, capsys, "jog", "--axis", "X", "--dir", "+", "--ratio", "10", "--seconds", "31")
    assert code == ExitCode.USAGE and "at most 30 s" in err
    started = time.monotonic()
    code, _, _ = run(csim, capsys, "jog", "--axis", "X", "--dir", "+", "--ratio", "10", "--seconds", "0.3")
    assert code == ExitCode.OK and time.monotonic() - started < 5.0
    ratio_writes = csim.writes_to(407)  # GV203's high word (10.0 = 0x4120 0000)
    jog = next(w for w in ratio_writes if w.values == (0x4120,))
    assert ratio_writes[-1].values == (0,)
    assert 0.3 <= ratio_writes[-1].t - jog.t < 1.5
    assert not csim.state().teach_enabled


def test_jog_errors(csim: Any, capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run(csim, capsys, "jog", "--axis", "J7", "--dir", "+", "--ratio", "10", "--for", "1")
    assert code == ExitCode.USAGE and "axis 'J7' does not exist" in one_line_error(err)
    code, _, err = run(csim, capsys, "jog", "--axis", "X", "--dir", "up", "--ratio", "10", "--for", "1")
    assert code == ExitCode.USAGE and "direction must be + or -" in one_line_error(err)
    code, _, err = run(csim, capsys, "jog", "--axis", "X", "--dir", "+", "--ratio", "150", "--for", "1")
    assert code == ExitCode.USAGE and "ratio" in one_line_error(err)
    assert csim.writes == []
    code, _, err = run(
        csim, capsys, "--monitor-only", "jog", "--axis", "X", "--dir", "+", "--ratio", "10", "--for", "1"
    )
    assert code == ExitCode.FAILED and "monitor-only" in one_line_error(err)
    assert csim.writes == []


@pytest.mark.usefixtures("open_envelope")  # a move without --project: no keep-in box
def test_motion_commands(csim: Any, capsys: pytest.CaptureFixture[str]) -> None:
    x0, y0, z0 = csim.state().pose[:3]
    code, out, err = run(csim, capsys, "step", "--frame", "base", "X=10", "z=-5", "--speed", "200")
    assert code == ExitCode.OK, err
    assert "incremental move (base): done" in out
    assert csim.state().pose[0] == pytest.approx(x0 + 10, abs=0.01)
    assert csim.state().pose[2] == pytest.approx(z0 - 5, abs=0.01)
    code, out, _ = run(csim, capsys, "step", "--frame", "joint", "J1=5", "J7=3")
    assert code == ExitCode.OK and csim.state().joints[6] == pytest.approx(3, abs=0.01)
    code, out, _ = run(
        csim, capsys, "point", "create", "5", "--xyzabc", str(x0), str(y0 + 30), str(z0), "180", "0", "0"
    )
    assert code == ExitCode.OK and "point 5: create temp point: success" in out
    code, out, _ = run(csim, capsys, "point", "create", "6", "--from-pose")
    assert code == ExitCode.OK and out.strip().splitlines()[-1].startswith("pose X=")
    assert 6 in csim.state().points
    code, out, err = run(csim, capsys, "move", "5", "--speed", "400")
    assert code == ExitCode.OK, err
    assert csim.state().pose[1] == pytest.approx(y0 + 30, abs=0.05)
    # the arm stands on point 5: the arc needs a middle point of its own
    code, out, _ = run(
        csim, capsys, "point", "create", "7", "--xyzabc", str(x0 + 25), str(y0 + 20), str(z0), "180", "0", "0"
    )
    assert code == ExitCode.OK
    code, out, err = run(
        csim, capsys, "move", "6", "--via", "7", "--ignore-middle", "--keep-orientation", "--speed", "400"
    )
    assert code == ExitCode.OK, err
    code, out, err = run(csim, capsys, "move", "6", "--via", "6", "--speed", "400")
    assert code == ExitCode.USAGE and "middle point must differ" in one_line_error(err)
    code, _, err = run(csim, capsys, "move", "99")
    assert code == ExitCode.FAILED
    assert one_line_error(err) == (
        "teachpad-cli: error: move to temp point refused: bad end point id (status 13)"
    )


def test_plain_commands(csim: Any, capsys: pytest.CaptureFixture[str]) -> None:
    assert run(csim, capsys, "mode", "manual")[0] == ExitCode.OK
    assert csim.state().work_mode is WorkMode.MANUAL
    assert run(csim, capsys, "mode", "auto")[0] == ExitCode.OK
    code, out, _ = run(csim, capsys, "program", "run", "2", "--mode", "single", "--speed", "50", "--no-wait")
    assert code == ExitCode.OK and out == "run program 2: started (under way; its end is not waited for)\n"
    assert csim.state().moving
    code, out, _ = run(csim, capsys, "pause")
    assert code == ExitCode.OK and out == "pause: done (the program state reads paused)\n"
    assert csim.state().paused
    assert run(csim, capsys, "resume")[0] == ExitCode.OK
    assert not csim.state().paused
    assert run(csim, capsys, "stop")[1] == "stop: done (the arm stands still)\n"
    assert not csim.state().moving
    code, out, _ = run(csim, capsys, "zero", "J2")  # waits until the arm stands at zero
    assert code == ExitCode.OK and out == "go to zero (J2): done\n"
    assert csim.writes_to(445)[-1].values == (1,)
    assert not csim.state().moving and csim.state().joints[1] == pytest.approx(0.0, abs=0.01)
    code, _, err = run(csim, capsys, "zero", "J12")
    assert code == ExitCode.USAGE and "J1..J11" in one_line_error(err)


def test_read_write_and_watch(csim: Any, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(csim, capsys, "write", "200", "30", "-1.5")
    assert code == ExitCode.OK and "(0000 41F0 0000 BFC0)" in out
    code, out, _ = run(csim, capsys, "read", "200", "2")
    assert out.splitlines() == ["GV200 = 30.0  (0000 41F0)", "GV201 = -1.5  (0000 BFC0)"]
    code, _, err = run(csim, capsys, "write", "220", "1")
    assert code == ExitCode.USAGE and "control registers" in one_line_error(err)
    code, out, _ = run(csim, capsys, *ROOMY_POLL, "watch", "--rate", "100", "--count", "3")
    lines = out.splitlines()
    assert code == ExitCode.OK and len(lines) == 3
    assert all(line.startswith("t=") and "mode=auto" in line and "cmd=" in line for line in lines)


def test_link_errors_exit_3(sim: Any, capsys: pytest.CaptureFixture[str]) -> None:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        free = s.getsockname()[1]
    code = main(["--port", str(free), "--timeout", "0.3", "status"])
    _, err = capsys.readouterr()
    assert code == ExitCode.LINK
    assert one_line_error(err) == (
        f"teachpad-cli: error: cannot connect to the controller at 127.0.0.1:{free}: connection refused"
    )
    sim.set_silent(True)
    code, _, err = run(sim, capsys, "--poll-timeout", "0.2", "status", "--json")
    assert code == ExitCode.LINK
    assert one_line_error(err) == (
        f"teachpad-cli: error: controller did not answer within 0.2 s (127.0.0.1:{sim.port})"
    )


def test_failures_exit_1_and_usage_exit_2(sim: Any, capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run(sim, capsys, "--monitor-only", "mode", "auto")
    assert code == ExitCode.FAILED
    assert one_line_error(err) == (
        "teachpad-cli: error: monitor-only mode: write to register 444 (GV222_L) was not sent"
    )
    sim.set_exception(ExcCodes.ILLEGAL_ADDRESS, range(441, 442))
    code, _, err = run(sim, capsys, "stop")
    assert code == ExitCode.FAILED
    assert one_line_error(err) == (
        "teachpad-cli: error: controller refused write to register 441 (GV220_H): illegal data address"
    )
    sim.set_exception(None)
    code, _, err = run(sim, capsys, "step", "--frame", "base", "X=abc")
    assert code == ExitCode.USAGE and "'abc' is not a number" in one_line_error(err)
    code, _, err = run(sim, capsys, "step", "--frame", "joint", "X=1")
    assert code == ExitCode.USAGE and "not valid for a joint step" in one_line_error(err)
    code, _, err = run(sim, capsys, "point", "create", "20000")
    assert code == ExitCode.USAGE and "point id must be in 0..10000" in one_line_error(err)
    assert sim.writes == []
    assert main(["nonsense"]) == ExitCode.USAGE
    assert "invalid choice" in capsys.readouterr().err
    assert main(["--help"]) == ExitCode.OK
    assert "exit codes" in capsys.readouterr().out


def test_rtu_framing_option(sim_factory: Any, capsys: pytest.CaptureFixture[str]) -> None:
    sim = sim_factory(framer="rtu")
    code, out, err = run(sim, capsys, "--framer", "rtu", *ROOMY_POLL, "status", "--json")
    assert code == ExitCode.OK, err
    assert json.loads(out)["mode"]["name"] == "auto"


def test_entry_point_module_runs() -> None:
    env = dict(os.environ)
    proc = subprocess.run(
        [sys.executable, "-m", "app.cli.main", "--help"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        env=env,
        timeout=30,
        check=False,
    )
    assert proc.returncode == 0 and "teachpad-cli" in proc.stdout


def test_interrupted_move_is_stopped(csim: Any) -> None:
    code, err = interrupt_cli(csim, ["step", "--frame", "base", "Y=100", "--speed", "20"], lambda s: s.moving)
    assert code == ExitCode.INTERRUPTED
    assert err.splitlines() == [
        "teachpad-cli: warning: interrupted: stop sent",
        "teachpad-cli: error: interrupted",
    ]
    assert csim.wait_for(lambda s: not s.moving, 2.0)
    assert csim.writes[-1].address == 441
