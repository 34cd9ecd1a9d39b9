"""The main window with the project: points and planner tabs, File/Edit menus, teach, restore,
plan runs against the simulator, close / recovery questions, and the 1280×800 fit."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from app.plan.runner import RunState
from app.points.point import SyncState
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    SIGNAL_TIMEOUT_MS,
    FakeProjectDialogs,
    app_settings_fixture,
    connect,
    fast_reconnect_fixture,
    link_fixture,
    project_dialogs_fixture,
    translator_fixture,
    window_fixture,
)
from ui.main_window import TAB_PLANNER, TAB_POINTS, MainWindow
from ui.panels.monitor_panel import MonitorPanel
from ui.panels.monitor_plots import unwrap_degrees
from ui.settings import AppSettings

pytestmark = [pytest.mark.timeout(60), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]

SAMPLE = Path(__file__).resolve().parents[2] / "resources" / "samples" / "demo.teachpad.json"


def _project_near(sim: Any, path: Path, speed: float = 400.0) -> Path:
    """A project with three points a few cm from the simulator's pose and a plan through them."""
    x, y, z, a, b, c = sim.state().pose
    offsets = [(30.0, 0.0, 0.0), (30.0, 30.0, 0.0), (0.0, 30.0, -20.0)]
    points = [
        {
            "id": i,
            "name": f"p{i}",
            "x": x + dx,
            "y": y + dy,
            "z": z + dz,
            "a": a,
            "b": b,
            "c": c,
            "e1": 0.0,
            "e2": 0.0,
            "e3": 0.0,
            "e4": 0.0,
            "e5": 0.0,
            "tool": 200,
            "note": "",
            "sync": "unknown",
            "sync_error": "",
        }
        for i, (dx, dy, dz) in enumerate(offsets, start=1)
    ]
    segments = [
        {
            "type": "line",
            "end": i,
            "speed": speed,
            "orientation": "changes",
            "ignore_middle": False,
            "tool": 200,
        }
        for i in (1, 2, 3)
    ]
    data = {
        "format": "teachpad-project",
        "version": 1,
        "name": "near",
        "description": "",
        "created": "2025-01-01T00:00:00Z",
        "modified": "2025-01-01T00:00:00Z",
        "points": points,
        "plans": [{"name": "short", "loops": 1, "segments": segments}],
    }
    path.write_text(json.dumps(data), encoding="utf-8")
    return path


def test_window_fits_1280x800(window: MainWindow) -> None:
    window.project.open_file(SAMPLE)
    for tab in ("monitor", "points", "planner"):
        window.show_tab(tab)
        hint = window.minimumSizeHint()
        assert hint.width() <= 1280 and hint.height() <= 800, (tab, hint)
    window.resize(1280, 800)
    assert window.control_bar.stop_button.isVisible()


def test_tabs_and_menus_in_both_languages(
    qtbot: Any,
    link: Any,
    app_settings: AppSettings,
    translator: Any,
    project_dialogs: FakeProjectDialogs,
    tmp_path: Path,
) -> None:
    for language in ("en", "zh_CN"):
        assert translator.set_language(language)
        window = MainWindow(
            link,
            app_settings,
            translator,
            project_dialogs=project_dialogs,
            autosave_dir=tmp_path,
            shutdown_link_on_close=False,
        )
        qtbot.addWidget(window)
        assert window.work_tabs.count() == 4  # Monitor, Points, Planner, 3D (the view3d branch)
        assert all(window.work_tabs.tabText(i) for i in range(3))  # also before Points / Planner are built
        points, planner = window.points_panel, window.planner_panel  # built on first use, in their tabs
        assert window.work_tabs.widget(TAB_POINTS) is points
        assert window.work_tabs.widget(TAB_PLANNER) is planner
        assert all(window.work_tabs.tabText(i) for i in range(3))
        assert window.project.action_undo in window.menus.edit_menu.actions()
        assert window.project.action_open in window.menus.file_menu.actions()
        if language == "zh_CN":
            assert window.tabs.tabText(0) == "点动"
        window.close()


