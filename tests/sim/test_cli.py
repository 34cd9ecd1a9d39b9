"""teachpad-sim: foreground process, stdin commands, clean stop on SIGTERM."""

from __future__ import annotations

import io
import os
import re
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import pytest

from app.protocol.enums import Alarm
from app.sim.cli import build_parser, execute, main
from app.sim.server import SimController
from tests.sim.conftest import Bus, poll
from tests.waits import CHILD_TIMEOUT, read_line

ROOT = Path(__file__).resolve().parents[2]


def test_help_lists_the_stdin_commands(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as info:
        main(["--help"])
    assert info.value.code == 0
    out = capsys.readouterr().out
    for word in (
        "--word-order",
        "--status-encoding",
        "--status-delay",
        "--rtu-framing",
        "alarm NAME on|off",
        "delay SECONDS",
        "drop",
        "exception CODE",
        "silent on|off",
        "restart",
    ):
        assert word in out
    args = build_parser().parse_args([])
    assert args.host == "127.0.0.1" and args.port == 5020 and args.unit == 1


def test_stdin_commands(sim: SimController, make_bus: Callable[..., Bus]) -> None:
    out = io.StringIO()
    assert execute(sim, "alarm estop on", out)
    assert sim.state().alarms == Alarm.ESTOP
    assert execute(sim, "alarm estop off", out)
    assert sim.state().alarms == Alarm.NONE
    assert execute(sim, "delay 0.01", out) and sim._delay_rule == (0.01, None, None)
    assert execute(sim, "delay 0", out)
    assert execute(sim, "status-delay 0.2", out) and sim._status_delay == 0.2
    assert execute(sim, "exception 6", out)
    bus = make_bus(sim.port)
    rr = bus.client.read_holding_registers(560, count=1, device_id=1)
    assert rr.isError() and rr.exception_code == 6
    assert execute(sim, "exception off", out)
    assert bus.mode() == 1
    assert execute(sim, "exception 6 0.05", out)  # busy for a window that lifts itself
    assert sim._exception_until is not None
    assert sim.wait_for(lambda _: not sim._exception_window_open(), 2)
    assert bus.mode() == 1
    assert execute(sim, "silent on", out) and sim._silent
    assert execute(sim, "silent off", out) and not sim._silent
    assert execute(sim, "drop", out)
    assert sim.wait_for(lambda _: sim.connections_count == 0, 2)
    assert execute(sim, "restart", out)
    assert execute(sim, "status", out)
    assert "pose " in out.getvalue() and "GV291" in out.getvalue()
    assert execute(sim, "bogus", out) and "unknown command" in out.getvalue()
    assert execute(sim, "delay x", out) and "bad command" in out.getvalue()
    assert not execute(sim, "quit", out)


def test_process_runs_takes_commands_and_stops_on_sigterm(make_bus: Callable[..., Bus]) -> None:
    env = dict(os.environ, PYTHONPATH=str(ROOT), PYTHONUNBUFFERED="1")
    with subprocess.Popen(
        [sys.executable, "-m", "app.sim.cli", "--port", "0"],
        cwd=ROOT,
        env=env,
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    ) as proc:
        try:
            assert proc.stdout is not None and proc.stdin is not None
            line = read_line(proc.stdout, "teachpad-sim's banner")
            match = re.search(r"listening on 127\.0\.0\.1:(\d+)", line)
            assert match, line
            bus = make_bus(int(match.group(1)))
            bus.write(444, 1)
            proc.stdin.write("alarm estop on\n")
            proc.stdin.flush()
            poll(bus.alarms, lambda a: a == int(Alarm.ESTOP))
            bus.close()
            t0 = time.monotonic()
            proc.send_signal(signal.SIGTERM)
            _out, err = proc.communicate(timeout=10)
            assert proc.returncode == 0, err
            assert time.monotonic() - t0 < 5
            assert "write fc=0x06 address=444" in err  # one log line per write
            assert "alarm ESTOP on" in err
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.communicate(timeout=CHILD_TIMEOUT)
