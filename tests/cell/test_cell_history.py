"""Issue 23, the cell view's per-controller history: state changes, alarms raised and cleared, and
program cycles read from the program-state register alone; bounded; CSV in UTF-8 with a BOM."""

from __future__ import annotations

from pathlib import Path

from app.cell.history import ControllerHistory, alarm_order
from app.models import ControllerStatus
from app.protocol.enums import Alarm, ControllerMode, ProgramState

STOPPED, RUNNING, PAUSED = ProgramState.STOPPED, ProgramState.RUNNING, ProgramState.PAUSED


def _status(
    program: ProgramState, alarms: Alarm = Alarm.NONE, mode: ControllerMode = ControllerMode.AUTO
) -> ControllerStatus:
    return ControllerStatus(mode=mode, program_state=program, alarms=alarms, command_status_code=0)


def _kinds(history: ControllerHistory) -> list[tuple[str, str]]:
    return [(e.kind, e.detail) for e in history.events]


def test_program_cycles_started_finished_stopped() -> None:
    history = ControllerHistory("R1")
    for t, status in enumerate(
        [
            _status(STOPPED),
            _status(RUNNING),  # started
            _status(STOPPED),  # finished: no alarm
            _status(RUNNING),  # started
            _status(PAUSED),
            _status(STOPPED),  # stopped from paused
            _status(RUNNING),  # started
            _status(STOPPED, Alarm.ESTOP),  # stopped by an alarm
        ]
    ):
        history.observe(status, 1000 * t)
    cycles = [k for k in _kinds(history) if k[0].startswith("program")]
    assert cycles == [
        ("program started", ""),
        ("program finished", ""),
        ("program started", ""),
        ("program stopped", "from paused"),
        ("program started", ""),
        ("program stopped", "alarm"),
    ]
    assert ("state", "program running -> paused") in _kinds(history)
    assert ("alarm raised", "emergency stop") in _kinds(history)


def test_mode_and_link_changes_are_recorded_once() -> None:
    history = ControllerHistory("R1")
    history.observe(_status(STOPPED), 0)
    history.silent("no answer in 0.15 s", 100)
    history.silent("no answer in 0.15 s", 200)
    history.observe(_status(STOPPED, mode=ControllerMode.MANUAL), 300)
    kinds = _kinds(history)
    assert kinds.count(("link", "not answering: no answer in 0.15 s")) == 1
    assert kinds.count(("link", "answering")) == 2
    assert ("state", "mode auto -> manual") in kinds


def test_alarms_most_severe_first_then_oldest() -> None:
    word = Alarm.ENCODER | Alarm.SERVO | Alarm.ESTOP
    assert alarm_order(int(word), {}) == [Alarm.ESTOP, Alarm.SERVO, Alarm.ENCODER]


def test_bounded_and_counted() -> None:
    history = ControllerHistory("R1", bound=4)
    for t in range(10):
        history.observe(_status(RUNNING if t % 2 else STOPPED), t)
    assert len(history.events) == 4
    assert history.dropped > 0
    assert history.events[-1].wall_ms == 9


def test_csv_is_utf8_with_bom_and_atomic(tmp_path: Path) -> None:
    history = ControllerHistory("机器人 1")
    history.observe(_status(STOPPED, Alarm.SERVO), 1_700_000_000_000)
    out = tmp_path / "h.csv"
    out.write_bytes(b"old")
    history.export_csv(out)
    data = out.read_bytes()
    assert data.startswith(b"\xef\xbb\xbf")
    lines = data.decode("utf-8-sig").splitlines()
    assert lines[0] == "time,controller,kind,detail"
    assert lines[1].split(",")[1:] == ["机器人 1", "link", "answering"]
    assert "alarm raised,servo alarm" in data.decode("utf-8-sig")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["h.csv"]
