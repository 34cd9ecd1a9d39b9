"""Temp points and plans at scale: project files, the point table, restore-all, plan preview.

Each figure is measured in the same run as a baseline:
* loading a 10,000-point project (``app.points.project.load_project``, which parses and validates
  everything) vs ``json.load`` of the same file;
* showing it: ``ui.models.points_model.PointsModel`` (behind the panel's ``PointFilterProxy``) in a
  ``QTableView`` set up like the points panel's, from construction to the first paint, vs a
  minimal table model of the same shape in the same view (offscreen Qt; null with a reason
  when the UI module is missing);
* restoring all points to the simulator with ``RobotClient.upload_points`` — the product's
  "restore all" path (the GUI worker calls it) — in rounds, each vs a bare pymodbus loop of
  the same per-point transactions sampled right before and after it (``benchmarks.restore``:
  the median of the round ratios); the CLI's path (``app.cli.points_upload.staged_upload``: the
  same batches, per tool) on a sample;
* the autosave of a large project (58 MB, as in issue 19: 10,000 points with long notes and
  400 plans of 1,000 segments): the time the GUI thread spends on it -- before (issue 19 s6) the
  whole save (``save_autosave`` on the GUI thread), now ``ProjectController.autosave_now`` (the
  snapshot; the writer's thread serializes and writes) -- and the longest the GUI thread could
  not run while the writer works, vs the same spin with nothing else running (quick mode: a tenth
  of the size);
* plan geometry for 1,000 segments (``plan_path``, ``plan_geometry``, ``check_plan``,
  ``estimate_plan``) vs sampling the same segments one by one with ``segment_path``; and the
  preview widget's (``ui.panels.plan_preview.PlanPreview``) redraw of the 1,000 segments, vs the
  same widget redrawing a 10-segment plan.

Requests and time per created point on each simulator timing profile: see ``benchmarks.completion``
(``completion_profiles``).

Quick mode restores 500 points (5 rounds, 0.1 s bare samples) instead of 10,000 and repeats less.
"""

from __future__ import annotations

import gc
import json
import math
import statistics
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from app.plan.checks import check_plan
from app.plan.estimates import estimate_plan
from app.plan.geometry import plan_geometry, plan_path, segment_path
from app.plan.segments import Plan, Segment
from app.points.ledger import PointLedger
from app.points.point import SyncState, TempPoint, make_point
from app.points.project import load_project, save_project
from app.points.project_model import Project
from benchmarks import completion, restore
from benchmarks.restore import QUICK_SAMPLE_S, ROUNDS, SAMPLE_S
from ui.startup_gc import gc_paused

PROJECT_POINTS = 10_000
PLAN_SEGMENTS = 1_000
PAINT_TIMEOUT = 10.0  # s to wait for a widget's first paint
HOME = (525.0, 0.0, 504.4)


def _ms(seconds: float) -> float:
    return round(1000.0 * seconds, 3)


def _median_ms(fn: Callable[[], object], repeats: int) -> float:
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return _ms(statistics.median(times))


def _points(n: int) -> list[TempPoint]:
    """``n`` points in front of the arm, tool down; ids 1..n."""
    return [
        make_point(
            i,
            f"p{i}",
            (300.0 + i % 100, -100.0 + i % 50, 300.0 + i % 20, 180.0, 0.0, float(i % 90)),
            note="bench" if i % 10 == 0 else "",
            sync=SyncState.UNKNOWN,
        )
        for i in range(1, n + 1)
    ]


# --- project file: load and show ---------------------------------------------------------------


def bench_load(path: Path, repeats: int) -> dict[str, Any]:
    def product() -> object:
        return load_project(path)

    def baseline() -> object:
        with path.open(encoding="utf-8") as f:
            return json.load(f)

    product()  # warm the file cache and imports
    # Interleaved, one of each per round: both sides of a ratio see the same minutes of a machine
    # whose speed drifts (all loads first, then all json.loads, measured each in another phase).
    # Each timed without automatic collection, after a full one, as the GUI process loads a project
    # (ui/gui_gc.py: its collections run from a timer, between events): otherwise which side a
    # full pass over the bench's own heap lands in decides the pair.
    load_ms: list[float] = []
    json_ms: list[float] = []
    for _ in range(repeats):
        for fn, times in ((product, load_ms), (baseline, json_ms)):
            gc.collect()
            with gc_paused():
                times.append(_median_ms(fn, 1))
    load, base = statistics.median(load_ms), statistics.median(json_ms)
    paired = statistics.median(a / b for a, b in zip(load_ms, json_ms, strict=True))
    return {
        "points": PROJECT_POINTS,
        "file_bytes": path.stat().st_size,
        "load_project_ms": load,
        "json_load_ms": base,
        "repeats": repeats,
        "ratio_of_medians": round(load / base, 2),
        "ratio_load_vs_json": round(paired, 2),  # the median of the rounds' ratios
    }


