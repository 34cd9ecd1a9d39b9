"""Issue 18 in the window, asserted at the simulator's write log: a switch from manual to auto is
the operator's decision, named in the confirmation; reduced-speed mode caps every motion and the
screen shows the cap where the speed is set; a fresh install's envelope and the keypad's ranges
follow the robot model."""

from __future__ import annotations

from typing import Any

import pytest
from PySide6.QtCore import Qt

from app.link.ops import GoZero, Stop
from app.link.types import WorkerError
from app.models import CommandResult
from app.protocol import registers
from app.protocol.enums import WorkMode
from app.safety.audit_read import query
from app.safety.envelope import REDUCED_SPEED_DEFAULT
from app.safety.profile import load_profile
from app.view3d.profile import default_profile
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    SIGNAL_TIMEOUT_MS,
    app_settings_fixture,
    connect,
    fast_reconnect_fixture,
    gv_writes,
    jogging,
    link_fixture,
    project_dialogs_fixture,
    ratio_writes,
    register_writes,
    translator_fixture,
    window_fixture,
)
from ui.keypad import KeypadDialog

pytestmark = [pytest.mark.timeout(60), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]


def _connected(qtbot: Any, window: Any, sim: Any) -> None:
    connect(qtbot, window.link, sim)
    qtbot.waitUntil(lambda: window.control_bar.mode_text() != "", timeout=SIGNAL_TIMEOUT_MS)


def _ok(predicate: Any = None) -> Any:
    return lambda r: isinstance(r, CommandResult) and r.ok and (predicate is None or predicate(r))


# --- manual mode -------------------------------------------------------------------------------


def test_go_to_zero_in_manual_names_the_switch_and_a_no_writes_nothing(
    qtbot: Any, sim_factory: Any, window: Any
) -> None:
    sim = sim_factory(work_mode=WorkMode.MANUAL)
    _connected(qtbot, window, sim)
    panel = window.program_panel
    questions: list[str] = []

    def answer_no(_title: str, text: str) -> bool:
        questions.append(text)
        return False

    window.confirm = answer_no
    panel.set_zero_axis(None)
    qtbot.mouseClick(panel.zero_button, Qt.MouseButton.LeftButton)
    qtbot.mouseClick(panel.run_button, Qt.MouseButton.LeftButton)
    assert questions[0].startswith(
        "The controller is in Manual mode. Switch it to Auto and move all axes to zero?"
    )
    assert questions[1].startswith("The controller is in Manual mode. Switch it to Auto and run program 1")
    assert sim.writes == []  # no 444, no 445, no program: cancelled means nothing sent
    assert sim.state().work_mode is WorkMode.MANUAL

    window.confirm = lambda _title, _text: True
    panel.set_zero_axis(1)  # J2 (20 degrees at home) -> 0
    with qtbot.waitSignal(
        window.link.commandFinished,
        check_params_cb=_ok(lambda r: "zero" in r.message),
        timeout=SIGNAL_TIMEOUT_MS,
    ):
        qtbot.mouseClick(panel.zero_button, Qt.MouseButton.LeftButton)
    (mode_at, mode), (zero_at, axis) = register_writes(sim, 444)[0], register_writes(sim, 445)[0]
    assert (mode, axis) == (1, 1) and mode_at < zero_at  # the switch the operator said yes to, first
    assert sim.state().joints[1] == pytest.approx(0.0, abs=1e-6)
    audit = window.safety_menu.safety.audit_dir
    window.safety_menu.safety.session.audit.close()
    writes = [r.args["address"] for r in query(audit) if r.kind == "write"]
    assert writes.index(444) < writes.index(445)  # the mode change is its own audited write


def test_a_controller_found_in_manual_is_not_switched_behind_the_confirmation(
    qtbot: Any, sim_factory: Any, window: Any
) -> None:
    """The panel read auto, the controller is in manual when the request runs: refused, said."""
    sim = sim_factory(work_mode=WorkMode.MANUAL)
    _connected(qtbot, window, sim)
    errors: list[WorkerError] = []
    window.link.errorOccurred.connect(errors.append)
    window.link.submit(GoZero(None))  # as a request confirmed in auto would arrive: no switch allowed
    qtbot.waitUntil(lambda: any(e.operation == "go to zero" for e in errors), timeout=SIGNAL_TIMEOUT_MS)
    error = next(e for e in errors if e.operation == "go to zero")
    assert error.reason is not None and error.reason.code == "manual_mode"
    assert sim.writes == []


# --- reduced-speed mode ------------------------------------------------------------------------


