"""Issue 18, "Another controller is not the same controller" and "Every move to a stored point
goes through the point guard", in the real window on a real link (restart canary on) and two
simulators on two ports.

Asserted at the simulators: their stored points, the arm's pose, the write log of register 440
(0xE0 create point, 0x42 move to point)."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterator
from typing import Any

import pytest

from app import timing
from app.connection import ConnectionSettings
from app.link.robot_link import RobotLink
from app.link.types import LinkState
from app.points.point import SyncState
from app.protocol.enums import RunCommand
from app.protocol.registers import CANARY_GV, REG_RUN_COMMAND
from tests.link.progress_log import ProgressLog
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    SIGNAL_TIMEOUT_MS,
    app_settings_fixture,
    canary_link_fixture,
    connection_settings,
    fast_reconnect_fixture,
    gv_writes,
    is_state,
    project_dialogs_fixture,
    register_writes,
    step_by_link,
    teach_here,
    translator_fixture,
    window_fixture,
)
from ui.main_window import TAB_POINTS, MainWindow

pytestmark = [pytest.mark.timeout(120), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]

CREATE, MOVE = int(RunCommand.CREATE_POINT), int(RunCommand.MOVE_TO_POINT)
TOLERANCE = 0.01  # mm: the simulator reaches a point exactly (float32 on the wire)
STEP_MM = 15.0  # between two taught points
SPEED = 120.0  # mm/s for Move to point
MOVE_TIMEOUT_MS = 20_000
FOREIGN_OFFSET = (-40.0, -40.0, 25.0)  # where "another client's" P1 is, from the ledger's


@pytest.fixture(name="link")
def identity_link_fixture(canary_link: RobotLink) -> Iterator[RobotLink]:
    """The window's link with the restart canary on (GV99), as the product runs."""
    yield canary_link


@pytest.fixture(name="sims")
def two_sims_fixture(sim_factory: Any) -> tuple[Any, Any]:
    """Two controllers on two ports. GV291 writable: each command is proven with a sentinel, so a
    loaded machine cannot turn a taught point into "unconfirmed" (not this test's subject)."""
    return sim_factory(gv291="writable"), sim_factory(gv291="writable")


def _near(pose: tuple[float, ...], target: tuple[float, ...]) -> bool:
    return math.dist(pose[:3], target[:3]) <= TOLERANCE


def _connect(qtbot: Any, window: MainWindow, sim: Any) -> ConnectionSettings:
    """What *File → Connect…* does once the dialog is accepted (``connect_with``)."""
    settings = connection_settings(sim)
    with qtbot.waitSignal(
        window.link.state.connectionChanged,
        check_params_cb=lambda s: s.connected and s.endpoint == settings.endpoint,
        timeout=SIGNAL_TIMEOUT_MS,
    ):
        window.connect_with(settings)
    return settings


def _teach_five(qtbot: Any, window: MainWindow, sim: Any) -> None:
    """Teach P1..P5 from the Points tab, the arm stepped STEP_MM along X before each (by the
    window's link: a helper client is another master, see ``step_by_link``)."""
    window.work_tabs.setCurrentIndex(TAB_POINTS)
    assert window.points_panel.isVisible()
    sync = window.point_sync
    for _ in range(5):
        step_by_link(qtbot, window.link, STEP_MM)
        teach_here(qtbot, sync)
    ledger = window.project.points_model.ledger
    assert ledger.ids() == [1, 2, 3, 4, 5]
    assert all(p.sync is SyncState.ON_CONTROLLER for p in ledger)
    assert all(_near(sim.state().points[p.id], p.xyzabc) for p in ledger)


def _move_to_p1(qtbot: Any, window: MainWindow) -> tuple[bool, str]:
    panel = window.points_panel
    row = window.project.points_model.row_of(1)
    assert row is not None
    panel.select_rows([row])
    panel.speed.setValue(SPEED)
    with qtbot.waitSignal(window.point_sync.moveFinished, timeout=MOVE_TIMEOUT_MS) as finished:
        panel.move_to_selected()  # the window's confirmation answers yes (window fixture)
    ok, reason = finished.args
    return bool(ok), str(reason)


def _sync(window: MainWindow) -> list[SyncState]:
    return [p.sync for p in window.project.points_model.ledger]


def test_connect_to_another_controller_makes_the_points_unknown_and_move_re_creates_p1(
    qtbot: Any, window: MainWindow, sims: tuple[Any, Any], make_client: Any
) -> None:
    """The issue's scenario: teach 5 points on one controller, Connect… to another that holds a
    P1 of its own at another pose, Move to point P1."""
    first, second = sims
    _connect(qtbot, window, first)
    _teach_five(qtbot, window, first)
    p1 = window.project.points_model.ledger.point(1)
    foreign = (p1.x + FOREIGN_OFFSET[0], p1.y + FOREIGN_OFFSET[1], p1.z + FOREIGN_OFFSET[2], p1.a, p1.b, p1.c)
    assert make_client(second).create_point(1, pose=foreign, wait=True).ok  # another client's P1
    start = second.state().pose

    _connect(qtbot, window, second)

    assert _sync(window) == [SyncState.UNKNOWN] * 5
    panel = window.points_panel
    assert panel.banner.isVisibleTo(panel) and panel.restore_button.isEnabled()
    assert "another controller" in panel.status.text()
    since = len(second.writes)

    ok, reason = _move_to_p1(qtbot, window)

    assert ok, reason
    # P1 was created from the ledger's copy before the move command, and the arm went there
    assert [v for i, v in register_writes(second, REG_RUN_COMMAND) if i >= since] == [CREATE, MOVE]
    final = second.state()
    assert _near(final.points[1], p1.xyzabc) and _near(final.pose, p1.xyzabc)
    assert not _near(final.pose, foreign) and not _near(final.pose, start)
    assert "Reached P1" in panel.status.text()
    assert _sync(window) == [SyncState.ON_CONTROLLER] + [SyncState.UNKNOWN] * 4


