"""Plan preview: the path in three projections — top (XY), front (XZ), side (YZ).

Each projection draws the whole plan with **one** ``PlotCurveItem`` whose data is the sampled
path of :func:`app.plan.geometry.plan_path` (NaN rows separate unknown segments; ``connect="finite"``),
so a plan of 1,000 segments is three ``setData`` calls, not 3,000 items. Arcs are the true
circles through start, middle and end (the core samples them with the middle point among the
samples). On top: the selected segment (thick), the referenced points (one scatter item,
labels for the first :data:`MAX_LABELS`), where the plan starts, and while a plan runs the
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
from PySide6.QtWidgets import QBoxLayout, QHBoxLayout, QLabel, QSizePolicy, QToolButton, QVBoxLayout, QWidget

from app.models import Pose
from app.plan.geometry import PlanPath, plan_path
from app.plan.presenter import PlanInfo
from app.plan.segments import Plan
from app.points.ledger import PointLedger
from app.safety.envelope import Envelope
from ui.joins import join_names
from ui.palette import COLOR_INK_SOFT
from ui.panels.plan_projection import FloatArray, Projection, style_plot
from ui.widgets.lines_label import LinesLabel

LIVE_FPS = 30
TRAIL_LENGTH = 600  # live TCP positions kept for the trail
INFO_WIDTH = 210  # px, the lengths / times column (at most)
INFO_MIN_WIDTH = 140  # px, on a narrow window
INFO_BELOW_WIDTH = 620  # px: a narrower preview shows the lengths / times below the plots

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
        self._slot.setMinimumSize(len(PROJECTIONS) * 90 + 12, 110 + QLabel().sizeHint().height())
        row.addWidget(self._slot, 1)
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
        layout = QBoxLayout(QBoxLayout.Direction.LeftToRight, self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addLayout(row, 1)
        layout.addLayout(side)
        self._layout = layout
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
            title.show()  # children made after their parent was shown are hidden until shown
            plot.show()
        self.retranslate()
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

    def resizeEvent(self, event: QResizeEvent) -> None:
        below = event.size().width() < INFO_BELOW_WIDTH
        direction = QBoxLayout.Direction.TopToBottom if below else QBoxLayout.Direction.LeftToRight
        if self._layout.direction() != direction:
            self._layout.setDirection(direction)
            self.info.setMaximumWidth(16777215 if below else INFO_WIDTH)
        super().resizeEvent(event)

    def retranslate(self) -> None:
        names = {
            "top": QCoreApplication.translate("PlanPreview", "Top (XY)"),
            "front": QCoreApplication.translate("PlanPreview", "Front (XZ)"),
            "side": QCoreApplication.translate("PlanPreview", "Side (YZ)"),
        }
        for key, title in self._titles.items():
            title.setText(names[key])
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
        """Points to mark (the plan's points), with labels (the first :data:`MAX_LABELS`)."""
        arr = np.asarray(xyz, dtype=np.float64).reshape(-1, 3)
        self._points = (arr, list(labels))
        for proj in self._projections.values():
            proj.points.setData(arr[:, proj.h], arr[:, proj.v])
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
        self.info.setText(text)

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
        lines = [
            self.tr("<b>{name}</b>: {n} segments, loops: {loops}").format(
                name=info.name, n=info.segments, loops=loops
            ),
            self.tr("One loop: {length}, {time}").format(length=info.loop_length, time=info.loop_time),
            self.tr("Total: {length}, {time}").format(length=info.total_length, time=info.total_time),
        ]
        if info.unknown:
            lines.append(
                self.tr("Not counted (unknown length): segments {list}").format(
                    list=join_names(str(k) for k in info.unknown)
                )
            )
        if info.selected is not None:
            k = info.selected
            lines.append(
                self.tr("Segment {k}: {length}, {time}").format(k=k.number, length=k.length, time=k.time)
            )
        lines.append(
            self.tr("Start: end of the last segment (robot pose unknown)")
            if info.assumed_start
            else self.tr("Start: the robot's current pose")
        )
        self.set_info("<br>".join(lines))

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
            proj.trail.setData(view[:, proj.h], view[:, proj.v])
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