def test_start_project_opens_remembers_and_offers_recovery(
    qtbot: Any,
    window: MainWindow,
    project_dialogs: FakeProjectDialogs,
    app_settings: AppSettings,
    tmp_path: Path,
) -> None:
    path = tmp_path / "demo.teachpad.json"
    path.write_bytes(SAMPLE.read_bytes())
    assert window.start_project(path)
    assert len(window.project.points_model.ledger) == 8
    assert window.planner_panel.current_plan() is not None
    assert app_settings.last_project == str(path)
    assert "demo.teachpad.json" in window.windowTitle()
    assert project_dialogs.asked == []  # no autosave: no question
    assert window.project.points_model.setData(window.project.points_model.index(0, 1), "renamed")
    assert window.project.is_dirty and window.project.autosave_now() is not None
    assert window.project.wait_autosave()
    # the next start (a crash left the autosave): the last project, then the autosave
    project_dialogs.recover = True
    second = MainWindow(
        window.link,
        app_settings,
        project_dialogs=project_dialogs,
        autosave_dir=tmp_path / "autosave",
        shutdown_link_on_close=False,
    )
    qtbot.addWidget(second)
    assert second.start_project(None)
    assert project_dialogs.asked == ["recover"] and second.project.is_dirty
    assert second.project.points_model.ledger.point(1).name == "renamed"


def test_close_asks_to_save_and_cancel_keeps_the_window(
    qtbot: Any, window: MainWindow, project_dialogs: FakeProjectDialogs
) -> None:
    window.project.open_file(SAMPLE)
    window.points_panel.add_point()
    assert window.project.is_dirty
    project_dialogs.save_choice = "cancel"
    assert not window.close()
    assert window.isVisible() and window.link.is_running
    project_dialogs.save_choice = "discard"
    assert window.close()
    assert not window.link.is_running  # shut down after the question
    assert project_dialogs.asked.count("save changes") == 2


def test_undo_from_the_edit_menu(window: MainWindow) -> None:
    window.project.open_file(SAMPLE)
    model = window.project.points_model
    window.points_panel.add_point()
    assert len(model.ledger) == 9
    window.project.action_undo.trigger()
    assert len(model.ledger) == 8


def test_teach_a_point_from_the_window(qtbot: Any, sim_factory: Any, window: MainWindow) -> None:
    # a writable GV291 (sentinel rule): under the observed rule a create whose answer comes past the
    # simulator's 0.25 s read-hold is rightly "done, unconfirmed" (a loaded machine), not ON_CONTROLLER
    sim = sim_factory(gv291="writable")
    connect(qtbot, window.link, sim)
    window.show_tab("points")
    panel = window.points_panel
    qtbot.waitUntil(panel.action_teach.isEnabled, timeout=SIGNAL_TIMEOUT_MS)
    with qtbot.waitSignal(window.point_sync.pointTaught, timeout=SIGNAL_TIMEOUT_MS) as taught:
        panel.action_teach.trigger()
    point_id = taught.args[0]
    point = window.project.points_model.ledger.point(point_id)
    assert point.sync is SyncState.ON_CONTROLLER
    assert point_id in sim.state().points
    assert abs(sim.state().points[point_id][0] - point.x) < 1e-3
    assert panel.selected_rows() == [window.project.points_model.row_of(point_id)]


