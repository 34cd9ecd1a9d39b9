"""``teachpad-sim --controllers N``: N controllers from one process, each on its own port with its
own arm and program, stopped together; and :class:`~app.sim.fleet.SimFleet`, the same in-process."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import pytest

from app.protocol.enums import ProgramState
from app.protocol.registers import POSE_BLOCK_COUNT, POSE_BLOCK_START
from app.sim.cli import main
from app.sim.config import SimConfig
from app.sim.fleet import SimFleet
from tests.sim.conftest import Bus, poll
from tests.waits import CHILD_TIMEOUT, read_line

ROOT = Path(__file__).resolve().parents[2]


def _connect_refused(port: int) -> bool:
    import socket

    try:
        socket.create_connection(("127.0.0.1", port), timeout=1.0).close()
    except OSError:
        return True
    return False


def test_three_controllers_from_one_process_answer_on_three_ports_with_distinct_arms_and_stop_together(
    make_bus: Callable[..., Bus],
) -> None:
    env = dict(os.environ, PYTHONPATH=str(ROOT), PYTHONUNBUFFERED="1")
    with subprocess.Popen(
        [sys.executable, "-m", "app.sim.cli", "--port", "0", "--controllers", "3"],
        cwd=ROOT,
        env=env,
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    ) as proc:
        try:
            assert proc.stdout is not None
            ports = []
            for i in range(3):
                line = read_line(proc.stdout, f"teachpad-sim's line for controller {i + 1}")
                match = re.search(r"listening on 127\.0\.0\.1:(\d+)", line)
                assert match, line
                ports.append(int(match.group(1)))
            assert len(set(ports)) == 3 and len({os.getpid(), proc.pid}) == 2
            buses = [make_bus(port) for port in ports]
            joints = [bus.joints() for bus in buses]
            assert len({tuple(round(j, 3) for j in js[:6]) for js in joints}) == 3  # three arms
            for bus in buses:  # each runs its program
                poll(bus.program_state, lambda s: s == int(ProgramState.RUNNING))

            def blocks() -> list[list[int]]:  # pose, external axes and joints (program 3 moves J7 only)
                return [bus.read(POSE_BLOCK_START, POSE_BLOCK_COUNT) for bus in buses]

            first = blocks()
            poll(blocks, lambda now: all(a != b for a, b in zip(now, first, strict=True)))
            for bus in buses:
                bus.close()
            proc.send_signal(signal.SIGTERM)
            out, err = proc.communicate(timeout=10)
            assert proc.returncode == 0, err
            assert out.strip().endswith("teachpad-sim stopped")
            assert all(_connect_refused(port) for port in ports)  # all three stopped with the process
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.communicate(timeout=CHILD_TIMEOUT)


def test_controllers_is_a_number_in_range_and_tcp_only(capsys: pytest.CaptureFixture[str]) -> None:
    for argv in (
        ["--controllers", "0"],
        ["--controllers", "x"],
        ["--controllers", "2", "--serial", "/dev/null"],
    ):
        with pytest.raises(SystemExit) as info:
            main(argv)
        assert info.value.code == 2
    err = capsys.readouterr().err
    assert "--controllers must be 1..256, got 0" in err and "expected a number of controllers" in err
    assert "cannot be used with --serial" in err


def test_a_fleet_in_process_distinct_ports_arms_programs_and_stops_together() -> None:
    fleet = SimFleet(4, SimConfig(host="127.0.0.1", port=0), programs=True)
    with fleet:
        assert len(set(fleet.ports)) == 4
        states = [sim.state() for sim in fleet]
        assert len({s.joints[:6] for s in states}) == 4
        assert all(s.program_state is ProgramState.RUNNING for s in states)
        assert len({sim.robot.program.program_id for sim in fleet if sim.robot.program}) == 3
        buses = [Bus(port) for port in fleet.ports]
        assert all(bus.mode() == 1 for bus in buses)
        for bus in buses:
            bus.close()
    poll(lambda: all(_connect_refused(p) for p in fleet.ports), bool)
    assert not any(sim.running for sim in fleet)
