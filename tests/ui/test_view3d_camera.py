"""The 3D view's camera and what it draws on screen (issue 21, layout): the default view frames
the arm and every point, re-fits for new points until the operator moves it, the wheel zooms
about the cursor, *Fit plan* frames the plan, point names never overlap, the TCP triad keeps its
screen size, and the dry run plays every loop and names it (both languages).

Every check is on screen positions: what the canvas's camera projects (the same projection it
draws with), in the canvas's own pixels."""

from __future__ import annotations

import itertools
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from PySide6.QtCore import QPoint, QPointF, Qt
from PySide6.QtGui import QWheelEvent
from PySide6.QtWidgets import QApplication

from app.plan.estimates import estimate_plan
from app.view3d.camera import FIT_MARGIN, Preset
from app.view3d.path import start_of
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    app_settings_fixture,
    connect,
    fast_reconnect_fixture,
    link_fixture,
    project_dialogs_fixture,
    translator_fixture,
    window_fixture,
)
from ui.main_window import MainWindow
from ui.panels.view3d_canvas import View3DCanvas
from ui.panels.view3d_panel import View3DPanel

DEMO = Path(__file__).resolve().parents[2] / "resources" / "samples" / "demo.teachpad.json"
TIGHT = 0.85 / FIT_MARGIN  # a fitted scene fills at least this much of the viewport along one side


def _settle() -> None:
    """Let the window lay out after a resize or a dock move (posted layout requests, resizes)."""
    for _ in range(3):
        QApplication.sendPostedEvents()
        QApplication.processEvents()


def _panel(window: MainWindow, qtbot: Any, size: tuple[int, int] = (1280, 800)) -> View3DPanel:
    window.resize(*size)
    panel = window.view3d.panel
    window.work_tabs.setCurrentWidget(panel)
    qtbot.waitUntil(lambda: panel.canvas.isVisible())
    _settle()
    return panel


def _screen(canvas: View3DCanvas, xyz: np.ndarray) -> np.ndarray:
    return canvas.project(np.asarray(xyz, dtype=np.float64).reshape(-1, 3))


def _inside(canvas: View3DCanvas, screen: np.ndarray) -> bool:
    w, h = canvas.width(), canvas.height()
    return bool(
        np.isfinite(screen).all()
        and (screen[:, 0] >= 0).all()
        and (screen[:, 0] <= w).all()
        and (screen[:, 1] >= 0).all()
        and (screen[:, 1] <= h).all()
    )


def _fill(canvas: View3DCanvas, screen: np.ndarray) -> float:
    """How much of the canvas the points' screen extents fill, along the fuller side."""
    extent = screen.max(axis=0) - screen.min(axis=0)
    return float(max(extent[0] / canvas.width(), extent[1] / canvas.height()))


def _scene(canvas: View3DCanvas) -> np.ndarray:
    assert canvas.arm is not None
    return np.concatenate([canvas.arm, canvas.point_xyz, canvas.path_xyz])


def _wheel(canvas: View3DCanvas, x: float, y: float, notches: int) -> None:
    pos = QPointF(x, y)
    event = QWheelEvent(
        pos,
        canvas.mapToGlobal(pos),
        QPoint(0, 0),
        QPoint(0, 120 * notches),
        Qt.MouseButton.NoButton,
        Qt.KeyboardModifier.NoModifier,
        Qt.ScrollPhase.NoScrollPhase,
        False,
    )
    QApplication.sendEvent(canvas, event)


