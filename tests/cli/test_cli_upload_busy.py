"""``teachpad-cli points upload`` through a controller *busy* (Modbus exception 6) for a while:
backed off and sent again, every point created at its pose, exit 0 (issue 19 section 4)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from pymodbus.constants import ExcCodes

from app import timing
from app.cli.exit_codes import ExitCode
from app.points.project import load_project
from app.protocol import registers
from tests.cli.test_cli import run
from tests.cli.test_cli_points_upload import _project

N = 40
WINDOW = 1.0  # s


def test_points_upload_backs_off_a_busy_controller(
    sim_factory: Any, capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(timing, "BUSY_RETRY_BUDGET", 10 * WINDOW)  # roomy: the window is the subject
    sim = sim_factory(command_latency=0.005)
    project = _project(sim, capsys, tmp_path, N)
    sim.set_exception(ExcCodes.DEVICE_BUSY, after_write=registers.REG_RUN_COMMAND, seconds=WINDOW)
    code, out, err = run(sim, capsys, "points", "upload", str(project))
    assert code == ExitCode.OK, err
    assert f"uploaded {N} point(s)" in out
    assert sim.exceptions_answered > 3
    held = sim.state().points
    assert all(held[i] == (300.0 + i, -i, 400.0, 180.0, 0.0, float(i % 90)) for i in range(1, N + 1))
    assert sorted(load_project(project).upload_history) == list(range(1, N + 1))