def _qt_app() -> Any:
    from PySide6.QtWidgets import QApplication

    return QApplication.instance() or QApplication([])


class _PaintProbe:
    """Counts paint events of one widget (an event filter; painting is done once
    ``processEvents`` returns)."""

    def __init__(self, widget: Any) -> None:
        from PySide6.QtCore import QEvent, QObject

        paint = QEvent.Type.Paint
        probe = self

        class Filter(QObject):
            def eventFilter(self, obj: Any, event: Any) -> bool:
                if event.type() == paint:
                    probe.count += 1
                return False

        self.count = 0
        self._filter = Filter()
        widget.installEventFilter(self._filter)


def _wait_painted(app: Any, probes: list[_PaintProbe], since: list[int]) -> None:
    deadline = time.perf_counter() + PAINT_TIMEOUT
    while any(p.count <= s for p, s in zip(probes, since, strict=True)):
        app.processEvents()
        if time.perf_counter() > deadline:
            raise RuntimeError("the widget was not painted within the timeout")


def bench_show(project: Project, repeats: int) -> dict[str, Any]:
    try:
        from PySide6.QtCore import QAbstractTableModel, QModelIndex, Qt
        from PySide6.QtGui import QUndoStack
        from PySide6.QtWidgets import QHeaderView, QTableView

        from ui.models.point_columns import COLUMNS
        from ui.models.point_filter import PointFilterProxy
        from ui.models.points_model import PointsModel
    except ImportError as exc:
        return {"show_ms": None, "reason": f"ui/points_model.py is not usable: {exc}"}
    app = _qt_app()
    rows, cols = len(project.ledger), len(COLUMNS)

    class MinimalModel(QAbstractTableModel):
        def rowCount(self, parent: Any = QModelIndex()) -> int:  # noqa: B008
            return 0 if parent.isValid() else rows

        def columnCount(self, parent: Any = QModelIndex()) -> int:  # noqa: B008
            return 0 if parent.isValid() else cols

        def data(self, index: Any, role: int = Qt.ItemDataRole.DisplayRole) -> Any:
            return str(index.row()) if role == Qt.ItemDataRole.DisplayRole else None

    def show(make_model: Callable[[], Any]) -> float:
        t0 = time.perf_counter()
        model = make_model()
        proxy = PointFilterProxy()
        proxy.setSourceModel(model)
        view = QTableView()  # set up like ui/points_panel.py's table
        view.setModel(proxy)
        view.setAlternatingRowColors(True)
        view.setWordWrap(False)
        view.verticalHeader().setVisible(False)
        view.verticalHeader().setDefaultSectionSize(24)
        view.horizontalHeader().setSectionResizeMode(QHeaderView.ResizeMode.Interactive)
        view.horizontalHeader().setStretchLastSection(True)
        view.resize(1280, 700)
        probe = _PaintProbe(view.viewport())
        view.show()
        _wait_painted(app, [probe], [0])
        elapsed = time.perf_counter() - t0
        view.close()
        view.deleteLater()
        proxy.deleteLater()
        app.processEvents()
        return elapsed

    stacks: list[Any] = []

    def product() -> Any:
        stack = QUndoStack()
        stacks.append(stack)
        return PointsModel(project, stack)

    show(product)  # warm up fonts, styles, the platform plugin
    product_ms = [_ms(show(product)) for _ in range(repeats)]
    baseline_ms = [_ms(show(MinimalModel)) for _ in range(repeats)]
    shown, base = statistics.median(product_ms), statistics.median(baseline_ms)
    return {
        "points": rows,
        "show_ms": shown,
        "minimal_model_show_ms": base,
        "ratio_vs_minimal_model": round(shown / base, 2),
        "what": "PointsModel + PointFilterProxy + QTableView, construction to first paint (offscreen)",
    }


# --- restore all ---------------------------------------------------------------------------------


def bench_restore(n: int, cli_n: int, *, rounds: int = ROUNDS, sample_s: float = SAMPLE_S) -> dict[str, Any]:
    """Restore-all of ``n`` points in ``rounds`` rounds, each beside a bare pymodbus sample
    (see :mod:`benchmarks.restore`); the CLI's path on ``cli_n`` of them."""
    return restore.bench_restore(_points(n), cli_n, rounds=rounds, sample_s=sample_s)


