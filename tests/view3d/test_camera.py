"""The orbit camera: projection, presets, fit-all and picking."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from app.errors import InvalidInput
from app.view3d.camera import Camera, Preset, grid_lines, nice_step, pick


def test_target_projects_to_the_centre_and_behind_is_nan() -> None:
    cam = Camera(target=(100.0, 50.0, 300.0), distance=1000.0)
    screen, depth = cam.project(np.array([[100.0, 50.0, 300.0], cam.eye - cam.basis[2] * 10.0]), 800, 600)
    assert np.allclose(screen[0], (400.0, 300.0))
    assert depth[0] == pytest.approx(1000.0)
    assert np.isnan(screen[1]).all()


@pytest.mark.parametrize(
    ("preset", "right", "up"),
    [
        (Preset.TOP, (1, 0, 0), (0, 1, 0)),
        (Preset.FRONT, (1, 0, 0), (0, 0, 1)),
        (Preset.SIDE, (0, 1, 0), (0, 0, 1)),
    ],
)
def test_presets_match_the_planner_projections(
    preset: Preset, right: tuple[int, ...], up: tuple[int, ...]
) -> None:
    cam = Camera(target=(0.0, 0.0, 0.0)).preset(preset)
    s, _ = cam.project(np.array([[0.0, 0.0, 0.0], right, up], dtype=float) * 100.0, 600, 600)
    assert s[1, 0] > s[0, 0] and s[1, 1] == pytest.approx(s[0, 1], abs=1e-6)  # right is right
    assert s[2, 1] < s[0, 1] and s[2, 0] == pytest.approx(s[0, 0], abs=1e-6)  # up is up


@pytest.mark.parametrize("ortho", [False, True])
def test_fit_all_shows_every_point(ortho: bool) -> None:
    pts = np.random.default_rng(3).uniform(-2000, 2000, (500, 3))
    cam = Camera(ortho=ortho).preset(Preset.ISO).fitted(pts, aspect=1.5)
    s, _ = cam.project(pts, 900, 600)
    assert np.isfinite(s).all()
    assert (s[:, 0] >= 0).all() and (s[:, 0] <= 900).all() and (s[:, 1] >= 0).all() and (s[:, 1] <= 600).all()


def test_orbit_zoom_pan() -> None:
    cam = Camera(target=(0.0, 0.0, 0.0), distance=1000.0)
    assert cam.orbited(10.0, 100.0).pitch == 90.0
    assert cam.zoomed(2.0).distance == pytest.approx(500.0)
    moved = cam.panned(50.0, 0.0, 600)
    s, _ = moved.project(np.zeros((1, 3)), 800, 600)
    assert s[0, 0] == pytest.approx(450.0)  # the scene follows the mouse
    with pytest.raises(InvalidInput):
        cam.zoomed(0.0)


def test_pick_nearest_within_radius_prefers_the_nearer_marker() -> None:
    screen = np.array([[10.0, 10.0], [100.0, 100.0], [100.4, 100.0], [np.nan, np.nan]])
    assert pick(screen, (12.0, 11.0)) == 0
    assert pick(screen, (50.0, 50.0)) is None
    assert pick(screen, (100.2, 100.0), depth=np.array([1.0, 900.0, 300.0, 1.0])) == 2
    assert pick(np.zeros((0, 2)), (0.0, 0.0)) is None


def test_grid_and_nice_steps() -> None:
    lines = grid_lines(500.0, 100.0)
    assert lines.shape == (22, 2, 3)
    assert [nice_step(v) for v in (0.7, 3.0, 42.0, 180.0)] == [1.0, 5.0, 50.0, 200.0]


def _extent(screen: np.ndarray) -> np.ndarray:
    return np.asarray(screen.max(axis=0) - screen.min(axis=0))


@pytest.mark.parametrize("ortho", [False, True])
@pytest.mark.parametrize("preset", list(Preset))
@pytest.mark.parametrize(("width", "height"), [(900, 600), (300, 700), (1200, 300)])
def test_fit_frames_the_points_tightly_at_any_aspect(
    ortho: bool, preset: Preset, width: int, height: int
) -> None:
    """Every point inside the viewport, and the points fill it (to the margin) along its tighter
    side: the distance comes from the points and the aspect, not from a bounding sphere."""
    from app.view3d.camera import FIT_MARGIN

    arm_and_points = np.array(
        [
            [0, 0, 0],
            [0, 0, 450],
            [100, 0, 450],
            [100, 0, 900],
            [525, 0, 900],
            [525, 0, 790],
            [400, -200, 300],
        ],
        dtype=np.float64,
    )
    cam = Camera(ortho=ortho).preset(preset).fitted(arm_and_points, aspect=width / height)
    s, _ = cam.project(arm_and_points, width, height)
    assert np.isfinite(s).all()
    assert (
        (s[:, 0] >= 0).all()
        and (s[:, 0] <= width).all()
        and (s[:, 1] >= 0).all()
        and (s[:, 1] <= height).all()
    )
    fill = _extent(s) / np.array([width, height])
    assert fill.max() == pytest.approx(1.0 / FIT_MARGIN, rel=0.03)


def test_zoom_at_keeps_every_point_of_the_cursor_ray_under_the_cursor() -> None:
    cam = Camera(target=(300.0, 0.0, 400.0), distance=2000.0).preset(Preset.ISO)
    w, h, cursor = 800, 600, (620.0, 170.0)
    near = cam.point_at(*cursor, w, h)  # on the target's plane
    ray = near - cam.eye
    far = cam.eye + ray * 1.6  # behind the target's plane, on the same ray
    for factor in (1.15, 1.15**3, 1 / 1.15**2):
        zoomed = cam.zoomed_at(factor, *cursor, w, h)
        assert zoomed.distance == pytest.approx(cam.distance / factor)
        s, _ = zoomed.project(np.array([near, far]), w, h)
        assert np.allclose(s, [cursor, cursor], atol=1e-6)
    ortho = replace(cam, ortho=True)
    s, _ = ortho.zoomed_at(2.0, *cursor, w, h).project(ortho.point_at(*cursor, w, h), w, h)
    assert np.allclose(s, [cursor], atol=1e-6)
    clamped = cam.zoomed_at(1e6, *cursor, w, h)  # the nearest allowed distance: still about the cursor
    assert np.allclose(clamped.project(near, w, h)[0], [cursor], atol=1e-6)