def test_plan_runs_from_the_planner_tab_to_the_last_point(
    qtbot: Any, sim_factory: Any, window: MainWindow, tmp_path: Path
) -> None:
    sim = sim_factory(gv291="writable")  # results proved by the sentinel (see the teach test above)
    window.project.open_file(_project_near(sim, tmp_path / "near.teachpad.json"))
    connect(qtbot, window.link, sim)
    window.show_tab("planner")
    planner = window.planner_panel
    runs: list[bool] = []
    window.run_controller.runningChanged.connect(runs.append)
    said: list[str] = []  # what the operator was told, quoted when the run never finishes
    planner.statusMessage.connect(said.append)
    window.point_sync.statusMessage.connect(lambda text, level: said.append(f"{level}: {text}"))
    window.link.errorOccurred.connect(lambda error: said.append(f"link: {error}"))
    try:
        with qtbot.waitSignal(window.run_controller.runFinished, timeout=30_000) as finished:
            assert planner.run()  # uploads the three points first (asked, answered yes), then runs
    except qtbot.TimeoutError:
        pytest.fail("the run never finished; the operator was told: " + " | ".join(said))
    assert finished.args[0].state is RunState.FINISHED
    assert runs == [True, False]
    assert sorted(sim.state().points) == [1, 2, 3]
    last = window.project.points_model.ledger.point(3)
    pose = sim.state().pose
    assert abs(pose[0] - last.x) < 0.5 and abs(pose[1] - last.y) < 0.5 and abs(pose[2] - last.z) < 0.5


def test_a_run_while_the_controller_is_not_answering_says_so_and_sends_nothing(
    qtbot: Any, sim: Any, window: MainWindow, tmp_path: Path
) -> None:
    """The connection is open but the controller has stopped answering (one poll unanswered):
    Run says the controller is not answering -- not "no connection" -- and nothing is written,
    from the planner's button and from the start after an upload (the run controller itself)."""
    from app.errors import LinkError
    from app.link.types import LinkState
    from ui.messages import error_text

    window.project.open_file(_project_near(sim, tmp_path / "near.teachpad.json"))
    connect(qtbot, window.link, sim, poll_timeout=0.2)  # the silence is seen quickly
    window.show_tab("planner")
    planner = window.planner_panel
    said: list[str] = []
    planner.statusMessage.connect(said.append)
    writes = len(sim.writes)
    sim.set_silent(True)
    try:
        qtbot.waitUntil(
            lambda: window.link.state.connection.state is LinkState.NOT_ANSWERING, timeout=SIGNAL_TIMEOUT_MS
        )
        assert not planner.run()
        expected = "The controller is not answering: the plan was not started. Try again when it answers."
        assert said[-1] == expected
        plan = planner.current_plan()
        assert plan is not None
        with pytest.raises(LinkError) as refused:
            window.run_controller.start(plan)
        assert refused.value.code == "run_not_answering_start"
        assert error_text(refused.value) == said[-1]
        assert len(sim.writes) == writes  # nothing was sent
    finally:
        sim.set_silent(False)
    window.link.disconnect()
    qtbot.waitUntil(
        lambda: window.link.state.connection.state is LinkState.DISCONNECTED, timeout=SIGNAL_TIMEOUT_MS
    )
    assert not planner.run()
    assert said[-1] == "Not connected to a controller: nothing was sent."


def test_run_disables_the_motion_panels(qtbot: Any, window: MainWindow) -> None:
    window.run_controller.runningChanged.emit(True)
    assert not window.points_panel.action_teach.isEnabled()
    assert not window.jog_panel.isEnabled() or not window.motion_enabled
    window.run_controller.runningChanged.emit(False)


def test_angles_are_unwrapped_for_the_plot(qtbot: Any) -> None:
    assert unwrap_degrees(179.0, 179.0, -179.0) == pytest.approx(181.0)
    assert unwrap_degrees(-179.0, -539.0, 179.0) == pytest.approx(-541.0)
    from app.models import Pose

    panel = MonitorPanel()
    qtbot.addWidget(panel)
    for i, a in enumerate((170.0, 178.0, -178.0, -170.0, 180.0, -180.0)):
        panel.on_pose(Pose(0.0, 0.0, 0.0, a, 0.0, 0.0), t=float(i))
    panel.refresh()
    _, ys = panel.curves["A"].getData()
    assert list(ys) == pytest.approx([170.0, 178.0, 182.0, 190.0, 180.0, 180.0])
    assert panel.readouts["A"].value == -180.0  # the readout shows the controller's value