# --- the autosave of a large project ---------------------------------------------------------------

AUTOSAVE_NOTE_CHARS = 1_000
AUTOSAVE_PLANS = 400
AUTOSAVE_SEGMENTS = 1_000


def _large_project(scale: int) -> Project:
    """About 58 MB on disk at ``scale`` 1 (a tenth of it at 10)."""
    note = "n" * AUTOSAVE_NOTE_CHARS
    points = [
        make_point(i, f"p{i}", (300.0 + i % 100, -100.0 + i % 50, 300.0, 180.0, 0.0, 0.0), note=note)
        for i in range(1, 10_000 // scale + 1)
    ]
    plans = [
        Plan(
            f"plan {k}",
            [Segment.line(1 + (j % 9_000) // scale, speed=200.0 + j % 7) for j in range(AUTOSAVE_SEGMENTS)],
        )
        for k in range(AUTOSAVE_PLANS // scale)
    ]
    return Project("bench", PointLedger(points), plans)


def _longest_gap_ms(done: Callable[[], bool]) -> float:
    """Spin in this (the GUI) thread until ``done``; the longest gap between two turns is the
    longest this thread could not run (the writer's thread holding the interpreter lock, or the
    OS running something else: see the baseline)."""
    longest, last = 0.0, time.perf_counter()
    while not done():
        now = time.perf_counter()
        longest, last = max(longest, now - last), now
    return _ms(longest)


def bench_autosave(quick: bool) -> dict[str, Any]:
    from app.points.autosave import save_autosave
    from ui.controllers.project_controller import ProjectController

    _qt_app()
    project = _large_project(10 if quick else 1)
    with gc_paused():  # as in the GUI process (ui/gui_gc.py): no collection in the writer's thread
        return _autosave_figures(project, ProjectController, save_autosave)


def _autosave_figures(project: Project, controller: Any, save_autosave: Callable[..., Any]) -> dict[str, Any]:
    with tempfile.TemporaryDirectory(prefix="teachpad-bench-") as tmp:
        path = Path(tmp) / "large.teachpad.json"
        save_project(project, path)
        size = path.stat().st_size
        t0 = time.perf_counter()
        save_autosave(project, path)  # issue 19's path: all of it on the GUI thread
        before = time.perf_counter() - t0
        path.with_name("large.teachpad.autosave.json").unlink()
        ctl = controller(project, path, autosave_interval=0)
        try:
            project.touch()  # an edit: the project is dirty
            t0 = time.perf_counter()
            ctl.autosave_now()
            gui = time.perf_counter() - t0
            ctl.wait_autosave(600.0)  # the GUI thread idle, as in its event loop
            written = time.perf_counter() - t0
            project.touch()
            t0 = time.perf_counter()
            ctl.autosave_now()
            gap = _longest_gap_ms(lambda: ctl.autosaver.idle)
            spun = time.perf_counter() - t0
            t0 = time.perf_counter()
            baseline = _longest_gap_ms(lambda: time.perf_counter() - t0 >= spun)
        finally:
            ctl.close()
    return {
        "project_mb": round(size / 1e6, 1),
        "points": len(project.ledger),
        "segments": sum(len(p) for p in project.plans),
        "before_gui_thread_ms": _ms(before),
        "after_gui_thread_ms": _ms(gui),
        "after_written_ms": _ms(written),
        "after_gui_thread_longest_gap_ms": gap,
        "baseline_longest_gap_ms": baseline,
        "note": "before: save_autosave on the GUI thread (issue 19 s6); after: autosave_now (the "
        "snapshot) on the GUI thread, the writer's thread serializes and writes; longest gap: the "
        "GUI thread spinning while the writer works, vs spinning as long with nothing else running",
    }


# --- plan geometry and preview -------------------------------------------------------------------


def _plan(segments: int) -> tuple[Plan, PointLedger]:
    """Points on a slowly rising helix; lines and arcs alternate (an arc uses two points)."""
    count = segments + segments // 2 + 1
    pts = []
    for i in range(1, count + 1):
        t = 0.35 * i
        pts.append(
            make_point(
                i, "", (450.0 + 80.0 * math.cos(t), 80.0 * math.sin(t), 300.0 + 0.05 * i, 180.0, 0.0, 0.0)
            )
        )
    ledger = PointLedger(pts)
    segs: list[Segment] = []
    pid = 1
    for k in range(segments):
        if k % 2 == 0:
            segs.append(Segment.line(pid, speed=200.0))
            pid += 1
        else:
            segs.append(Segment.arc(pid, pid + 1, speed=100.0))
            pid += 2
    return Plan("bench", segs), ledger


def bench_plan(repeats: int) -> dict[str, Any]:
    plan, ledger = _plan(PLAN_SEGMENTS)

    def one_by_one() -> np.ndarray[Any, Any]:
        start: Any = HOME
        out = []
        for seg in plan.segments:
            xyz = segment_path(start, seg, ledger)
            out.append(xyz)
            start = xyz[-1]
        return np.concatenate(out)

    path = plan_path(plan, ledger, HOME)
    assert np.allclose(path.xyz, one_by_one(), atol=1e-6), "plan_path and segment_path disagree"
    vectorised = _median_ms(lambda: plan_path(plan, ledger, HOME), repeats)
    baseline = _median_ms(one_by_one, repeats)
    return {
        "segments": PLAN_SEGMENTS,
        "samples": int(path.xyz.shape[0]),
        "plan_path_ms": vectorised,
        "segment_by_segment_ms": baseline,
        "ratio_plan_path_vs_one_by_one": round(vectorised / baseline, 3),
        "plan_geometry_ms": _median_ms(lambda: plan_geometry(plan, ledger, HOME), repeats),
        "check_plan_ms": _median_ms(lambda: check_plan(plan, ledger, current_pose=HOME), repeats),
        "estimate_plan_ms": _median_ms(lambda: estimate_plan(plan, ledger, HOME), repeats),
    }


def bench_preview(repeats: int) -> dict[str, Any]:
    try:
        from ui.panels.plan_preview import PlanPreview
    except ImportError as exc:
        return {"redraw_ms": None, "reason": f"ui/plan_preview.py is not usable: {exc}"}
    app = _qt_app()
    big_plan, big_ledger = _plan(PLAN_SEGMENTS)
    small_plan, small_ledger = _plan(10)
    # two versions of each path so that every redraw has new data to draw
    other_start = (500.0, 50.0, 450.0)
    big = [plan_path(big_plan, big_ledger, HOME), plan_path(big_plan, big_ledger, other_start)]
    small = [plan_path(small_plan, small_ledger, HOME), plan_path(small_plan, small_ledger, other_start)]
    preview = PlanPreview()
    preview.resize(1280, 360)
    try:
        viewports = [proj.plot.viewport() for proj in preview.projections.values()]
    except AttributeError as exc:
        return {"redraw_ms": None, "reason": f"PlanPreview has no plot viewports to watch: {exc}"}
    probes = [_PaintProbe(v) for v in viewports]
    preview.show()
    _wait_painted(app, probes, [0] * len(probes))

    def redraw(path: Any) -> float:
        since = [p.count for p in probes]
        t0 = time.perf_counter()
        preview.set_path(path)
        _wait_painted(app, probes, since)
        return time.perf_counter() - t0

    try:
        redraw(big[1])  # warm up
        big_ms = [_ms(redraw(big[i % 2])) for i in range(repeats)]
        small_ms = [_ms(redraw(small[i % 2])) for i in range(repeats)]
    finally:
        preview.close()
        preview.deleteLater()
        app.processEvents()
    redraw_big, redraw_small = statistics.median(big_ms), statistics.median(small_ms)
    return {
        "segments": PLAN_SEGMENTS,
        "redraw_ms": redraw_big,
        "redraw_10_segments_ms": redraw_small,
        "ratio_vs_10_segments": round(redraw_big / redraw_small, 2),
        "what": "PlanPreview.set_path (3 projections) until all three plots painted (offscreen)",
    }


def run(quick: bool) -> dict[str, Any]:
    repeats = 3 if quick else 5
    out: dict[str, Any] = {}
    with tempfile.TemporaryDirectory(prefix="teachpad-bench-") as tmp:
        path = Path(tmp) / "bench.teachpad.json"
        project = Project("bench", PointLedger(_points(PROJECT_POINTS)))
        t0 = time.perf_counter()
        save_project(project, path)
        save_s = time.perf_counter() - t0
        out["project_load"] = bench_load(path, 3 if quick else 9)  # 9 rounds: ~3 s
        out["project_load"]["save_project_ms"] = _ms(save_s)
        out["points_table_show"] = bench_show(load_project(path), repeats)
    if quick:
        out["restore_all"] = bench_restore(500, 200, rounds=5, sample_s=QUICK_SAMPLE_S)
    else:
        out["restore_all"] = bench_restore(PROJECT_POINTS, 1000)
    out["completion_profiles"] = completion.bench_profiles(60 if quick else 300)
    out["plan_geometry"] = bench_plan(repeats)
    out["plan_preview"] = bench_preview(repeats)
    out["autosave_large"] = bench_autosave(quick)
    return out
