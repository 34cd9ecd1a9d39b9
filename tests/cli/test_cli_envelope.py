"""Issue 19 §5: the safety envelope binds teachpad-cli as it binds the GUI (app/cli/guard.py).

Asserted at the simulator: its pose and its write log."""

from __future__ import annotations

import shutil
from pathlib import Path
from typing import Any

import pytest

from app.cli.exit_codes import ExitCode
from app.cli.main import main
from app.safety.audit import default_audit_dir
from app.safety.audit_read import Result, query
from app.safety.box import Box
from app.safety.envelope import Envelope
from tests.cli.conftest import save_envelope
from tests.cli.test_cli_points import SAMPLES

SCAN = 0.02
GV203_HIGH = 407  # the jog ratio's high word: 20.0 = 0x41A0 0000, 100.0 = 0x42C8 0000


def run(sim: Any, capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(["--port", str(sim.port), "--timeout", "3", *argv])
    out, err = capsys.readouterr()
    return code, out, err


def one_line(err: str) -> str:
    lines = [line for line in err.strip().splitlines() if "warning" not in line]
    assert len(lines) == 1 and "Traceback" not in err, err
    return lines[0]


@pytest.fixture
def csim(sim_factory: Any) -> Any:
    return sim_factory(command_latency=SCAN)


def box_around(sim: Any, half: float = 100.0, *, z_above: float | None = None) -> Box:
    x, y, z = sim.state().pose[:3]
    hi_z = z + (half if z_above is None else z_above)
    return Box("cell", (x - half, y - half, z - half), (x + half, y + half, hi_z))


def test_the_issues_step_through_the_box_and_the_speed_cap_is_refused(
    csim: Any, capsys: pytest.CaptureFixture[str]
) -> None:
    """`step X=150 --speed 400` with a keep-in box 100 mm around the arm and a 100 mm/s cap:
    refused in one sentence, exit 1, no write at the simulator, the arm where it was."""
    save_envelope(Envelope(keep_in=box_around(csim), max_speed=100.0))
    before = csim.state().pose
    writes = len(csim.writes)
    code, _, err = run(csim, capsys, "step", "--frame", "base", "X=150", "--speed", "400")
    assert code == ExitCode.FAILED
    assert one_line(err) == (
        "teachpad-cli: error: step refused: speed 400 mm/s is above the 100 mm/s allowed"
    )
    code, _, err = run(csim, capsys, "step", "--frame", "base", "X=150", "--speed", "50")
    assert code == ExitCode.FAILED
    assert "step refused: X = " in one_line(err) and "outside the allowed work space" in err
    assert len(csim.writes) == writes and csim.state().pose == before
    refused = [r for r in query(default_audit_dir()) if r.result == Result.REFUSED]
    assert [r.command for r in refused][-2:] == ["step", "step"]
    # inside the box and under the cap it goes
    code, _, err = run(csim, capsys, "step", "--frame", "base", "X=20", "--speed", "50")
    assert code == ExitCode.OK, err
    assert csim.state().pose[0] == pytest.approx(before[0] + 20, abs=0.01)


def test_a_joint_step_past_a_joint_limit_is_refused(csim: Any, capsys: pytest.CaptureFixture[str]) -> None:
    j1 = csim.state().joints[0]
    save_envelope(Envelope(joint_limits=((j1 - 10, j1 + 10),) + ((-180.0, 180.0),) * 5))
    writes = len(csim.writes)
    code, _, err = run(csim, capsys, "step", "--frame", "joint", "J1=15")
    assert code == ExitCode.FAILED and "step refused: J1 = " in one_line(err)
    assert len(csim.writes) == writes


def test_the_issues_jog_at_ratio_100_goes_at_the_20_percent_cap(
    csim: Any, capsys: pytest.CaptureFixture[str]
) -> None:
    save_envelope(Envelope(max_jog_ratio=20.0))
    code, _, err = run(csim, capsys, "jog", "--axis", "X", "--dir", "+", "--ratio", "100", "--seconds", "0.3")
    assert code == ExitCode.OK, err
    assert "ratio 100 % capped at 20 %" in err
    ratios = [w.values[0] for w in csim.writes_to(GV203_HIGH)]
    assert 0x42C8 not in ratios and 0x41A0 in ratios and ratios[-1] == 0


def test_a_jog_towards_the_box_wall_stops_before_it(csim: Any, capsys: pytest.CaptureFixture[str]) -> None:
    """Z + at 20 % (50 mm/s) for 5 s would go 250 mm; the wall is 40 mm above: the jog guard
    (the GUI's, watching the pose) stops it inside, exit 1 in words."""
    box = box_around(csim, 400.0, z_above=40.0)
    save_envelope(Envelope(keep_in=box))
    z0 = csim.state().pose[2]
    code, out, err = run(csim, capsys, "jog", "--axis", "Z", "--dir", "+", "--ratio", "20", "--seconds", "5")
    assert code == ExitCode.FAILED
    assert "jog stopped before the limit: Z = " in one_line(err)
    z = csim.state().pose[2]
    assert z0 + 5.0 < z <= box.hi[2], (z0, z, box.hi[2])
    assert not csim.state().jogging and not csim.state().teach_enabled
    assert out.strip().splitlines()[-1].startswith("pose X=")
    # a jog that would have to stop at once (the wall 3 mm above, within its look-ahead) is
    # refused: nothing is written
    save_envelope(Envelope(keep_in=box_around(csim, 400.0, z_above=3.0)))
    writes = len(csim.writes)
    code, _, err = run(csim, capsys, "jog", "--axis", "Z", "--dir", "+", "--ratio", "20", "--seconds", "5")
    assert code == ExitCode.FAILED and "jog refused: " in one_line(err)
    assert len(csim.writes) == writes
    # and back out, away from the wall, it goes
    code, _, err = run(csim, capsys, "jog", "--axis", "Z", "--dir", "-", "--ratio", "20", "--seconds", "0.3")
    assert code == ExitCode.OK, err
    assert csim.state().pose[2] < z
    assert csim.state().pose[2] <= box.hi[2]


def test_a_move_the_host_cannot_check_is_refused(csim: Any, capsys: pytest.CaptureFixture[str]) -> None:
    """A fresh install's envelope has a keep-in box: a point the CLI holds no copy of (no
    --project) cannot be checked against it, so the move is refused, nothing written."""
    x, y, z = csim.state().pose[:3]
    code, _, err = run(
        csim, capsys, "point", "create", "5", "--xyzabc", str(x), str(y + 30), str(z), "180", "0", "0"
    )
    assert code == ExitCode.OK, err
    writes = len(csim.writes)
    code, _, err = run(csim, capsys, "move", "5", "--speed", "50")
    assert code == ExitCode.FAILED
    assert "move to point refused: P5 cannot be checked against the safety envelope" in one_line(err)
    assert len(csim.writes) == writes and csim.state().pose[:3] == pytest.approx((x, y, z))


def test_run_checks_its_plan_against_the_envelope_in_force(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Without --safety, `run` checks the plan against the GUI's envelope (it checked none)."""
    demo = tmp_path / "demo.teachpad.json"
    shutil.copy(SAMPLES / "demo.teachpad.json", demo)
    assert main(["run", str(demo), "--plan", "circle", "--check"]) == ExitCode.OK
    capsys.readouterr()
    save_envelope(Envelope(keep_in=Box("cell", (9000.0,) * 3, (9001.0,) * 3)))
    assert main(["run", str(demo), "--plan", "circle", "--check"]) == ExitCode.FAILED
    err = capsys.readouterr().err
    assert "outside the allowed work space" in err and "(outside the safety envelope): not running it" in err