@pytest.mark.parametrize("where", ["1280x800", "1920x1080", "beside the planner"])
def test_default_camera_frames_the_live_arm_and_every_point(
    qtbot: Any, sim: Any, link: Any, window: MainWindow, where: str
) -> None:
    assert window.project.open_file(DEMO)
    size = (1280, 800) if where == "beside the planner" else tuple(int(v) for v in where.split("x"))
    panel = _panel(window, qtbot, size)  # type: ignore[arg-type]
    if where == "beside the planner":  # a narrow, tall canvas
        panel.beside_button.setChecked(True)
        qtbot.waitUntil(lambda: panel.canvas.isVisible())
        _settle()
    connect(qtbot, link, sim)
    qtbot.waitUntil(lambda: panel._joints is not None and "flange" in panel.canvas.drawn, timeout=5000)
    canvas = panel.canvas
    canvas.repaint()
    screen = _screen(canvas, _scene(canvas))
    assert _inside(canvas, screen), (where, canvas.size(), screen.min(axis=0), screen.max(axis=0))
    assert _fill(canvas, screen) >= TIGHT, (where, _fill(canvas, screen))


def test_new_points_refit_the_camera_until_the_operator_moves_it(qtbot: Any, window: MainWindow) -> None:
    assert window.project.open_file(DEMO)
    panel = _panel(window, qtbot)
    canvas = panel.canvas
    model = window.project.points_model
    model.add_point(name="far", pose=(-1400.0, 1200.0, 1000.0, 180.0, 0.0, 180.0))
    qtbot.waitUntil(lambda: len(canvas.point_xyz) == 9)
    canvas.repaint()
    screen = _screen(canvas, _scene(canvas))
    assert _inside(canvas, screen) and _fill(canvas, screen) >= TIGHT  # framed again: the camera follows
    # the operator zooms: from now on the scene does not move the camera
    _wheel(canvas, canvas.width() * 0.3, canvas.height() * 0.4, 2)
    moved = canvas.camera
    assert not canvas.auto_camera
    model.add_point(name="farther", pose=(1800.0, -1700.0, 50.0, 180.0, 0.0, 180.0))
    qtbot.waitUntil(lambda: len(canvas.point_xyz) == 10)
    assert canvas.camera == moved
    assert not _inside(canvas, _screen(canvas, canvas.point_xyz[-1]))
    # Fit all: everything again, and the camera follows the scene again
    panel.fit_button.click()
    assert canvas.auto_camera
    screen = _screen(canvas, _scene(canvas))
    assert _inside(canvas, screen) and _fill(canvas, screen) >= TIGHT


def test_the_wheel_zooms_about_the_cursor(qtbot: Any, window: MainWindow) -> None:
    assert window.project.open_file(DEMO)
    panel = _panel(window, qtbot)
    canvas = panel.canvas
    canvas.set_camera(canvas.camera.preset(Preset.ISO))
    model = window.project.points_model
    row = model.row_of(2)
    assert row is not None
    xyz = np.array(model.point_at(row).xyz)
    x, y = _screen(canvas, xyz)[0]  # the cursor on point P2, away from the centre
    assert abs(x - canvas.width() / 2) > 40 or abs(y - canvas.height() / 2) > 40
    cam, w, h = canvas.camera, canvas.width(), canvas.height()
    ppm = cam.pixels_per_mm(h)  # the world under the cursor, on the target's plane
    plane = np.array(cam.target) + ((x - w / 2) * cam.basis[0] + (h / 2 - y) * cam.basis[1]) / ppm
    assert np.allclose(_screen(canvas, plane)[0], (x, y))
    before = canvas.camera
    for notches in (3, -5, 1):
        _wheel(canvas, x, y, notches)
        assert np.allclose(_screen(canvas, xyz)[0], (x, y), atol=0.01)
        assert np.allclose(_screen(canvas, plane)[0], (x, y), atol=0.01)
    assert canvas.camera.distance == pytest.approx(before.distance / 1.15 ** (3 - 5 + 1))
    centre = before.target  # what the screen's centre showed has moved: not a zoom about the centre
    assert not np.allclose(_screen(canvas, np.array(centre))[0], (canvas.width() / 2, canvas.height() / 2))


