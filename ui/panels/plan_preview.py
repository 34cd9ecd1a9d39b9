"""Plan preview: the path in three projections — top (XY), front (XZ), side (YZ).

Each projection draws the whole plan with **one** ``PlotCurveItem`` whose data is the sampled
path of :func:`app.plan.geometry.plan_path` (NaN rows separate unknown segments; ``connect="finite"``),
so a plan of 1,000 segments is three ``setData`` calls, not 3,000 items. Arcs are the true
circles through start, middle and end (the core samples them with the middle point among the
samples). On top: the selected segment (thick), the referenced points (one scatter item,
labels for the first `MAX_LABELS` of plan_projection), where the plan starts, and while a plan runs the
live TCP (position and a short trail), repainted at most :data:`LIVE_FPS` times a second from
the latest pose (poses arrive at the poll rate). Outside a run, poses are only remembered.
The items of one projection are a :class:`ui.panels.plan_projection.Projection`.

The view fits every change (another plan, a segment added, removed or edited, a point moved)
until the operator zooms or pans a projection (pyqtgraph's ``sigRangeChangedManually``): from
then on the operator's view stays, until "Fit" (or another plan) fits again. A plan without
segments shows all the project's points (the ones it can use), fitted, not an empty view.

The plots are built on first show (or when ``projections`` is asked for): the planner is a hidden
tab at start, so the window's first paint does not wait for pyqtgraph. Until then the setters
only remember what to draw; the build draws it.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from PySide6.QtCore import QCoreApplication, QEvent, Qt, QTimer, Slot
from PySide6.QtGui import QResizeEvent
from PySide6.QtWidgets import (
    QBoxLayout,
    QHBoxLayout,
    QLabel,
    QSizePolicy,
    QTabBar,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from app.models import Pose
from app.plan.geometry import PlanPath, plan_path
from app.plan.presenter import PlanInfo
from app.plan.segments import Plan
from app.points.ledger import PointLedger
from app.safety.envelope import Envelope
from ui.joins import join_names
from ui.palette import COLOR_INK_SOFT
from ui.panels.plan_projection import PLOT_MIN_SIDE, FloatArray, Projection, style_plot
from ui.widgets.lines_label import LinesLabel

LIVE_FPS = 30
TRAIL_LENGTH = 600  # live TCP positions kept for the trail
INFO_WIDTH = 210  # px, the lengths / times column (at most)
INFO_MIN_WIDTH = 140  # px, on a narrow window
INFO_BELOW_WIDTH = 620  # px: a narrower preview shows the lengths / times below the plots
#: px: a narrower preview shows one projection at a time (its tabs), the lengths / times below it
COMPACT_BELOW_WIDTH = 3 * PLOT_MIN_SIDE + 2 * 6 + INFO_MIN_WIDTH + 6

#: (key, horizontal axis, vertical axis) — 0 = X, 1 = Y, 2 = Z.
PROJECTIONS: tuple[tuple[str, int, int], ...] = (("top", 0, 1), ("front", 0, 2), ("side", 1, 2))
AXIS_NAMES = ("X", "Y", "Z")


class PlanPreview(QWidget):
    """Top / front / side projections of a plan (see the module docstring).

    Public: :meth:`set_path`, :meth:`set_points`, :meth:`set_start`, :meth:`set_selected`,
    :meth:`start_live` / :meth:`stop_live` / :meth:`on_pose` (live TCP), :meth:`clear`;
    ``projections`` (key -> items) for tests.
    """

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("PlanPreview")
        self._path: PlanPath | None = None
        self._selected: int | None = None
        self._previewed: Plan | None = None  # the plan the view range was fitted to
        self._operator_view = False  # the operator zoomed / panned since the last fit
        self._pending: Pose | None = None
        self._live_wanted = False
        self._trail = np.full((2 * TRAIL_LENGTH, 3), np.nan)
        self._trail_count = 0
        self._last_tcp: Pose | None = None
        self._live_timer = QTimer(self)
        self._live_timer.setInterval(int(1000 / LIVE_FPS))
        self._live_timer.timeout.connect(self._paint_live)

        row = QHBoxLayout()
        row.setContentsMargins(0, 0, 0, 0)
        row.setSpacing(6)
        self._row = row
        self._projections: dict[str, Projection] = {}  # empty until built (setters only remember)
        self._titles: dict[str, QLabel] = {}
        self._points: tuple[FloatArray, list[str]] = (np.empty((0, 3)), [])
        self._start: tuple[float, float, float] | None = None
        # Until the plots exist, a placeholder asks for the room they will (layouts stay the same).
        self._boxes: tuple[FloatArray, FloatArray] = (np.empty((0, 3)), np.empty((0, 3)))  # envelope
        self._slot: QWidget | None = QWidget(self)
        self._slot.setMinimumSize(PLOT_MIN_SIDE, PLOT_MIN_SIDE + QLabel().sizeHint().height())
        row.addWidget(self._slot, 1)
        self._compact = True
        # all the lines of the lengths / times, and the ones beside one projection (as many as fit)
        self._info: tuple[str, list[str]] = ("", [])
        self.view_tabs = QTabBar(self)  # one projection at a time on a narrow preview
        self.view_tabs.setObjectName("PlanPreviewTabs")
        self.view_tabs.setDrawBase(False)
        self.view_tabs.setUsesScrollButtons(False)
        self.view_tabs.setElideMode(Qt.TextElideMode.ElideNone)
        for _key, _h, _v in PROJECTIONS:
            self.view_tabs.addTab("")
        self.view_tabs.currentChanged.connect(self._show_current)
        self.info = QLabel(self)
        self.info.setWordWrap(True)
        self.info.setStyleSheet(f"color: {COLOR_INK_SOFT};")
        self.info.setAlignment(Qt.AlignmentFlag.AlignLeft | Qt.AlignmentFlag.AlignTop)
        self.info.setMinimumWidth(INFO_MIN_WIDTH)
        self.info.setMaximumWidth(INFO_WIDTH)
        self.info.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        self.fit_button = QToolButton(self)
        self.fit_button.setObjectName("PlanPreviewFit")
        self.fit_button.clicked.connect(self.fit)
        # the robot model whose reach the checks use, beside Fit (elided, whole in the tooltip)
        self.reach_label = LinesLabel(1, self)
        self.reach_label.setObjectName("PlanPreviewReachModel")
        self.reach_label.setStyleSheet(f"color: {COLOR_INK_SOFT};")
        self.reach_label.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Fixed)
        self.reach_label.hide()  # until the window gives the reach check
        self._reach_model = ""
        fit_row = QHBoxLayout()
        fit_row.setContentsMargins(0, 0, 0, 0)
        fit_row.addWidget(self.fit_button)
        fit_row.addWidget(self.reach_label, 1, Qt.AlignmentFlag.AlignVCenter)
        side = QVBoxLayout()
        side.setContentsMargins(0, 0, 0, 0)
        side.addWidget(self.info, 1)
        side.addLayout(fit_row)
        # The lengths / times sit right of the plots, or below them on a narrow panel.
        layout = QBoxLayout(QBoxLayout.Direction.TopToBottom)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addLayout(row, 1)
        layout.addLayout(side)
        self._layout = layout
        self._side = side
        self._fit_row = fit_row
        self._header = QHBoxLayout()  # the tabs and Fit on a narrow preview
        self._header.setContentsMargins(0, 0, 0, 0)
        self._header.addWidget(self.view_tabs, 1, Qt.AlignmentFlag.AlignBottom)
        outer = QVBoxLayout(self)
        outer.setContentsMargins(0, 0, 0, 0)
        outer.setSpacing(2)
        outer.addLayout(self._header)
        outer.addLayout(layout, 1)
        self._show_current()
        self.retranslate()

    @property
    def projections(self) -> dict[str, Projection]:
        """Key -> the projection's plot items (built now if they were not yet)."""
        self._build_plots()
        return self._projections

    @property
    def plots_built(self) -> bool:
        return bool(self._projections)

    def _build_plots(self) -> None:
        if self._projections:
            return
        import pyqtgraph as pg  # deferred: see the module docstring

        if self._slot is not None:
            self._row.removeWidget(self._slot)
            self._slot.hide()  # at once: deleteLater waits for the event loop
            self._slot.deleteLater()
            self._slot = None
        for key, h, v in PROJECTIONS:
            plot = pg.PlotWidget(self)
            style_plot(plot)
            plot.setLabel("bottom", f"{AXIS_NAMES[h]} (mm)")
            plot.setLabel("left", f"{AXIS_NAMES[v]} (mm)")
            self._projections[key] = Projection(plot, h, v)
            plot.getViewBox().sigRangeChangedManually.connect(self._on_operator_view)
            title = QLabel(self)
            title.setStyleSheet(f"font-weight: bold; color: {COLOR_INK_SOFT};")
            self._titles[key] = title
            cell = QVBoxLayout()
            cell.setSpacing(0)
            cell.addWidget(title)
            cell.addWidget(plot, 1)
            self._row.addLayout(cell, 1)
        self.retranslate()
        self._show_current()
        # draw what the setters remembered
        for proj in self._projections.values():
            proj.set_boxes(*self._boxes)
        operator_view = self._operator_view
        self.set_path(self._path, keep_view=True)
        self.set_points(*self._points)
        self.set_start(self._start)
        self._paint_trail()
        self._auto_range()
        self._operator_view = operator_view

    @property
    def compact(self) -> bool:
        """One projection at a time (the tabs choose it), the lengths / times below it."""
        return self._compact

    def shown_projections(self) -> list[Projection]:
        """The projections on screen: all three, or the current tab's on a narrow preview."""
        return [p for p in self._projections.values() if p.plot.isVisibleTo(self)]

    def resizeEvent(self, event: QResizeEvent) -> None:
        width = event.size().width()
        compact = width < COMPACT_BELOW_WIDTH
        below = compact or width < INFO_BELOW_WIDTH
        direction = QBoxLayout.Direction.TopToBottom if below else QBoxLayout.Direction.LeftToRight
        if self._layout.direction() != direction:
            self._layout.setDirection(direction)
            self.info.setMaximumWidth(16777215 if below else INFO_WIDTH)
        if compact != self._compact:
            self._compact = compact
            self._show_current()
        super().resizeEvent(event)
        if compact:
            self._show_info()  # as many lines as fit the new height

    @Slot()
    def _show_current(self, *_args: Any) -> None:
        """All three projections with their titles, or the current tab's alone."""
        compact = self._compact
        self.view_tabs.setVisible(compact)
        # Fit beside the tabs on a narrow preview, else under the lengths / times
        self._fit_row.removeWidget(self.fit_button)
        self._header.removeWidget(self.fit_button)
        if compact:
            self._header.addWidget(self.fit_button, 0, Qt.AlignmentFlag.AlignBottom)
        else:
            self._fit_row.insertWidget(0, self.fit_button)
        self._show_info()
        current = self.view_tabs.currentIndex()
        for i, (key, _h, _v) in enumerate(PROJECTIONS):
            proj, title = self._projections.get(key), self._titles.get(key)
            if proj is None or title is None:
                continue
            proj.plot.setVisible(not compact or i == current)
            title.setVisible(not compact)

    def retranslate(self) -> None:
        names = {
            "top": QCoreApplication.translate("PlanPreview", "Top (XY)"),
            "front": QCoreApplication.translate("PlanPreview", "Front (XZ)"),
            "side": QCoreApplication.translate("PlanPreview", "Side (YZ)"),
        }
        for key, title in self._titles.items():
            title.setText(names[key])
        tabs = {
            "top": QCoreApplication.translate("PlanPreview", "Top"),
            "front": QCoreApplication.translate("PlanPreview", "Front"),
            "side": QCoreApplication.translate("PlanPreview", "Side"),
        }
        for i, (key, _h, _v) in enumerate(PROJECTIONS):
            self.view_tabs.setTabText(i, tabs[key])
            self.view_tabs.setTabToolTip(i, names[key])
        self.fit_button.setText(QCoreApplication.translate("PlanPreview", "Fit"))
        self.set_reach_model(self._reach_model)
        self.fit_button.setToolTip(
            QCoreApplication.translate(
                "PlanPreview",
                "Fit the views to the plan; they follow every change again until you zoom or pan",
            )
        )

    def changeEvent(self, event: QEvent) -> None:
        if event.type() == QEvent.Type.LanguageChange:
            self.retranslate()
        super().changeEvent(event)

    # --- the plan
    @property
    def path(self) -> PlanPath | None:
        return self._path

    def set_path(self, path: PlanPath | None, *, keep_view: bool = False) -> None:
        """The plan's sampled path (None: nothing to draw). ``keep_view``: leave the view
        range alone (the caller fits after drawing the points too)."""
        self._path = path
        for proj in self._projections.values():
            if path is None or path.xyz.shape[0] == 0:
                proj.path.setData([], [])
            else:
                proj.path.setData(path.xyz[:, proj.h], path.xyz[:, proj.v], connect="finite")
        self._draw_selected()
        if not keep_view:
            self._auto_range()

    def set_points(self, xyz: FloatArray | Sequence[Sequence[float]], labels: Sequence[str] = ()) -> None:
        """Points to mark (the plan's points), with labels (plan_projection.MAX_LABELS at most)."""
        arr = np.asarray(xyz, dtype=np.float64).reshape(-1, 3)
        self._points = (arr, list(labels))
        names = [*labels[: len(arr)], *[""] * (len(arr) - len(labels))]  # each point's hover tip
        for proj in self._projections.values():
            proj.points.setData(arr[:, proj.h], arr[:, proj.v], data=names)
            proj.set_labels(arr, list(labels))

    def set_start(self, xyz: Sequence[float] | FloatArray | None) -> None:
        """Where the plan starts (the robot's pose, or an assumed start)."""
        self._start = None if xyz is None else (float(xyz[0]), float(xyz[1]), float(xyz[2]))
        for proj in self._projections.values():
            if xyz is None:
                proj.start.setData([], [])
            else:
                proj.start.setData([float(xyz[proj.h])], [float(xyz[proj.v])])

    def set_selected(self, index: int | None) -> None:
        self._selected = index
        self._draw_selected()

    @property
    def selected(self) -> int | None:
        return self._selected

    def set_reach_model(self, name: str) -> None:
        """Name the robot model whose reach the plan's checks use ("": none, hidden)."""
        self._reach_model = name
        if name:
            text = QCoreApplication.translate("PlanPreview", "Reach: robot model \u201c%1\u201d")
            self.reach_label.setText(text.replace("%1", name))
        self.reach_label.setVisible(bool(name))

    def set_info(self, text: str) -> None:
        self._info = (text, [text] if text else [])
        self._show_info()

    def _show_info(self) -> None:
        """All the lines; beside one projection, the first lines that fit under it (whole lines:
        nothing is cut mid-word), the rest in the tooltip."""
        whole, lines = self._info
        shown = whole
        if self._compact:
            room = self._info_room()
            shown = ""
            for n in range(len(lines), 0, -1):
                candidate = "<br>".join(lines[:n])
                self.info.setText(candidate)
                if self.info.heightForWidth(max(self.info.width(), PLOT_MIN_SIDE)) <= room:
                    shown = candidate
                    break
        self.info.setText(shown)
        self.info.setToolTip(whole if shown != whole else "")
        self.info.setVisible(bool(shown))  # an empty label would still take a line's height

    def _info_room(self) -> int:
        """Height left for the lengths / times under one projection of :data:`PLOT_MIN_SIDE` px."""
        spacing = self._layout.spacing() + self._side.spacing() + 2
        reach = self.reach_label.height() + self._side.spacing() if self.reach_label.isVisibleTo(self) else 0
        return self.height() - self._header.sizeHint().height() - 2 - PLOT_MIN_SIDE - spacing - reach

    def show_plan(
        self, plan: Plan, ledger: PointLedger, start: Sequence[float] | None, selected: int | None
    ) -> None:
        """Draw ``plan`` from ``start`` with the points it uses (all the points while it has no
        segments); the view fits another plan always, a change of the same plan unless the
        operator zoomed or panned since the last fit."""
        another = plan is not self._previewed
        self._previewed = plan
        self.set_path(plan_path(plan, ledger, start), keep_view=True)
        if len(plan):
            used = [ledger.get(pid) for pid in sorted(plan.point_ids())]
            present = [p for p in used if p is not None]
        else:
            present = list(ledger)  # what a new plan can use
        self.set_points(
            np.array([p.xyz for p in present], dtype=np.float64).reshape(-1, 3), [f"P{p.id}" for p in present]
        )
        self.set_start(start)
        self.set_selected(selected)
        if another or not self._operator_view:
            self.fit()

    @property
    def follows_changes(self) -> bool:
        """The view fits every change (the operator has not zoomed or panned since the last fit)."""
        return not self._operator_view

    @Slot()
    def fit(self) -> None:
        """Fit every projection to what it shows; the view follows the changes again."""
        self._operator_view = False
        self._auto_range()

    @Slot()
    def _on_operator_view(self, *_args: Any) -> None:
        self._operator_view = True

    def show_info(self, info: PlanInfo) -> None:
        """The plan's lengths and times (worked out by :func:`app.plan.presenter.plan_info`)."""
        loops = self.tr("endless") if info.loops == 0 else str(info.loops)
        name = self.tr("<b>{name}</b>: {n} segments, loops: {loops}").format(
            name=info.name, n=info.segments, loops=loops
        )
        totals = [
            self.tr("One loop: {length}, {time}").format(length=info.loop_length, time=info.loop_time),
            self.tr("Total: {length}, {time}").format(length=info.total_length, time=info.total_time),
        ]
        if info.unknown:
            totals.append(
                self.tr("Not counted (unknown length): segments {list}").format(
                    list=join_names(str(k) for k in info.unknown)
                )
            )
        selected: list[str] = []
        if info.selected is not None:
            k = info.selected
            selected.append(
                self.tr("Segment {k}: {length}, {time}").format(k=k.number, length=k.length, time=k.time)
            )
        start = (
            self.tr("Start: end of the last segment (robot pose unknown)")
            if info.assumed_start
            else self.tr("Start: the robot's current pose")
        )
        # beside one projection the plan's name (the segments' title) and the selected segment's
        # length and time (its row) are left to the tooltip: the totals and the start stay
        self._info = ("<br>".join([name, *totals, *selected, start]), [*totals, start])
        self._show_info()

    def set_envelope(self, envelope: Envelope | None) -> None:
        """Outline the keep-in box and the keep-out boxes in every projection (None: none)."""
        keep_in = envelope.keep_in.edges() if envelope is not None and envelope.keep_in else np.empty((0, 3))
        zones = [b.edges() for b in envelope.keep_out] if envelope is not None else []
        keep_out = np.vstack(zones) if zones else np.empty((0, 3))
        self._boxes = (keep_in, keep_out)
        if self.plots_built:  # else drawn when the plots are built (first show)
            for proj in self._projections.values():
                proj.set_boxes(keep_in, keep_out)

    def clear(self) -> None:
        self._previewed = None
        self.set_path(None)
        self.set_points(np.empty((0, 3)))
        self.set_start(None)
        self.clear_live()

    def _draw_selected(self) -> None:
        path, index = self._path, self._selected
        rows: FloatArray | None = None
        if path is not None and index is not None:
            hit = np.flatnonzero(path.segment == index)
            if hit.size:
                rows = path.xyz[hit[0] : hit[-1] + 1]
        for proj in self._projections.values():
            if rows is None:
                proj.selected.setData([], [])
            else:
                proj.selected.setData(rows[:, proj.h], rows[:, proj.v], connect="finite")

    def _auto_range(self) -> None:
        for proj in self._projections.values():
            proj.plot.getPlotItem().enableAutoRange()
            proj.plot.getPlotItem().autoRange()

    # --- live TCP
    @property
    def live(self) -> bool:
        return self._live_wanted

    def start_live(self) -> None:
        """Draw the TCP from :meth:`on_pose` (throttled) until :meth:`stop_live`."""
        self._trail[:] = np.nan
        self._trail_count = 0
        for proj in self._projections.values():
            proj.trail.setData([], [])  # a new trail (the last run's is gone)
        self._live_wanted = True
        self._paint_live()
        if self.isVisible() and not self._live_timer.isActive():
            self._live_timer.start()

    def stop_live(self) -> None:
        """Stop repainting; the last TCP position and trail stay visible."""
        self._live_wanted = False
        self._live_timer.stop()
        self._paint_live()

    def clear_live(self) -> None:
        self._live_wanted = False
        self._live_timer.stop()
        self._pending = None
        self._trail[:] = np.nan
        self._trail_count = 0
        self._last_tcp = None
        for proj in self._projections.values():
            proj.tcp.setData([], [])
            proj.trail.setData([], [])

    @Slot(object)
    def on_pose(self, pose: Pose) -> None:
        """Latest TCP pose: drawn on the next live frame (kept for later when not live)."""
        self._pending = pose

    def _paint_live(self) -> None:
        pose, self._pending = self._pending, None
        if pose is None:
            return
        # ring buffer written twice so that the last TRAIL_LENGTH rows are one contiguous view
        k = self._trail_count % TRAIL_LENGTH
        xyz = (pose.x, pose.y, pose.z)
        self._trail[k] = xyz
        self._trail[k + TRAIL_LENGTH] = xyz
        self._trail_count += 1
        self._last_tcp = pose
        self._paint_trail()

    def _paint_trail(self) -> None:
        if not self._trail_count or not self._projections:
            return
        k = (self._trail_count - 1) % TRAIL_LENGTH
        n = min(self._trail_count, TRAIL_LENGTH)
        end = k + 1 + TRAIL_LENGTH if self._trail_count > TRAIL_LENGTH else k + 1
        view = self._trail[end - n : end]
        for proj in self._projections.values():
            # copies: pyqtgraph keeps the arrays it is given, and the ring buffer is written
            # again (and refilled with NaN by a new run): a curve whose data turned all NaN
            # under it raised in its paint (pyqtgraph 0.14 arrayToLineSegments)
            proj.trail.setData(view[:, proj.h].copy(), view[:, proj.v].copy())
        if self._last_tcp is not None:
            self._paint_tcp(self._last_tcp)

    def _paint_tcp(self, pose: Pose) -> None:
        xyz = (pose.x, pose.y, pose.z)
        for proj in self._projections.values():
            proj.tcp.setData([xyz[proj.h]], [xyz[proj.v]])

    def hideEvent(self, event: Any) -> None:
        self._live_timer.stop()  # nothing to paint while hidden; showEvent resumes
        super().hideEvent(event)

    def showEvent(self, event: Any) -> None:
        self._build_plots()
        super().showEvent(event)
        if self._live_wanted and not self._live_timer.isActive():
            self._live_timer.start()
