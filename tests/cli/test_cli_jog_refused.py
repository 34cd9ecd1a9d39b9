"""teachpad-cli and a controller that refuses the write that stops motion (issue 19, item 1).

``teachpad-cli jog`` used to warn "could not set the jog ratio to 0", exit 1 and leave the arm
jogging when the controller answered *busy* (Modbus exception 6) at the end of the jog. Now speed
0 goes out again every poll, a Stop (441) too after ``timing.HALT_ESCALATE_AFTER``, until the
controller answers and the pose is seen still, for ``timing.HALT_CONFIRM_BUDGET`` at most; then
it says what happened (app/link/halt.py). Asserted at the simulator: its pose and write log.
"""

from __future__ import annotations

import threading
import time
from typing import Any

import pytest
from pymodbus.constants import ExcCodes

from app import timing
from app.cli.exit_codes import ExitCode
from app.cli.main import main
from app.link.types import StepFrame
from app.protocol import registers
from app.sim.config import WriteRecord
from tests.ui.pendant_support import jogging, ratio_writes
from tests.waits import join

pytestmark = pytest.mark.timeout(60)

BUSY = ExcCodes.DEVICE_BUSY  # Modbus exception 6
RATIO_REGISTERS = range(registers.gv_reg(registers.GV_PARAM3), registers.gv_reg(registers.GV_PARAM3) + 2)
STOP_REGISTER = range(registers.REG_STOP, registers.REG_STOP + 1)
REFUSED_REQUESTS = 15  # requests answered "busy" before the controller answers again (~0.5-1 s)
STOPS_WITHIN = 1.0  # s from the controller's first good answer to the stop (a poll is 50 ms)
WAIT = 10.0  # s for the simulator to show what the test waits for


@pytest.fixture
def busy_sim(sim_factory: Any) -> Any:
    """No communication watchdog: nothing stops a jog but the host (the field report's controller)."""
    return sim_factory(watchdog=None)


def _jog(sim: Any, seconds: float) -> list[str]:
    return [
        "--port",
        str(sim.port),
        "jog",
        "--axis",
        "Z",
        "--dir",
        "+",
        "--ratio",
        "10",
        "--seconds",
        f"{seconds:g}",
    ]


class _Cli:
    """teachpad-cli's main() in a thread; the test turns the simulator's knobs meanwhile."""

    def __init__(self, argv: list[str]) -> None:
        self.code: int | None = None
        self._thread = threading.Thread(target=self._run, args=(argv,), name="test-cli", daemon=True)
        self._thread.start()

    def _run(self, argv: list[str]) -> None:
        self.code = main(argv)

    @property
    def running(self) -> bool:
        return self._thread.is_alive()

    def wait(self) -> int:
        join(self._thread, "teachpad-cli", timeout=30.0)
        assert self.code is not None
        return self.code


def _refused_for_a_while(sim: Any, cli: _Cli) -> None:
    """The controller answers "busy" to :data:`REFUSED_REQUESTS` requests (or until the CLI gave up)."""
    before = sim.requests_count
    deadline = time.monotonic() + WAIT
    while sim.requests_count < before + REFUSED_REQUESTS and cli.running:
        assert time.monotonic() < deadline, "the client sent nothing while the controller was busy"
        time.sleep(0.01)


def _halting(write: WriteRecord) -> bool:
    speed_zero = write.address == RATIO_REGISTERS.start and write.values == (0, 0)
    return speed_zero or (write.address == registers.REG_STOP and write.values == (1,))


def test_jog_busy_at_its_end_stops_the_arm_once_the_controller_answers(
    busy_sim: Any, capsys: pytest.CaptureFixture[str]
) -> None:
    """The field report's reproduction: jog Z+ at 10 %, busy for a while, then answering again."""
    sim = busy_sim
    cli = _Cli(_jog(sim, 3.0))
    assert sim.wait_for(lambda s: s.jogging and s.teach_ratio == 10.0, timeout=WAIT)
    sim.set_exception(BUSY)
    _refused_for_a_while(sim, cli)
    writes_before = len(sim.writes)
    sim.set_exception(None)
    answers_again = time.monotonic()
    code = cli.wait()
    _out, err = capsys.readouterr()
    assert not jogging(sim), err  # the old code: jogging on (until a watchdog or a teach disable)
    first = sim.writes[writes_before]
    assert _halting(first) and first.t - answers_again < STOPS_WITHIN
    assert not sim.state().teach_enabled  # teach mode off after the confirmed stop
    assert "could not set the jog ratio to 0" not in err
    assert "the arm stands still" in err
    # the jog itself ended early, at a status read the controller refused: said, exit 1
    assert code == ExitCode.FAILED and "server device busy" in err and "Traceback" not in err


