"""3D view benchmark: frame times of the QPainter projection with 10,000 point markers and a
1,000-segment plan (lines and true arcs), and the time to check their reach.

* ``rotate_frame_ms``: what a mouse drag costs per frame -- the camera turns 2° and the whole
  scene is projected and drawn again with the drag's level of detail (markers thinned to
  ``LOD_MAX_POINTS`` and only those projected, the path to ``LOD_MAX_PATH_ROWS`` rows, no
  antialiasing, no labels), into a QImage of the canvas's size (the
  raster engine, as the widget's backing store). ``rotate_fps`` = 1000 / median.
  ``rotate_frame_cpu_ms``: the same frames in CPU time of the GUI thread (what a frame costs
  when the machine's other work does not take the core away; ``rotate_fps_cpu`` from its median).
* ``still_frame_ms``: the first frame after the drag ends (full quality: every marker, the
  antialiased path, arrows; the static layers are then cached).
* ``live_frame_ms``: a new arm pose with the camera still (cached static layers + the arm).
* ``reach_points_s`` / ``reach_path_s``: IK of every point / of the plan's path samples (one
  batch each, cold cache).
* ``plan_reach_cold_s`` / ``plan_reach_again_ms`` / ``plan_reach_point_moved_ms``: the
  planner's reach check of the whole plan: cold, repeated, and after one point moved.

Usage: python -m benchmarks.view3d [--quick]  (``benchmarks.gui.run`` adds it as ``view3d``).
"""

from __future__ import annotations

import json
import os
import statistics
import sys
import time
from typing import Any

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

import numpy as np
from PySide6.QtGui import QImage, QPainter
from PySide6.QtWidgets import QApplication

from app.plan.geometry import plan_path
from app.plan.segments import Plan, Segment
from app.points.ledger import PointLedger
from app.points.point import SyncState, make_point
from app.view3d.camera import Preset
from app.view3d.kinematics import ArmModel
from app.view3d.profile import default_profile
from app.view3d.reach import ReachChecker
from ui.panels import view3d_canvas
from ui.panels.view3d_canvas import View3DCanvas
from ui.panels.view3d_scene import SYNC_COLORS

N_POINTS = 10_000
N_SEGMENTS = 1_000
CANVAS_SIZE = (1200, 800)
PATH_SAMPLES = 24  # per segment, as the panel draws a plan of this size (40,000 rows / 1,000)
SYNC_STATES = list(SyncState)


def _scene(rng: np.random.Generator) -> tuple[PointLedger, Plan]:
    xyz = np.column_stack(
        [rng.uniform(150, 750, N_POINTS), rng.uniform(-500, 500, N_POINTS), rng.uniform(50, 800, N_POINTS)]
    )
    points = [
        make_point(i + 1, f"P{i + 1}", (*xyz[i], 180.0, 0.0, 180.0), sync=SYNC_STATES[i % 4])
        for i in range(N_POINTS)
    ]
    segments = []
    for k in range(N_SEGMENTS):
        a, b = 2 * k + 1, 2 * k + 2
        segments.append(Segment.arc(a, b, speed=100.0) if k % 2 else Segment.line(b, speed=100.0))
    return PointLedger(points), Plan("bench", segments)


def _pct(values: list[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(q * len(ordered)))]


def _summary(ms: list[float]) -> dict[str, float]:
    return {"median": statistics.median(ms), "p95": _pct(ms, 0.95), "max": max(ms), "n": len(ms)}


def _planner_reach(model: ArmModel, ledger: PointLedger, plan: Plan) -> dict[str, float]:
    """The planner's reach check (``ReachChecker.plan_issues``, on the GUI thread): the whole
    plan with a cold cache, the same again (a recheck after an unrelated change), and after
    one of its points moved (an edit)."""
    checker = ReachChecker(model)
    t0 = time.perf_counter()
    checker.plan_issues(plan, ledger, None)
    cold = time.perf_counter() - t0
    t0 = time.perf_counter()
    checker.plan_issues(plan, ledger, None)
    again = time.perf_counter() - t0
    moved = []
    for k in range(3):
        row = ledger.row_of(plan[k].end_id)
        assert row is not None
        p = ledger[row]
        ledger.replace(row, make_point(p.id, p.name, (p.x + 1.0, p.y, p.z, p.a, p.b, p.c)))
        t0 = time.perf_counter()
        checker.plan_issues(plan, ledger, None)
        moved.append(time.perf_counter() - t0)
    return {
        "plan_reach_cold_s": cold,
        "plan_reach_again_ms": again * 1000.0,
        "plan_reach_point_moved_ms": statistics.median(moved) * 1000.0,
    }


