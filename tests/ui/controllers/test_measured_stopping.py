"""Measured stopping in the window, against the simulator's own record of when the arm came to
rest (``SimController.rest_records``): the Stop button, a jog release, the monitor's line, the
audit trail and the support bundle."""

from __future__ import annotations

import math
import time
import zipfile
from pathlib import Path
from typing import Any

import pytest
from PySide6.QtCore import Qt

from app import timing
from app.link.ops import JogRelease, Step, Stop
from app.link.types import StepFrame
from app.safety.audit_read import query
from app.safety.stopping import StopKind, StopMeasurement
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    SIGNAL_TIMEOUT_MS,
    app_settings_fixture,
    connect,
    fast_reconnect_fixture,
    jogging,
    link_fixture,
    project_dialogs_fixture,
    translator_fixture,
    window_fixture,
)

pytestmark = [pytest.mark.timeout(60), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]

POLL_PERIOD = 1.0 / timing.POLL_HZ_DEFAULT
STEP_SPEED = 100.0  # mm/s


def _measured(qtbot: Any, window: Any, click: Any) -> StopMeasurement:
    with qtbot.waitSignal(window.stop_timing.measured, timeout=SIGNAL_TIMEOUT_MS) as blocker:
        click()
    result: StopMeasurement = blocker.args[0]
    return result


def _check_against_the_simulator(
    result: StopMeasurement, sim: Any, at_click: dict[str, Any], speed: float
) -> None:
    rest = sim.rest_records()[-1]
    truth = rest.t - result.clicked_at  # the simulator: from the click to the arm at rest
    assert result.still
    # within one poll period of the simulator's record: the arm is first seen at rest by the
    # first poll after it stopped (a poll in the same simulator tick may see it a tick earlier);
    # a loaded machine may space the polls wider: then within the gap the polls had
    assert -POLL_PERIOD <= result.seconds - truth <= max(POLL_PERIOD, result.poll_gap) + 0.005
    # the distance: from where the arm was at the click (the simulator's pose then) to where it
    # rests; the product places the click between the polls around it, as if the arm moved evenly:
    # off by at most the way the arm went from the last poll before the click to its rest (the
    # simulator moves in ticks: one more tick's way)
    travelled = math.dist(at_click["pose"][:3], rest.pose[:3])
    window = at_click["age"] + max(0.0, truth) + 1.0 / timing.SIM_TICK_HZ
    assert result.distance_mm == pytest.approx(travelled, abs=speed * window + 0.1)


def test_a_stop_is_timed_as_the_simulator_recorded_it(
    qtbot: Any, sim: Any, window: Any, tmp_path: Path
) -> None:
    connect(qtbot, window.link, sim, poll_timeout=1.0)
    z0 = sim.state().pose[2]
    window.link.submit(Step(StepFrame.BASE, (0.0, 0.0, -100.0, 0.0, 0.0, 0.0), speed=STEP_SPEED))  # 1 s
    state = window.link.state
    qtbot.waitUntil(lambda: state.pose is not None and state.pose.z < z0 - 10.0, timeout=SIGNAL_TIMEOUT_MS)
    at_click: dict[str, Any] = {}

    def click() -> None:
        at_click.update(pose=sim.state().pose, polled=state.pose, age=state.age() or 0.0)
        qtbot.mouseClick(window.control_bar.stop_button, Qt.MouseButton.LeftButton)

    result = _measured(qtbot, window, click)
    assert result.kind is StopKind.STOP
    assert not sim.state().moving
    _check_against_the_simulator(result, sim, at_click, STEP_SPEED)
    # the arm went on after the click as far as the simulator says (on a loaded machine its motion
    # ticker may not have moved it between the last poll before the click and the Stop: 0 mm then)
    moved_after_click = math.dist(at_click["pose"][:3], sim.rest_records()[-1].pose[:3])
    if moved_after_click > 0.1:
        assert result.distance_mm > 0.0
    # the monitor says it
    label = window.monitor_panel.last_stop_label.text()
    assert label == f"Last stop: {result.ms} ms, {result.distance_mm:.1f} mm"
    # the audit trail has it
    audit_dir = window.safety_menu.safety.audit_dir
    [record] = [r for r in query(audit_dir) if r.command == "stop measured"]
    assert record.kind == "action" and record.args["ms"] == result.ms and record.args["still"] is True
    assert record.args["mm"] == pytest.approx(result.distance_mm, abs=0.001)
    # the support bundle summarises the session
    out = tmp_path / "bundle.zip"
    window.safety_menu.save_path = lambda _t, _s: str(out)
    assert window.safety_menu.write_bundle() == out
    with zipfile.ZipFile(out) as zf:
        lines = zf.read("stopping.txt").decode("utf-8").splitlines()
    assert lines[0] == "measured stopping: 1 in this session (click to the arm seen still)"
    assert lines[1].startswith(f"stop: 1; time median {result.seconds * 1000:.0f} ms")


