"""A long move from teachpad-cli (issue 18): the completion wait of a move that runs for 15 s (the
old overflow came at about 11 s).

The status backoff used to raise ``OverflowError`` about 11 s into any move (``2.0 ** reads`` at
the 1025th read). 15 mm at 1 mm/s keeps the simulator moving for 15 s of its own time: slow,
not far. (Ten minutes of the same wait are covered without the wall clock in
tests/link/test_tracker.py.)
"""

from __future__ import annotations

from typing import Any

import pytest

from app.cli.exit_codes import ExitCode
from app.cli.main import main

LONG_MOVE_MM = 15.0
LONG_MOVE_SPEED = 1.0  # mm/s: 15 s

pytestmark = pytest.mark.timeout(120)


def test_a_15_s_step_from_the_cli_ends_done(sim: Any, capsys: pytest.CaptureFixture[str]) -> None:
    z = sim.state().pose[2]
    code = main(
        [
            "--port",
            str(sim.port),
            "step",
            "--frame",
            "base",
            f"Z=-{LONG_MOVE_MM:g}",
            "--speed",
            f"{LONG_MOVE_SPEED:g}",
        ]
    )
    out, err = capsys.readouterr()
    assert code == ExitCode.OK, err
    assert "Traceback" not in err and err == ""
    assert "incremental move (base): done" in out
    assert sim.state().pose[2] == pytest.approx(z - LONG_MOVE_MM, abs=1e-3)
    steps = [w for w in sim.writes if w.address == 440 and w.values == (0x41,)]
    assert len(steps) == 1