def test_jog_whose_speed_0_is_refused_for_good_escalates_to_stop(
    busy_sim: Any, capsys: pytest.CaptureFixture[str]
) -> None:
    sim = busy_sim
    cli = _Cli(_jog(sim, 0.5))
    assert sim.wait_for(lambda s: s.jogging and s.teach_ratio == 10.0, timeout=WAIT)
    sim.set_exception(BUSY, RATIO_REGISTERS)  # speed 0 refused for good; 441 and the reads answer
    code = cli.wait()
    out, err = capsys.readouterr()
    assert not jogging(sim), err
    assert [w.values for w in sim.writes_to(registers.REG_STOP)] == [(1,)]
    assert "took the stop (441)" in err and "the arm stands still" in err
    assert code == ExitCode.OK and "pose" in out
    sim.set_exception(None)


def test_jog_never_confirmed_within_the_budget_says_so_and_exits_1(
    busy_sim: Any, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(timing, "HALT_CONFIRM_BUDGET", 1.0)
    sim = busy_sim
    cli = _Cli(_jog(sim, 3.0))
    assert sim.wait_for(lambda s: s.jogging, timeout=WAIT)
    sim.set_exception(BUSY)
    code = cli.wait()
    _out, err = capsys.readouterr()
    assert code == ExitCode.FAILED
    assert "did not confirm the jog's speed 0 and Stop (441)" in err
    assert "the arm may still be moving" in err and "teach mode was left on" in err
    assert jogging(sim)  # true: nothing got through
    sim.set_exception(None)


def test_jog_answered_at_once_writes_speed_0_once(busy_sim: Any, capsys: pytest.CaptureFixture[str]) -> None:
    sim = busy_sim
    code = main(_jog(sim, 0.2))
    _out, err = capsys.readouterr()
    assert code == ExitCode.OK and err == ""
    assert ratio_writes(sim) == [0.0, 10.0, 0.0, 0.0]  # enable's GV200-203, 10 %, the release, disable's
    assert sim.writes_to(registers.REG_STOP) == []


def test_stop_refused_as_busy_goes_out_again_until_taken(
    busy_sim: Any, capsys: pytest.CaptureFixture[str], make_client: Any
) -> None:
    sim = busy_sim
    make_client(sim).step(StepFrame.BASE, [0.0, 0.0, -30.0, 0.0, 0.0, 0.0], speed=5.0, wait=False)  # 6 s
    assert sim.wait_for(lambda s: s.moving, timeout=WAIT)
    sim.set_exception(BUSY, STOP_REGISTER)
    cli = _Cli(["--port", str(sim.port), "stop"])
    _refused_for_a_while(sim, cli)
    assert sim.state().moving
    sim.set_exception(None)
    answers_again = time.monotonic()
    code = cli.wait()
    out, err = capsys.readouterr()
    assert not sim.state().moving, err  # the old code: refused once, exit 1, the move went on
    assert code == ExitCode.OK and "stop: done" in out
    stops = sim.writes_to(registers.REG_STOP)
    assert len(stops) == 1 and stops[0].t - answers_again < STOPS_WITHIN
    assert "took the stop (441)" in err


def test_the_stop_after_ctrl_c_goes_out_again_while_the_controller_is_busy(
    busy_sim: Any, make_client: Any
) -> None:
    from app.cli.context import stop_on_a_fresh_link

    sim = busy_sim
    client = make_client(sim)
    client.step(StepFrame.BASE, [0.0, 0.0, -30.0, 0.0, 0.0, 0.0], speed=5.0, wait=False)  # 6 s
    assert sim.wait_for(lambda s: s.moving, timeout=WAIT)
    sim.set_exception(BUSY, STOP_REGISTER)

    def answer_again() -> None:
        before = sim.requests_count
        deadline = time.monotonic() + WAIT
        while sim.requests_count < before + REFUSED_REQUESTS // 3 and time.monotonic() < deadline:
            time.sleep(0.01)
        sim.set_exception(None)

    helper = threading.Thread(target=answer_again, name="test-busy-off", daemon=True)
    helper.start()
    stop_on_a_fresh_link(client)  # the old code: the busy answer raised, the move went on
    join(helper)
    assert sim.wait_for(lambda s: not s.moving, timeout=2.0)
    # taken once busy ended (a second one follows: the step was never seen taken, see the function)
    stops = sim.writes_to(registers.REG_STOP)
    assert stops and all(w.values == (1,) for w in stops)