def test_a_jog_release_is_timed_the_same_way(qtbot: Any, sim: Any, window: Any) -> None:
    connect(qtbot, window.link, sim, poll_timeout=1.0)
    qtbot.waitUntil(lambda: window.jog_panel.axes_box.isEnabled(), timeout=SIGNAL_TIMEOUT_MS)
    window.jog_panel.speed_slider.setValue(20)  # 50 mm/s
    button = window.jog_panel.button(0, 1)
    x0 = sim.state().pose[0]
    qtbot.mousePress(button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: jogging(sim) and abs(sim.state().pose[0] - x0) > 5.0, timeout=SIGNAL_TIMEOUT_MS)
    state = window.link.state
    qtbot.waitUntil(
        lambda: state.pose is not None and abs(state.pose.x - x0) > 5.0, timeout=SIGNAL_TIMEOUT_MS
    )
    at_click = {"pose": sim.state().pose, "polled": state.pose, "age": state.age() or 0.0}
    with qtbot.waitSignal(window.stop_timing.measured, timeout=SIGNAL_TIMEOUT_MS) as blocker:
        qtbot.mouseRelease(button, Qt.MouseButton.LeftButton)
    result: StopMeasurement = blocker.args[0]
    assert result.kind is StopKind.JOG_RELEASE
    assert not jogging(sim)
    _check_against_the_simulator(result, sim, at_click, 50.0)
    assert window.monitor_panel.last_stop_label.text().startswith("Last jog release: ")
    audit = [r for r in query(window.safety_menu.safety.audit_dir) if r.command == "jog release measured"]
    assert len(audit) == 1 and audit[0].args["kind"] == "jog release"