def test_fit_plan_frames_the_plan_and_its_points(qtbot: Any, window: MainWindow) -> None:
    assert window.project.open_file(DEMO)
    panel = _panel(window, qtbot)
    canvas = panel.canvas
    planner = window.planner_panel
    for row in (1, 0):
        planner.select_plan(row)
        qtbot.waitUntil(lambda: panel.plan is planner.current_plan())
        _wheel(canvas, 40.0, 40.0, -6)  # the operator zoomed far out, off to a corner
        canvas.set_camera(canvas.camera.orbited(35.0, 10.0))
        plan = planner.current_plan()
        assert plan is not None and panel.fit_plan_button.isEnabled()
        panel.fit_plan_button.click()
        ids = plan.point_ids()
        points = np.array([p.xyz for p in window.project.points_model.ledger if p.id in ids])
        screen = _screen(canvas, np.concatenate([canvas.path_xyz, points]))
        assert _inside(canvas, screen) and _fill(canvas, screen) >= TIGHT, (row, _fill(canvas, screen))
        assert not canvas.auto_camera  # the operator's framing: new points do not undo it


def _overlapping(rects: list[Any]) -> list[tuple[int, int]]:
    return [(a, b) for (a, ra), (b, rb) in itertools.combinations(rects, 2) if ra.intersects(rb)]


def test_point_labels_never_overlap_and_the_selected_one_shows(qtbot: Any, window: MainWindow) -> None:
    assert window.project.open_file(DEMO)
    panel = _panel(window, qtbot)
    canvas = panel.canvas
    hidden_somewhere: set[int] = set()
    for preset in Preset:
        panel.set_preset(preset)
        for zoom in (1.0, 0.25):  # as fitted, and zoomed out: the markers crowd together
            canvas.set_camera(canvas.camera.zoomed(zoom))
            canvas.repaint()
            rects = canvas.label_rects
            assert rects and not _overlapping(rects), (preset, zoom, _overlapping(rects))
            assert all(canvas.rect().contains(r.toAlignedRect()) for _pid, r in rects)
            badges = canvas._badge_rects()  # "no pose: home position shown" at least
            assert badges and not [pid for pid, r in rects if any(r.intersects(b) for b in badges)]
            hidden_somewhere |= set(int(i) for i in canvas.point_ids) - {pid for pid, _r in rects}
    assert hidden_somewhere  # crowded views hide names (today they pile up)
    # a crowded view: the selected point's name shows whatever its rank, still without overlap
    panel.set_preset(Preset.ISO)
    canvas.set_camera(canvas.camera.zoomed(0.25))
    canvas.repaint()
    hidden = sorted(set(int(i) for i in canvas.point_ids) - {pid for pid, _r in canvas.label_rects})
    assert hidden
    row = window.project.points_model.row_of(hidden[0])
    assert row is not None
    window.points_panel.select_rows([row])
    canvas.repaint()
    assert hidden[0] in {pid for pid, _r in canvas.label_rects}
    assert not _overlapping(canvas.label_rects)
    # ... and so does the hovered one
    others = sorted(set(int(i) for i in canvas.point_ids) - {pid for pid, _r in canvas.label_rects})
    assert others
    x, y = _screen(canvas, canvas.point_xyz[[int(i) for i in canvas.point_ids].index(others[0])])[0]
    assert canvas.hover_at(x, y) is not None
    canvas.repaint()
    assert canvas.hovered_id in {pid for pid, _r in canvas.label_rects}
    assert not _overlapping(canvas.label_rects)


def _triad_px(canvas: View3DCanvas) -> float:
    tri = canvas.drawn["flange_triad"]
    return float(np.max(np.hypot(*(tri[1:] - tri[0]).T)))


