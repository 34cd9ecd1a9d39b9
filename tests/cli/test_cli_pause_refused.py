"""``teachpad-cli pause`` against a controller that answers the Pause *busy* (issue 19, item 1:
the same for every write that stops motion, in the CLI too).

The old code wrote 442 once: refused, it exited 1 with the exception and the program ran on; a
refusal for a moment (exception 6 means "try again later") never paused it. Now 442 goes out
again every poll until the controller answers and the pose is seen still; not answered within
``timing.PAUSE_ESCALATE_AFTER`` s, a Stop instead, and the CLI says the arm was stopped, not
paused (exit 1). Asserted at the simulator: its program state and write log.
"""

from __future__ import annotations

import time
from typing import Any

import pytest
from pymodbus.constants import ExcCodes

from app import timing
from app.cli.exit_codes import ExitCode
from app.cli.main import main
from app.protocol import registers
from app.protocol.enums import ProgramMotionMode, ProgramState

pytestmark = pytest.mark.timeout(60)

BUSY = ExcCodes.DEVICE_BUSY  # Modbus exception 6
PAUSE_REGISTER = range(registers.REG_PAUSE, registers.REG_PAUSE + 1)
BUSY_FOR = 1.0  # s the controller answers the Pause "busy"
PAUSED_WITHIN = 0.5  # s from the end of the refusals to the pause taken (a poll is 50 ms)
WAIT = 10.0  # s for the simulator to show what the test waits for


def _running(sim: Any, make_client: Any) -> None:
    make_client(sim).run_program(1, ProgramMotionMode.CYCLE, 0, 20)
    assert sim.wait_for(lambda s: s.program_state == ProgramState.RUNNING, timeout=WAIT)


def test_pause_refused_as_busy_for_a_second_goes_out_again_and_pauses(
    sim: Any, capsys: pytest.CaptureFixture[str], make_client: Any
) -> None:
    _running(sim, make_client)
    sim.set_exception(BUSY, PAUSE_REGISTER, seconds=BUSY_FOR)
    busy_until = time.monotonic() + BUSY_FOR
    code = main(["--port", str(sim.port), "pause"])
    out, err = capsys.readouterr()
    state = sim.state()
    assert state.program_state == ProgramState.PAUSED and state.paused, err  # old: exit 1, running
    assert code == ExitCode.OK, err
    taken = sim.writes_to(registers.REG_PAUSE)
    assert len(taken) == 1 and taken[0].t - busy_until < PAUSED_WITHIN
    assert not sim.writes_to(registers.REG_STOP)  # a busy second is not a Stop: resumable
    assert "refused or did not answer" in err and "took the pause (442)" in err, err
    assert "pause" in out


def test_pause_never_taken_becomes_a_stop_and_says_it_did_not_pause(
    sim: Any, capsys: pytest.CaptureFixture[str], make_client: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(timing, "PAUSE_ESCALATE_AFTER", 0.3)
    _running(sim, make_client)
    # busy past the bound (the simulator's busy 442 also refuses the pose block's reads)
    sim.set_exception(BUSY, PAUSE_REGISTER, seconds=BUSY_FOR)
    busy_until = time.monotonic() + BUSY_FOR
    code = main(["--port", str(sim.port), "pause"])
    _out, err = capsys.readouterr()
    assert code == ExitCode.FAILED, err
    assert "Stop (441) was sent instead" in err and "stopped, not paused" in err, err
    stops = sim.writes_to(registers.REG_STOP)
    assert [w.values for w in stops] == [(1,)] and stops[0].t < busy_until  # while it was busy
    assert not sim.state().moving and not sim.writes_to(registers.REG_PAUSE)
