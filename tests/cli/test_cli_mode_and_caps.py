"""teachpad-cli and the operator's decisions (issue 18): a controller in manual mode is not
switched to auto without ``--auto``, and ``--reduced-speed`` caps every motion -- asserted at
the simulator's write log."""

from __future__ import annotations

from typing import Any

import pytest

from app.cli.exit_codes import ExitCode
from app.cli.main import main
from app.protocol import registers
from app.protocol.codec import WordOrder, registers_to_float
from app.protocol.enums import WorkMode
from app.safety.envelope import REDUCED_SPEED_DEFAULT, Envelope
from app.view3d.profile import default_profile

SCAN = 0.02  # see tests/link/test_client_sim.py


def run(sim: Any, capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(["--port", str(sim.port), *argv])
    out, err = capsys.readouterr()
    return code, out, err


def register_values(sim: Any, address: int) -> list[int]:
    """Every value written to one register, in order (single writes and blocks alike)."""
    return [
        w.values[address - w.address] for w in sim.writes if w.address <= address < w.address + len(w.values)
    ]


def gv_values(sim: Any, gv: int, since: int = 0) -> list[float]:
    """Every float written to GVn (both of its registers in one write), in order, from the
    ``since``-th write on."""
    low = registers.gv_reg(gv)
    out = []
    for w in sim.writes[since:]:
        start = low - w.address
        if start >= 0 and start + 2 <= len(w.values):
            out.append(registers_to_float(list(w.values[start : start + 2]), WordOrder.LOW_FIRST))
    return out


@pytest.fixture
def manual_sim(sim_factory: Any) -> Any:
    return sim_factory(command_latency=SCAN, work_mode=WorkMode.MANUAL)


@pytest.fixture
def csim(sim_factory: Any) -> Any:
    return sim_factory(command_latency=SCAN)


@pytest.mark.parametrize("argv", [("zero", "all"), ("program", "run", "2")], ids=["zero", "program run"])
def test_manual_mode_is_refused_without_auto_and_nothing_is_written(
    manual_sim: Any, capsys: pytest.CaptureFixture[str], argv: tuple[str, ...]
) -> None:
    code, out, err = run(manual_sim, capsys, *argv)
    assert code == ExitCode.FAILED, err
    assert out == "" and "Traceback" not in err
    assert "the controller is in manual mode" in err and "--auto" in err
    assert manual_sim.writes == []  # no 444, no 445, no 446..449, no 440
    assert manual_sim.state().work_mode is WorkMode.MANUAL


def test_auto_switches_the_mode_first_as_its_own_write(
    manual_sim: Any, capsys: pytest.CaptureFixture[str]
) -> None:
    code, _, err = run(manual_sim, capsys, "zero", "J2", "--auto")
    assert code == ExitCode.OK, err
    assert [(w.address, w.values) for w in manual_sim.writes] == [
        (registers.REG_WORK_MODE, (1,)),  # its own 0x06, before the command
        (registers.REG_GO_ZERO, (1,)),
    ]
    assert manual_sim.state().work_mode is WorkMode.AUTO


def test_help_says_what_manual_mode_does(capsys: pytest.CaptureFixture[str]) -> None:
    for argv in (["zero", "--help"], ["program", "run", "--help"]):
        assert main(argv) == 0
        out = " ".join(capsys.readouterr().out.split())
        assert "--auto" in out and "manual mode is refused (exit 1, nothing written)" in out
    assert main(["--help"]) == 0
    assert "--reduced-speed" in capsys.readouterr().out


@pytest.mark.usefixtures("open_envelope")  # a move without --project: no keep-in box
def test_reduced_speed_caps_the_program_run_step_move_and_jog(
    csim: Any, capsys: pytest.CaptureFixture[str]
) -> None:
    caps = Envelope().motion_caps(default_profile().reach)
    code, _, err = run(csim, capsys, "--reduced-speed", "program", "run", "2", "--speed", "100")
    assert code == ExitCode.OK, err
    assert "reduced speed: motions capped at 10 %" in err
    assert register_values(csim, registers.REG_PROGRAM_SPEED) == [10]  # asked 100 %
    assert run(csim, capsys, "stop")[0] == ExitCode.OK
    assert csim.wait_for(lambda s: not s.moving, 5.0)

    code, _, err = run(csim, capsys, "--reduced-speed", "step", "--frame", "joint", "J1=2", "--speed", "5")
    assert code == ExitCode.OK, err
    speeds = gv_values(csim, registers.GV_EXPECTED_SPEED)
    assert speeds[-1] == pytest.approx(caps.joint_rpm_cap, rel=1e-5) and caps.joint_rpm_cap < 5

    # point 7 here, then a 5 mm step away: the move back to it moves (a move of no length is
    # judged only by GV291's bounce off 255, which a poll spaced wider than the bounce -- a loaded
    # machine -- misses and rightly reads "outcome unknown")
    assert run(csim, capsys, "point", "create", "7")[0] == ExitCode.OK
    code, _, err = run(csim, capsys, "--reduced-speed", "step", "--frame", "base", "Z=-5", "--speed", "500")
    assert code == ExitCode.OK, err
    assert gv_values(csim, registers.GV_EXPECTED_SPEED)[-1] == REDUCED_SPEED_DEFAULT

    code, _, err = run(csim, capsys, "--reduced-speed", "move", "7", "--speed", "800")
    assert code == ExitCode.OK, err
    assert gv_values(csim, registers.GV_EXPECTED_SPEED)[-1] == REDUCED_SPEED_DEFAULT

    before = len(csim.writes)
    code, _, err = run(
        csim,
        capsys,
        "--reduced-speed",
        "jog",
        "--axis",
        "Z",
        "--dir",
        "-",
        "--ratio",
        "50",
        "--seconds",
        "0.2",
    )
    assert code == ExitCode.OK, err
    ratios = gv_values(csim, registers.GV_PARAM3, since=before)  # the enable's 0, the ratio, the stop's 0
    assert max(ratios) == 10.0  # the jog went out at the cap, not at 50 %


def test_reduced_speed_refuses_go_to_zero(csim: Any, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(csim, capsys, "--reduced-speed", "zero", "all")
    assert code == ExitCode.FAILED and out == ""
    assert "go to zero refused in reduced-speed mode" in err and "Traceback" not in err
    assert csim.writes == []
