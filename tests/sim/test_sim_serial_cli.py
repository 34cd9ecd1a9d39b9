"""``teachpad-sim --serial PORT`` serves RTU on a serial device; ``--watchdog`` sets the watchdog."""

from __future__ import annotations

import io
import signal
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from app.connection import ConnectionSettings
from app.link.client import RobotClient
from app.sim.cli import build_parser, execute
from app.sim.guard import WATCHDOG_TIMEOUT
from tests.link.serial.relay import PtyRelay
from tests.waits import CHILD_TIMEOUT, kill_child, read_line

ROOT = Path(__file__).resolve().parents[2]


def test_watchdog_and_serial_flags_parse() -> None:
    parser = build_parser()
    args = parser.parse_args([])
    assert args.watchdog == WATCHDOG_TIMEOUT and args.serial is None and args.baud == 115200
    assert parser.parse_args(["--watchdog", "off"]).watchdog is None
    assert parser.parse_args(["--watchdog", "0.5"]).watchdog == 0.5
    for bad in ("soon", "-1", "100"):
        with pytest.raises(SystemExit):
            parser.parse_args(["--watchdog", bad])
    args = parser.parse_args(
        ["--serial", "/dev/ttyUSB0", "--baud", "9600", "--parity", "E", "--stopbits", "2"]
    )
    assert (args.serial, args.baud, args.parity, args.stopbits) == ("/dev/ttyUSB0", 9600, "E", 2)


def test_teachpad_sim_serves_a_serial_line() -> None:
    relay = PtyRelay(57600)
    proc = subprocess.Popen(
        [sys.executable, "-m", "app.sim.cli", "--serial", relay.sim_port, "--baud", "57600", "--no-stdin"],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    client = RobotClient(ConnectionSettings(serial_port=relay.host_port, baudrate=57600, timeout=0.5))
    try:
        assert proc.stdout is not None
        banner = read_line(proc.stdout, "teachpad-sim's banner")
        assert f"listening on {relay.sim_port} (57600 baud, 8N1)" in banner
        client.connect()
        assert client.read_status().mode == 1
    finally:
        client.close()
        proc.send_signal(signal.SIGTERM)
        try:
            out, err = proc.communicate(timeout=CHILD_TIMEOUT)
        finally:
            kill_child(proc)  # only when it did not stop by itself
            relay.close()
    assert proc.returncode == 0, err
    assert "teachpad-sim stopped" in out


def test_watchdog_stdin_command(sim_factory: Any) -> None:
    sim = sim_factory()
    out = io.StringIO()
    assert execute(sim, "watchdog off", out) and not sim.watchdog.enabled
    assert execute(sim, "watchdog 0.5", out) and sim.watchdog.timeout == 0.5
    assert execute(sim, "watchdog soon", out) and "bad command" in out.getvalue()