def _lose_and_regain(qtbot: Any, window: MainWindow, sim: Any, *, restart: bool = False) -> None:
    """The controller goes silent until the link is down, then answers again (``restart``: it
    restarted meanwhile); the link reconnects by itself."""
    with qtbot.waitSignal(
        window.link.state.connectionChanged, check_params_cb=is_state(LinkState.DOWN), timeout=10_000
    ):
        sim.set_silent(True)
    if restart:
        sim.restart_controller()
    with qtbot.waitSignal(window.link.controllerReconnected, timeout=10_000):
        sim.set_silent(False)
    assert window.link.state.connected


def test_reconnecting_to_the_same_controller_boot_keeps_the_points(
    qtbot: Any,
    window: MainWindow,
    sims: tuple[Any, Any],
    make_client: Any,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(timing, "NOT_ANSWERING_DOWN_AFTER", 0.3)  # a lost link in about 1.3 s
    sim = sims[0]
    _connect(qtbot, window, sim)
    _teach_five(qtbot, window, sim)
    canary_writes = len(gv_writes(sim, CANARY_GV))
    panel = window.points_panel

    _lose_and_regain(qtbot, window, sim)

    assert _sync(window) == [SyncState.ON_CONTROLLER] * 5  # the same boot: nothing was lost
    assert not panel.banner.isVisibleTo(panel)
    assert len(gv_writes(sim, CANARY_GV)) == canary_writes  # proven by a read, nothing written

    # ... while a controller that restarted during the loss is another boot: its points are gone
    _lose_and_regain(qtbot, window, sim, restart=True)

    assert sim.state().points == {}
    assert _sync(window) == [SyncState.UNKNOWN] * 5
    assert panel.banner.isVisibleTo(panel) and "restarted" in panel.status.text()
    assert len(gv_writes(sim, CANARY_GV)) == canary_writes + 1  # a new token for the new boot


def test_a_changed_register_profile_keeps_the_same_boot_but_not_another_unit(
    qtbot: Any, window: MainWindow, sim_factory: Any, make_client: Any
) -> None:
    """A reconnect with other settings to the same controller and boot keeps the points; another
    unit id (another controller behind the same address) does not."""
    sim = sim_factory(gv291="writable", unit=0)  # answers every unit id
    settings = _connect(qtbot, window, sim)
    _teach_five(qtbot, window, sim)
    for changed in (
        dataclasses.replace(settings, poll_timeout=0.9),  # the same controller and boot
        dataclasses.replace(settings, unit=2),
    ):
        with qtbot.waitSignal(
            window.link.state.connectionChanged, check_params_cb=is_state(LinkState.CONNECTED), timeout=5000
        ):
            window.link.connect_to(changed)
        expected = SyncState.ON_CONTROLLER if changed.unit == settings.unit else SyncState.UNKNOWN
        assert _sync(window) == [expected] * 5, changed


def test_bad_end_point_id_makes_the_point_unknown(
    qtbot: Any, window: MainWindow, sims: tuple[Any, Any], make_client: Any
) -> None:
    """The controller loses P1 between its creation and the move (as a restart would): the move is
    answered "bad end point id", and P1 is not believed on the controller any more."""
    sim = sims[0]
    _connect(qtbot, window, sim)
    _teach_five(qtbot, window, sim)
    # the controller forgets P1 right after any create of it (here: before the move goes out)
    ProgressLog(window.link, lambda point: sim.remove_point(point.point_id))
    sim.remove_point(1)  # and before: today's Move to point sends 0x42 without creating it
    since = len(sim.writes)

    ok, reason = _move_to_p1(qtbot, window)

    assert not ok and "bad end point id" in reason
    assert register_writes(sim, REG_RUN_COMMAND)[-1][1] == MOVE and len(sim.writes) > since
    assert sim.state().command_status == 13 and 1 not in sim.state().points
    assert _sync(window) == [SyncState.UNKNOWN] + [SyncState.ON_CONTROLLER] * 4
    panel = window.points_panel
    assert panel.banner.isVisibleTo(panel) and "Move to P1 failed" in panel.status.text()


def test_an_arm_that_arrives_elsewhere_is_a_failed_move_never_reached(
    qtbot: Any, window: MainWindow, sims: tuple[Any, Any], make_client: Any
) -> None:
    """Another master writes its P1 right after TeachPad's create, before the move: the arm goes
    there once (the stated window), and the window says the move failed, in words."""
    sim = sims[0]
    _connect(qtbot, window, sim)
    _teach_five(qtbot, window, sim)
    p1 = window.project.points_model.ledger.point(1)
    foreign = (p1.x + FOREIGN_OFFSET[0], p1.y + FOREIGN_OFFSET[1], p1.z + FOREIGN_OFFSET[2], p1.a, p1.b, p1.c)
    sim.overwrite_after_create(1, foreign)
    sim.add_point(1, foreign)  # and before: today's Move to point sends 0x42 without creating it

    ok, _reason = _move_to_p1(qtbot, window)

    assert not ok
    assert _near(sim.state().pose, foreign) and not sim.state().moving
    text = window.points_panel.status.text()
    assert "Reached" not in text and text.startswith("Move to P1 failed: The arm stopped at (")
    assert "mm from P1" in text and "overwritten by another tool" in text
    assert window.project.points_model.ledger.point(1).sync is SyncState.UNKNOWN