def test_a_stop_never_seen_still_says_so(
    qtbot: Any, sim: Any, window: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(timing, "STOP_STILL_TIMEOUT", 0.5)
    # a loaded machine can hold the simulator's ticker a while: only a long pause counts as rest
    monkeypatch.setattr(timing, "STOP_STILL_SPAN", 0.4)
    connect(qtbot, window.link, sim, poll_timeout=1.0)
    window.link.submit(Step(StepFrame.BASE, (0.0, 0.0, -100.0, 0.0, 0.0, 0.0), speed=50.0))  # 2 s
    qtbot.waitUntil(lambda: sim.state().moving, timeout=SIGNAL_TIMEOUT_MS)
    monkeypatch.setattr(sim.robot, "stop", lambda: None)  # a controller that does not stop
    result = _measured(
        qtbot, window, lambda: qtbot.mouseClick(window.control_bar.stop_button, Qt.MouseButton.LeftButton)
    )
    assert not result.still and result.seconds == 0.5 and result.distance_mm > 5.0
    label = window.monitor_panel.last_stop_label.text()
    assert label == f"Last stop: not seen still within 0.5 s ({result.distance_mm:.1f} mm)"
    monkeypatch.undo()
    window.link.submit(Stop())
    assert sim.wait_for(lambda s: not s.moving, 2.0)


def test_a_stop_without_a_link_is_not_measured(qtbot: Any, window: Any) -> None:
    with qtbot.assertNotEmitted(window.stop_timing.measured, wait=100):
        qtbot.mouseClick(window.control_bar.stop_button, Qt.MouseButton.LeftButton)
    assert not window.stop_timing.watch.measuring
    assert window.monitor_panel.last_stop_label.text() == "Last stop: not measured yet"


def test_the_menus_stop_and_esc_are_measured_too(qtbot: Any, sim: Any, window: Any) -> None:
    connect(qtbot, window.link, sim, poll_timeout=1.0)
    qtbot.waitUntil(lambda: window.link.state.fresh, timeout=SIGNAL_TIMEOUT_MS)
    result = _measured(qtbot, window, window.menus.stop_action.trigger)  # Esc's action
    # nothing moved: still from the click on
    assert (
        result.kind is StopKind.STOP and result.still and result.seconds == 0.0 and result.distance_mm == 0.0
    )
    assert window.monitor_panel.last_stop_label.text() == "Last stop: 0 ms, 0.0 mm"


SLOW_SEND = 0.15  # s the link takes to take a request, as on a loaded machine (the stop line's hand-off)


def _slow_link(window: Any, monkeypatch: pytest.MonkeyPatch) -> list[tuple[float, Any]]:
    """Every request takes SLOW_SEND to submit, as on a loaded machine; returns (when its submit
    began, the op) for each (the motion controller sends the Stop or the release in the first slot
    of the signal the measuring hears after it)."""
    submit = window.link.submit
    sent: list[tuple[float, Any]] = []

    def slow(op: Any) -> int:
        sent.append((time.monotonic(), op))
        time.sleep(SLOW_SEND)
        return int(submit(op))

    monkeypatch.setattr(window.link, "submit", slow)
    return sent


def _sent_at(sent: list[tuple[float, Any]], kind: type) -> float:
    at: float = next(at for at, op in reversed(sent) if isinstance(op, kind))
    return at


def _moving_on_a_slow_link(
    qtbot: Any, sim: Any, window: Any, monkeypatch: pytest.MonkeyPatch
) -> list[tuple[float, Any]]:
    """Connected, the arm stepping down (1 s), then every request slow to submit (``_slow_link``)."""
    connect(qtbot, window.link, sim, poll_timeout=1.0)
    window.link.submit(Step(StepFrame.BASE, (0.0, 0.0, -100.0, 0.0, 0.0, 0.0), speed=STEP_SPEED))  # 1 s
    qtbot.waitUntil(lambda: sim.state().moving, timeout=SIGNAL_TIMEOUT_MS)
    sent = _slow_link(window, monkeypatch)
    return sent


def test_a_stop_is_timed_from_the_click_however_long_sending_it_takes(
    qtbot: Any, sim: Any, window: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    sent = _moving_on_a_slow_link(qtbot, sim, window, monkeypatch)
    result = _measured(
        qtbot, window, lambda: qtbot.mouseClick(window.control_bar.stop_button, Qt.MouseButton.LeftButton)
    )
    assert result.clicked_at <= _sent_at(sent, Stop)  # from the click, not from after the Stop went out
    assert result.clicked_at <= sim.rest_records()[-1].t  # the arm rested after the click


def test_a_jog_release_is_timed_from_the_release_however_long_sending_it_takes(
    qtbot: Any, sim: Any, window: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    connect(qtbot, window.link, sim, poll_timeout=1.0)
    qtbot.waitUntil(lambda: window.jog_panel.axes_box.isEnabled(), timeout=SIGNAL_TIMEOUT_MS)
    button = window.jog_panel.button(0, 1)
    qtbot.mousePress(button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: jogging(sim), timeout=SIGNAL_TIMEOUT_MS)
    sent = _slow_link(window, monkeypatch)
    result = _measured(qtbot, window, lambda: qtbot.mouseRelease(button, Qt.MouseButton.LeftButton))
    assert result.kind is StopKind.JOG_RELEASE
    assert result.clicked_at <= _sent_at(sent, JogRelease)


def test_the_menus_stop_is_timed_from_before_it_was_sent(
    qtbot: Any, sim: Any, window: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    sent = _moving_on_a_slow_link(qtbot, sim, window, monkeypatch)
    result = _measured(qtbot, window, window._menu_stop)
    assert result.clicked_at <= _sent_at(sent, Stop)


def test_a_stop_asked_for_without_a_click_is_not_timed_from_an_earlier_click(
    qtbot: Any, sim: Any, window: Any
) -> None:
    connect(qtbot, window.link, sim, poll_timeout=1.0)
    bar = window.control_bar
    first = _measured(qtbot, window, lambda: qtbot.mouseClick(bar.stop_button, Qt.MouseButton.LeftButton))
    assert bar.stop_clicked_at is None  # the click's time lived while its signal was out
    before = time.monotonic()
    second = _measured(qtbot, window, bar.stopRequested.emit)  # a Stop asked for some other way
    assert second.kind is StopKind.STOP
    assert second.clicked_at >= before > first.clicked_at  # timed from now, not from that click


def test_a_jog_release_time_is_its_own(qtbot: Any, sim: Any, window: Any) -> None:
    connect(qtbot, window.link, sim, poll_timeout=1.0)
    qtbot.waitUntil(lambda: window.jog_panel.axes_box.isEnabled(), timeout=SIGNAL_TIMEOUT_MS)
    button = window.jog_panel.button(0, 1)
    qtbot.mousePress(button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: jogging(sim), timeout=SIGNAL_TIMEOUT_MS)
    first = _measured(qtbot, window, lambda: qtbot.mouseRelease(button, Qt.MouseButton.LeftButton))
    assert first.kind is StopKind.JOG_RELEASE
    assert window.jog_panel.released_at is None
    before = time.monotonic()
    second = _measured(qtbot, window, window.jog_panel.jogReleased.emit)
    assert second.clicked_at >= before > first.clicked_at
