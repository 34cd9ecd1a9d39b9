"""Another master on the controller while a teachpad-cli command runs (issue 19 section 2): the
CLI says so in a warning line, the audit trail records it, and the move's "done" -- which cannot
be told from the other master's -- is "outcome unknown" (exit 4)."""

from __future__ import annotations

import threading
from typing import Any

import pytest

from app.cli.exit_codes import ExitCode
from app.cli.main import main
from app.connection import ConnectionSettings
from app.link.client import RobotClient
from app.safety.audit import default_audit_dir
from tests.waits import join

pytestmark = pytest.mark.timeout(120)

STEP_MM = 12.0
SPEED = 4.0  # mm/s: a 3 s move, long enough for another master to write during it
FOREIGN_GV = 225  # the speed parameter (registers 450-451) another master writes mid-move


def test_another_master_writing_parameters_mid_move_is_said_by_the_cli(
    sim: Any, capsys: pytest.CaptureFixture[str]
) -> None:
    start_z = sim.state().pose[2]
    other = RobotClient(ConnectionSettings(host="127.0.0.1", port=sim.port, timeout=2.0))
    other.connect()

    stop = threading.Event()

    def another_master() -> None:  # writes a parameter once our move is seen under way
        while not stop.wait(0.01):
            if abs(sim.state().pose[2] - start_z) > 0.5:
                other.write_gv(FOREIGN_GV, [7.0])
                return

    thread = threading.Thread(target=another_master, daemon=True)
    thread.start()
    try:
        code = main(
            ["--port", str(sim.port), "step", "--frame", "base", f"Z=-{STEP_MM:g}", "--speed", f"{SPEED:g}"]
        )
    finally:
        stop.set()
        join(thread, "another master")
        other.close()
    _out, err = capsys.readouterr()
    assert code == ExitCode.UNKNOWN, err
    assert "another Modbus master was seen while it ran" in err
    assert "warning: another Modbus master is on this controller: register 451 changed" in err
    assert "Traceback" not in err
    records = [
        line
        for p in sorted(default_audit_dir().rglob("*"))
        if p.is_file()
        for line in p.read_text().splitlines()
    ]
    assert any("another Modbus master seen" in line for line in records)