@pytest.mark.parametrize("ortho", [False, True])
def test_tcp_triad_keeps_its_screen_size_whatever_the_zoom(
    qtbot: Any, window: MainWindow, ortho: bool
) -> None:
    panel = _panel(window, qtbot)
    panel.ortho_button.setChecked(ortho)
    canvas = panel.canvas
    panel.on_joints((20.0, 10.0, -15.0, 30.0, 50.0, 10.0))
    panel._update_arm()
    assert canvas.flange is not None
    flange = canvas.flange[:3, 3]
    canvas.repaint()
    lengths = [_triad_px(canvas)]
    for factor in (3.0, 1 / 9.0):  # zoomed in 3x about the flange, then out to 1/3 of the first
        x, y = _screen(canvas, flange)[0]
        canvas.zoom_at(factor, x, y)
        canvas.repaint()
        lengths.append(_triad_px(canvas))
    from ui.panels.view3d_canvas import TRIAD_PX

    assert lengths[0] == pytest.approx(TRIAD_PX, rel=0.15)  # the longest axis lies nearly across the view
    assert lengths[1] == pytest.approx(lengths[0], rel=0.03)
    assert lengths[2] == pytest.approx(lengths[0], rel=0.03)


def test_dry_run_plays_every_loop_and_names_it_in_both_languages(qtbot: Any, window: MainWindow) -> None:
    assert window.project.open_file(DEMO)
    panel = _panel(window, qtbot)
    planner = window.planner_panel
    planner.select_plan(0)  # pick and place: 2 loops in the demo
    plans = window.project.plans_model
    assert plans.set_loops(0, 20)
    bar = panel.dry_bar
    qtbot.waitUntil(lambda: bar.run is not None and bar.run.loops == 20)
    plan = planner.current_plan()
    assert plan is not None and plan.loops == 20
    ledger = window.project.points_model.ledger
    start, _rot = start_of(plan, ledger, None)
    assert bar.run is not None
    assert bar.run.duration == pytest.approx(estimate_plan(plan, ledger, start).total_time)
    assert bar.loop_label.text() == "loop 1 of 20"
    bar.slider.setValue(500)  # half way through the run: loop 10 or 11
    assert bar.loop_label.text() in ("loop 10 of 20", "loop 11 of 20")
    bar.slider.setValue(1000)
    assert bar.loop_label.text() == "loop 20 of 20"
    canvas = panel.canvas
    canvas.repaint()
    end = ledger.get(plan.segments[-1].end_id)
    assert end is not None
    assert np.allclose(canvas.drawn["ghost_flange"], _screen(canvas, np.array(end.xyz)), atol=0.5)
    window.set_language("zh_CN")
    assert bar.loop_label.text() == "第 20 轮（共 20 轮）"
    assert panel.fit_plan_button.text() == "缩放至轨迹"
    assert plans.set_loops(0, 0)  # endless
    qtbot.waitUntil(lambda: bar.run is not None and bar.run.loops == 0)
    bar.slider.setValue(1000)
    assert bar.loop_label.text() == "第 2 轮（无限循环：之后每轮都相同）"
    window.set_language("en")
    assert bar.loop_label.text() == "loop 2 (endless: every later loop is the same)"


@pytest.mark.parametrize("size", [(1280, 800), (1920, 1080)], ids=lambda s: f"{s[0]}x{s[1]}")
@pytest.mark.parametrize("language", ["en", "zh_CN"])
def test_the_3d_view_lays_out_whole_in_both_languages(
    qtbot: Any, window: MainWindow, translator: Any, language: str, size: tuple[int, int]
) -> None:
    """Its buttons (Fit plan too), the model's line and the dry run bar with its loop: no text
    clipped, no two widgets on top of each other, in its tab and beside the planner."""
    from tests.ui.layout_audit import clipped_texts, overlapping_siblings
    from tests.ui.test_layout import cjk_font_installed

    assert window.project.open_file(DEMO)
    window.set_language(language)
    panel = _panel(window, qtbot, size)
    window.planner_panel.select_plan(0)  # 2 loops: the loop shows in the dry run bar
    qtbot.waitUntil(lambda: panel.dry_bar.loop_label.isVisible())
    for where in ("tab", "beside the planner"):
        panel.beside_button.setChecked(where != "tab")
        qtbot.waitUntil(lambda: panel.isVisible())
        _settle()
        found = overlapping_siblings(panel)
        if language == "en" or cjk_font_installed():
            found += clipped_texts(panel)
        assert not found, (where, found)