def run(quick: bool = False) -> dict[str, Any]:
    app = QApplication.instance() or QApplication([])
    rng = np.random.default_rng(11)
    ledger, plan = _scene(rng)
    points = list(ledger)
    canvas = View3DCanvas()
    canvas.resize(*CANVAS_SIZE)
    model = ArmModel(default_profile())
    q = model.home
    canvas.set_arm(model.link_points(q), model.joint_points(q), model.forward(q))
    t0 = time.perf_counter()
    path = plan_path(plan, ledger, points[0].xyzabc, PATH_SAMPLES)
    path_ms = (time.perf_counter() - t0) * 1000.0
    colors = [SYNC_COLORS[p.sync] for p in points]
    canvas.set_points(
        np.array([p.xyz for p in points]),
        [p.id for p in points],
        [p.label for p in points],
        colors,
        np.zeros(N_POINTS, dtype=bool),
    )
    mids = np.array([p.xyz for s in plan.segments if s.via_id is not None and (p := ledger.get(s.via_id))])
    canvas.set_path(path.xyz, path.segment, np.zeros(len(path.xyz), dtype=bool), mids, path.xyz[0])
    canvas.set_camera(canvas.camera.preset(Preset.ISO))
    canvas.fit_all()
    image = QImage(*CANVAS_SIZE, QImage.Format.Format_ARGB32_Premultiplied)

    cpu: list[float] = []

    def frame() -> float:
        start, start_cpu = time.perf_counter(), time.thread_time()
        painter = QPainter(image)
        canvas.render_scene(painter)
        painter.end()
        cpu.append((time.thread_time() - start_cpu) * 1000.0)
        return (time.perf_counter() - start) * 1000.0

    frames = 60 if quick else 240
    canvas.set_dragging(True)
    frame()  # warm-up
    rotate = []
    for _ in range(frames):
        canvas.set_camera(canvas.camera.orbited(2.0, 0.0))
        rotate.append(frame())
    rotate_cpu = cpu[1:]
    canvas.set_dragging(False)
    still = []
    for _ in range(max(5, frames // 8)):
        canvas.set_camera(canvas.camera.orbited(2.0, 0.0))
        still.append(frame())
    live = []
    for k in range(frames):
        q = model.home + np.array([k % 30, 0, 0, 0, 0, 0], dtype=np.float64)
        canvas.set_arm(model.link_points(q), model.joint_points(q), model.forward(q))
        live.append(frame())
    checker = ReachChecker(model)
    n_reach = 2000 if quick else N_POINTS
    t0 = time.perf_counter()
    reach = checker.points(points[:n_reach])
    reach_points_s = time.perf_counter() - t0
    t0 = time.perf_counter()
    checker.path(plan, ledger, None)
    reach_path_s = time.perf_counter() - t0
    planner = _planner_reach(model, ledger, plan)
    canvas.deleteLater()
    app.processEvents()
    rot = _summary(rotate)
    return {
        "points": N_POINTS,
        "segments": N_SEGMENTS,
        "path_rows": len(path.xyz),
        "canvas_px": list(CANVAS_SIZE),
        "lod_max_points": view3d_canvas.LOD_MAX_POINTS,
        "lod_max_path_rows": view3d_canvas.LOD_MAX_PATH_ROWS,
        "rotate_frame_ms": rot,
        "rotate_fps": 1000.0 / rot["median"],
        "rotate_fps_p95": 1000.0 / rot["p95"],
        "rotate_frame_cpu_ms": _summary(rotate_cpu),
        "rotate_fps_cpu": 1000.0 / statistics.median(rotate_cpu),
        "still_frame_ms": _summary(still),
        "live_frame_ms": _summary(live),
        "plan_path_ms": path_ms,
        "reach_points": n_reach,
        "reach_points_s": reach_points_s,
        "reach_points_unreachable": sum(1 for r in reach.values() if r.value != "ok"),
        "reach_path_s": reach_path_s,
        **planner,
        "load_avg_1m": os.getloadavg()[0],
    }


if __name__ == "__main__":
    json.dump(run("--quick" in sys.argv[1:]), sys.stdout, indent=2, sort_keys=True)
    sys.stdout.write("\n")