def test_reduced_speed_caps_every_motion_and_shows_the_cap(qtbot: Any, sim: Any, window: Any) -> None:
    _connected(qtbot, window, sim)
    safety = window.safety_menu.safety
    assert safety.set_reduced(True)  # any operator may switch it on
    caps = safety.caps
    assert caps is not None

    # the jog: the slider says what goes out
    jog = window.jog_panel
    jog.set_ratio(50)
    assert jog.speed_value.text() == "50 % → 10 % (reduced speed)"
    assert "reduced speed" in jog.speed_value.toolTip()
    qtbot.mousePress(jog.button(2, 0), Qt.MouseButton.LeftButton)  # Z-
    qtbot.waitUntil(lambda: jogging(sim), timeout=SIGNAL_TIMEOUT_MS)
    qtbot.mouseRelease(jog.button(2, 0), Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: not jogging(sim), timeout=SIGNAL_TIMEOUT_MS)
    assert max(ratio_writes(sim)) == 10.0

    # the program run: the field shows the cap, the run goes out at it
    program = window.program_panel
    program.speed_spin.setValue(50)
    assert program.speed_cap.isVisibleTo(program) and program.speed_cap.text() == "→ 10 % (reduced speed)"
    questions: list[str] = []

    def answer_yes(_title: str, text: str) -> bool:
        questions.append(text)
        return True

    window.confirm = answer_yes
    program.id_spin.setValue(2)
    qtbot.mouseClick(program.run_button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(
        lambda: len(register_writes(sim, registers.REG_PROGRAM_SPEED)) == 1, timeout=SIGNAL_TIMEOUT_MS
    )
    assert [v for _, v in register_writes(sim, registers.REG_PROGRAM_SPEED)] == [10]
    assert "at 10 % (capped by reduced speed; 50 % set)" in questions[-1]
    stop_ids: list[int] = []  # the Stop's own result (the stopped program's comes first)
    with qtbot.waitSignal(
        window.link.commandFinished,
        check_params_cb=lambda r: r.request_id in stop_ids,
        timeout=SIGNAL_TIMEOUT_MS,
    ):
        stop_ids.append(window.link.submit(Stop()))
    assert sim.wait_for(lambda s: not s.moving, 5.0)

    # a move to a point: the cap beside its speed, and the speed it goes out at
    points = window.points_panel
    points.speed.setValue(500.0)
    assert points.speed_cap.isVisibleTo(points) and points.speed_cap.text() == "→ 250 mm/s (reduced speed)"
    assert points.sent_speed() == REDUCED_SPEED_DEFAULT

    # go to zero cannot be capped: held
    assert not program.zero_button.isEnabled() and "reduced-speed" in program.zero_button.toolTip()

    # steps: the joint step at the rpm cap, a base step at the TCP cap (not refused)
    step = window.step_panel
    assert step.speed_cap.isVisibleTo(step) and step.speed_cap.text() == "→ 1.72 rpm"
    with qtbot.waitSignal(window.link.commandFinished, check_params_cb=_ok(), timeout=SIGNAL_TIMEOUT_MS):
        qtbot.mouseClick(step.plus_buttons[0], Qt.MouseButton.LeftButton)
    step.set_frame(step.frame.BASE)
    step.speed_spin.setValue(500.0)
    assert step.speed_cap.text() == "→ 250 mm/s"
    with qtbot.waitSignal(window.link.commandFinished, check_params_cb=_ok(), timeout=SIGNAL_TIMEOUT_MS):
        qtbot.mouseClick(step.minus_buttons[2], Qt.MouseButton.LeftButton)  # Z-
    qtbot.waitUntil(lambda: len(gv_writes(sim, registers.GV_EXPECTED_SPEED)) >= 2, timeout=SIGNAL_TIMEOUT_MS)
    speeds = [v for _, v in gv_writes(sim, registers.GV_EXPECTED_SPEED)]
    assert speeds == pytest.approx([caps.joint_rpm_cap, REDUCED_SPEED_DEFAULT], rel=1e-6)


# --- defaults: a fresh install, the keypad ------------------------------------------------------


def test_a_fresh_install_checks_the_robot_models_joint_limits_and_a_keep_in_box(window: Any) -> None:
    safety = window.safety_menu.safety
    model = default_profile()
    env = safety.envelope
    assert env.joint_limits == tuple((j.min_deg, j.max_deg) for j in model.joints)
    assert env.keep_in is not None
    assert env.keep_in.lo == (-1400.0, -1400.0, 0.0) and env.keep_in.hi == (1400.0, 1400.0, 1400.0)
    assert model.reach <= 1400.0  # the box is the model's reach, rounded out; Z from its base up
    saved = load_profile(safety.profile_path)  # saved once painted: every later start reads it
    assert saved.envelope == env and saved.revision == 1 and saved.robot == model.name
    safety.session.audit.close()
    assert [r.command for r in query(safety.audit_dir) if r.kind == "action"] == [
        "create the default envelope"
    ]


def test_the_keypad_offers_an_axis_its_own_limits(qtbot: Any, sim: Any, window: Any) -> None:
    _connected(qtbot, window, sim)
    step = window.step_panel
    qtbot.waitUntil(lambda: step._pose is not None, timeout=SIGNAL_TIMEOUT_MS)
    j1 = step.value_spins[0]
    assert (j1.minimum(), j1.maximum()) == (-340.0, 340.0)  # the span of J1's limits, not 10000
    dialog = KeypadDialog(j1, window)
    qtbot.addWidget(dialog)
    text = dialog.range_label.text()
    assert text.startswith("From -170.000 to 170.000")  # J1 stands at 0: its limits are -170..170
    assert "J1 limits -170 … 170 °, now at 0.0 °" in text
    for key in ["1", "8", "0"]:
        dialog.press(key)
    assert dialog.value() is None and not dialog.ok_button.isEnabled()  # past J1's limit
    j2 = KeypadDialog(step.value_spins[1], window)  # J2 at 20 degrees, limits -100..135
    qtbot.addWidget(j2)
    assert j2.range_label.text().startswith("From -120.000 to 115.000")
