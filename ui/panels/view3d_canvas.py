"""The 3D view's drawing surface: a QPainter projection of the scene (no OpenGL, so it draws
under the offscreen platform and in tests).

Everything is projected with one matrix product per layer (:class:`app.view3d.camera.Camera`)
and drawn with one ``drawPoints``/``drawLines`` call per colour from numpy buffers (pyqtgraph's
``PrimitiveArray``, no Python object per point). The camera-dependent static layers (grid,
points, path) are cached in a pixmap while the camera stands still, so a live pose only
redraws the arm; the points' names are a second cached layer drawn over the arm (a hovered or
selected point redraws only that layer); while the mouse drags, large scenes are thinned (level
of detail) and drawn in full again on release. The canvas keeps the screen positions it drew last in
:attr:`View3DCanvas.drawn` and the rectangles of the point names in
:attr:`View3DCanvas.label_rects` (tests and the benchmark read them).

The camera follows the scene until the operator moves it: while :attr:`View3DCanvas.auto_camera`
is on (at start, and again after *Fit all* or a preset), the view is re-fitted to the arm, the
points and the plan whenever the panel says the scene changed (a project opened, points added or
moved, the first pose after connecting), when the canvas is resized, and when the live arm would
leave the viewport. A drag (rotate, pan), a wheel zoom or *Fit plan* turns it off: from then on
only the operator's own actions move the camera. The wheel zooms about the cursor (the world
point under it stays under it); the TCP triad keeps :data:`TRIAD_PX` pixels whatever the zoom;
point names never overlap (:mod:`ui.panels.view3d_labels`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Final

import numpy as np
from numpy.typing import NDArray
from PySide6.QtCore import QEvent, QPointF, QRectF, Qt, Signal
from PySide6.QtGui import (
    QColor,
    QFont,
    QFontMetricsF,
    QMouseEvent,
    QPainter,
    QPaintEvent,
    QPixmap,
    QResizeEvent,
    QWheelEvent,
)
from PySide6.QtWidgets import QWidget

from app.safety.envelope import Envelope
from app.view3d.camera import Camera, grid_lines, nice_step, pick
from ui.palette import (
    COLOR_AXIS,
    COLOR_CURVE_BLUE,
    COLOR_CURVE_GREEN,
    COLOR_CURVE_RED,
    COLOR_ERROR,
    COLOR_GRID,
    COLOR_HIGHLIGHT,
    COLOR_INK,
    COLOR_INK_SOFT,
    COLOR_OK,
    COLOR_PATH,
    COLOR_START,
    COLOR_TRAIL,
    COLOR_WHITE,
)
from ui.panels.view3d_draw import Buffers, pen
from ui.panels.view3d_labels import place_labels

FloatArray = NDArray[np.float64]

ROTATE_DEG_PER_PX: Final = 0.4
ZOOM_PER_WHEEL_STEP: Final = 1.15  # one wheel notch (120)
CLICK_SLOP_PX: Final = 4
LOD_MAX_POINTS: Final = 2500  # markers drawn while dragging (thinned above this)
LOD_MAX_PATH_ROWS: Final = 4000  # path samples drawn while dragging
LOD_MAX_ARROWS: Final = 200  # direction arrows drawn while dragging (none for longer plans)
AA_MAX_PATH_ROWS: Final = 10_000  # longer paths are drawn without antialiasing
MAX_LABELS: Final = 40  # point names drawn when few points are visible (the hovered and selected: always)
LABEL_MIN_PX_PER_MM: Final = 0.6  # or when zoomed in this far
LABEL_FONT_PT: Final = 8
LABEL_BACKING: Final = QColor(255, 255, 255, 170)  # behind a name: readable over the arm and the path
GRID_EXTENT_MM: Final = 1500.0
GRID_STEP_MM: Final = 100.0
AXIS_MM: Final = 150.0  # base frame axes
TRIAD_PX: Final = 48.0  # TCP triad: each axis this long on screen when it lies across the view
MARKER_PX: Final = 7
ARROW_PX: Final = 9.0
COLOR_BACKGROUND: Final = "#f7f9fa"
AXIS_COLORS: Final = (COLOR_CURVE_RED, COLOR_CURVE_GREEN, COLOR_CURVE_BLUE)  # X Y Z
COLOR_ARM: Final = "#546e7a"
COLOR_GHOST_ARM: Final = "#8e24aa"  # the dry run's arm


class View3DCanvas(QWidget):
    """Draws the scene; the panel feeds it. Signals: ``pointClicked(int)`` (a point id, -1 for
    a click on nothing), ``cameraChanged()``."""

    pointClicked = Signal(int)
    cameraChanged = Signal()

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("View3DCanvas")
        self.setMinimumSize(200, 160)
        self.setFocusPolicy(Qt.FocusPolicy.ClickFocus)
        self.setMouseTracking(True)  # the hovered point's name shows
        self.camera = Camera()
        self.auto_camera = True  # the camera follows the scene until the operator moves it
        self._buf = Buffers()
        self._static: QPixmap | None = None
        self._labels: QPixmap | None = None  # the names, drawn over the arm
        self._point_depth = np.zeros(0)  # of the points drawn last (the names' priority)
        self._dragging = False
        self._press: QPointF | None = None
        self._last: QPointF | None = None
        self._moved = False
        self._button = Qt.MouseButton.NoButton
        self.drawn: dict[str, FloatArray] = {}
        self._grid = grid_lines(GRID_EXTENT_MM, GRID_STEP_MM)
        self.scale_text = ""
        # scene
        self.point_xyz = np.zeros((0, 3))
        self.point_ids = np.zeros(0, dtype=np.intp)
        self.point_names: list[str] = []
        self.point_colors: list[str] = []  # one colour per point
        self._color_codes = np.zeros(0, dtype=np.intp)  # index into _color_names per point
        self._color_names: list[str] = []
        self.point_bad = np.zeros(0, dtype=bool)
        self.selected_ids: set[int] = set()
        self.hovered_id: int | None = None
        self.plan_ids: set[int] = set()  # the plan's points: their names come before the others'
        self.label_rects: list[tuple[int, QRectF]] = []  # (point id, rectangle) of each name drawn
        self.path_xyz = np.zeros((0, 3))
        self.path_segment = np.zeros(0, dtype=np.intp)
        self.path_bad = np.zeros(0, dtype=bool)
        self.path_mids = np.zeros((0, 3))
        self.path_start: FloatArray | None = None
        self.active_segment: int | None = None
        self.arm: FloatArray | None = None  # (m, 3) polyline
        self.arm_joints: FloatArray | None = None
        self.flange: FloatArray | None = None  # 4x4
        self.ghost_arm: FloatArray | None = None
        self.ghost_flange: FloatArray | None = None
        self.trace = np.zeros((0, 3))
        self.badges: list[tuple[str, str]] = []  # (text, colour)
        self.keep_in_edges = np.zeros((0, 3))  # the safety envelope's boxes: point pairs (Box.edges)
        self.keep_out_edges = np.zeros((0, 3))

    # --- scene setters ---------------------------------------------------------------------
    def set_camera(self, camera: Camera) -> None:
        self.camera = camera
        self.invalidate()
        self.cameraChanged.emit()

    def invalidate(self) -> None:
        """The static layers must be drawn again."""
        self._static = None
        self.update()

    def invalidate_labels(self) -> None:
        """Only the points' names must be placed and drawn again (not the whole static layer)."""
        self._labels = None
        self.update()

    def set_points(
        self,
        xyz: FloatArray,
        ids: Sequence[int],
        names: Sequence[str],
        colors: Sequence[str],
        bad: NDArray[np.bool_],
    ) -> None:
        self.point_xyz = np.asarray(xyz, dtype=np.float64).reshape(-1, 3)
        self.point_ids = np.asarray(ids, dtype=np.intp)
        self.point_names = list(names)
        self.point_colors = list(colors)
        self._color_names = list(dict.fromkeys(self.point_colors))
        lookup = {c: i for i, c in enumerate(self._color_names)}
        self._color_codes = np.array([lookup[c] for c in self.point_colors], dtype=np.intp)
        self.point_bad = np.asarray(bad, dtype=bool)
        self.invalidate()

    def set_envelope(self, envelope: Envelope | None) -> None:
        """Draw the keep-in box (green) and the keep-out boxes (red) as wire frames."""
        self.keep_in_edges = envelope.keep_in.edges() if envelope and envelope.keep_in else np.zeros((0, 3))
        zones = [b.edges() for b in envelope.keep_out] if envelope else []
        self.keep_out_edges = np.vstack(zones) if zones else np.zeros((0, 3))
        self.invalidate()

    def set_selected(self, ids: set[int]) -> None:
        if ids != self.selected_ids:
            self.selected_ids = set(ids)
            self.invalidate_labels()  # the selected points' names always show

    def set_hovered(self, point_id: int | None) -> None:
        if point_id != self.hovered_id:
            self.hovered_id = point_id
            self.invalidate_labels()

    def set_plan_ids(self, ids: set[int]) -> None:
        """The points the plan uses (their names are written before the others')."""
        if ids != self.plan_ids:
            self.plan_ids = set(ids)
            self.invalidate_labels()

    def set_path(
        self,
        xyz: FloatArray,
        segment: NDArray[np.intp],
        bad: NDArray[np.bool_],
        mids: FloatArray,
        start: FloatArray | None,
    ) -> None:
        self.path_xyz = np.asarray(xyz, dtype=np.float64).reshape(-1, 3)
        self.path_segment = np.asarray(segment, dtype=np.intp)
        self.path_bad = np.asarray(bad, dtype=bool)
        self.path_mids = np.asarray(mids, dtype=np.float64).reshape(-1, 3)
        self.path_start = start
        self.invalidate()

    def set_active_segment(self, index: int | None) -> None:
        if index != self.active_segment:
            self.active_segment = index
            self.update()

    def set_arm(self, links: FloatArray | None, joints: FloatArray | None, flange: FloatArray | None) -> None:
        first = self.arm is None
        self.arm, self.arm_joints, self.flange = links, joints, flange
        if self.auto_camera and links is not None and (first or not self.shows(links)):
            self.auto_fit()
        self.update()

    def set_ghost_arm(self, links: FloatArray | None, flange: FloatArray | None) -> None:
        self.ghost_arm, self.ghost_flange = links, flange
        self.update()

    def set_trace(self, xyz: FloatArray) -> None:
        self.trace = xyz
        self.update()

    def set_badges(self, badges: list[tuple[str, str]]) -> None:
        if badges != self.badges:
            self.badges = badges
            self.invalidate_labels()  # the point names keep clear of the badges

    def scene_bounds(self) -> FloatArray:
        parts = [self.point_xyz, self.path_xyz, np.zeros((1, 3))]
        if self.arm is not None:
            parts.append(self.arm)
        return np.concatenate(parts, axis=0)

    def fit_all(self) -> None:
        """Frame the arm, the points and the plan; the camera follows the scene again."""
        self.auto_camera = True
        self.auto_fit()

    def auto_fit(self) -> None:
        """Re-fit to the scene, unless the operator has moved the camera (see the module
        docstring)."""
        if self.auto_camera:
            self.set_camera(self.camera.fitted(self.scene_bounds(), self.width() / max(1, self.height())))

    def fit_to(self, xyz: FloatArray) -> None:
        """Frame these points (*Fit plan*): the operator's choice, the camera stops following."""
        if len(xyz) and np.isfinite(xyz).all(axis=1).any():
            self.auto_camera = False
            self.set_camera(self.camera.fitted(xyz, self.width() / max(1, self.height())))

    def shows(self, xyz: FloatArray) -> bool:
        """Whether every finite point of ``xyz`` projects inside the canvas."""
        world = np.asarray(xyz, dtype=np.float64).reshape(-1, 3)
        pts = self.project(world[np.isfinite(world).all(axis=1)])  # NaN: behind the eye
        return bool(
            np.isfinite(pts).all()
            and (pts[:, 0] >= 0).all()
            and (pts[:, 0] <= self.width()).all()
            and (pts[:, 1] >= 0).all()
            and (pts[:, 1] <= self.height()).all()
        )

    def resizeEvent(self, event: QResizeEvent) -> None:
        super().resizeEvent(event)
        self.auto_fit()  # a new aspect: the scene is framed again (while the camera follows it)

    def project(self, xyz: FloatArray) -> FloatArray:
        pts = np.asarray(xyz, dtype=np.float64).reshape(-1, 3)
        return self.camera.project(pts, self.width(), self.height())[0]

    # --- painting --------------------------------------------------------------------------
    def paintEvent(self, event: QPaintEvent) -> None:
        painter = QPainter(self)
        self.render_scene(painter)
        painter.end()

    def render_scene(self, painter: QPainter) -> None:
        """Draw everything with ``painter`` (the widget's, or an image's in the benchmark)."""
        w, h = self.width(), self.height()
        if self._dragging:  # no names while dragging
            painter.fillRect(0, 0, w, h, QColor(COLOR_BACKGROUND))
            self._draw_static(painter, lod=True)
            self._draw_dynamic(painter)
            self._draw_overlay(painter)
            return
        ratio = self.devicePixelRatioF()
        if self._static is None or self._static.size() != self.size() * ratio:
            self._static = self._layer(
                ratio, QColor(COLOR_BACKGROUND), lambda p: self._draw_static(p, lod=False)
            )
            self._labels = None
        if self._labels is None:  # also alone: another point hovered or selected
            self._labels = self._layer(ratio, QColor(Qt.GlobalColor.transparent), self._draw_labels)
        painter.drawPixmap(0, 0, self._static)
        self._draw_dynamic(painter)
        painter.drawPixmap(0, 0, self._labels)  # the names over the arm: always readable
        self._draw_overlay(painter)  # the badges and the scale over everything

    def _layer(self, ratio: float, background: QColor, draw: Callable[[QPainter], None]) -> QPixmap:
        """A cached layer of the canvas's size, drawn once by ``draw``."""
        pix = QPixmap(self.size() * ratio)
        pix.setDevicePixelRatio(ratio)
        pix.fill(background)
        p = QPainter(pix)
        draw(p)
        p.end()
        return pix

    def _draw_static(self, painter: QPainter, *, lod: bool) -> None:
        painter.setRenderHint(QPainter.RenderHint.Antialiasing, False)
        self._draw_floor(painter)
        self._draw_envelope(painter)
        self._draw_path(painter, lod)
        self._draw_points(painter, lod)

    def _draw_floor(self, painter: QPainter) -> None:
        """The floor grid (and its scale's words) and the base frame's axes."""
        cam, w, h = self.camera, self.width(), self.height()
        g = cam.project(self._grid.reshape(-1, 3), w, h)[0].reshape(-1, 4)
        painter.setPen(pen(COLOR_GRID, 1))
        self._buf.draw_lines(painter, g)
        self.scale_text = self.tr("grid %1 mm").replace("%1", f"{GRID_STEP_MM:g}")
        axes = np.array([[0, 0, 0], [AXIS_MM, 0, 0], [0, AXIS_MM, 0], [0, 0, AXIS_MM]], dtype=np.float64)
        a = cam.project(axes, w, h)[0]
        for i, color in enumerate(AXIS_COLORS):
            painter.setPen(pen(color, 2))
            self._buf.draw_lines(painter, np.concatenate([a[0], a[i + 1]])[None, :])

    def _draw_envelope(self, painter: QPainter) -> None:
        """The safety envelope's boxes: keep-in green, keep-out red."""
        cam, w, h = self.camera, self.width(), self.height()
        for edges, color in ((self.keep_in_edges, COLOR_OK), (self.keep_out_edges, COLOR_ERROR)):
            if len(edges):
                painter.setPen(pen(color, 1.5))
                self._buf.draw_lines(painter, cam.project(edges, w, h)[0].reshape(-1, 4))

    def _draw_path(self, painter: QPainter, lod: bool) -> None:
        """The plan's path: lines, unreachable samples, middle points, start, direction."""
        cam, w, h = self.camera, self.width(), self.height()
        if not len(self.path_xyz):
            self.drawn["path"] = self.drawn["path_bad"] = self.drawn["mids"] = np.zeros((0, 2))
            return
        path = self.path_xyz
        step = max(1, len(path) // LOD_MAX_PATH_ROWS) if lod else 1
        sxy = cam.project(path[::step], w, h)[0]  # while dragging: every step-th row only
        # antialiased when drawn in full and not huge (tens of thousands of AA lines are slow)
        painter.setRenderHint(QPainter.RenderHint.Antialiasing, not lod and len(path) <= AA_MAX_PATH_ROWS)
        painter.setPen(pen(COLOR_PATH, 1 if lod else 2))
        self._buf.draw_polyline(painter, sxy)
        self._draw_arrows(painter, lod)
        self.drawn["path"] = sxy
        bad = sxy[self.path_bad] if step == 1 else cam.project(path[self.path_bad], w, h)[0]
        if len(bad):
            self._buf.draw_sprites(painter, bad, COLOR_ERROR, 6)
        self.drawn["path_bad"] = bad
        mids = cam.project(self.path_mids, w, h)[0]
        if not (lod and len(mids) > LOD_MAX_ARROWS):
            self._buf.draw_sprites(painter, mids, COLOR_PATH, 8, square=True)
        self.drawn["mids"] = mids
        self._draw_start(painter)

    def _draw_start(self, painter: QPainter) -> None:
        if self.path_start is None or not np.isfinite(self.path_start).all():
            return
        sx, sy = self.project(self.path_start)[0]
        if np.isfinite(sx):
            painter.setPen(pen(COLOR_START, 3))
            painter.setBrush(QColor(COLOR_START))
            painter.drawEllipse(QPointF(sx, sy), 6, 6)

    def _draw_points(self, painter: QPainter, lod: bool) -> None:
        """The points, one drawPixmapFragments per colour; while dragging only every k-th is
        projected and drawn (drawn["points"] then holds those, and picking projects again)."""
        cam, w, h = self.camera, self.width(), self.height()
        n = len(self.point_xyz)
        if not n:
            self.drawn["points"] = self.drawn["bad_points"] = np.zeros((0, 2))
            self.label_rects = []
            return
        k = n // LOD_MAX_POINTS + 1 if lod and n > LOD_MAX_POINTS else 1
        pts, depth = cam.project(self.point_xyz[::k], w, h)
        self.drawn["points"] = pts
        codes = self._color_codes[::k]
        for code, color in enumerate(self._color_names):
            self._buf.draw_sprites(painter, pts[codes == code], color, MARKER_PX)
        bad = pts[self.point_bad] if k == 1 else cam.project(self.point_xyz[self.point_bad], w, h)[0]
        if len(bad):
            self._buf.draw_sprites(painter, bad, COLOR_ERROR, MARKER_PX + 3)
        self.drawn["bad_points"] = bad
        self._point_depth = depth

    def _draw_arrows(self, painter: QPainter, lod: bool) -> None:
        """One arrowhead per segment at its middle sample, pointing along the path."""
        seg = self.path_segment
        if not len(seg) or (lod and seg[-1] >= LOD_MAX_ARROWS):
            return
        k = int(np.count_nonzero(seg == seg[0]))
        rows = np.arange(k // 2, len(seg) - 1, k)
        a = self.project(self.path_xyz[rows])
        b = self.project(self.path_xyz[rows + 1])
        d = b - a
        norm = np.hypot(d[:, 0], d[:, 1])
        ok = np.isfinite(norm) & (norm > 1e-9)
        u = d[ok] / norm[ok, None]
        tip = a[ok]
        left = tip - ARROW_PX * u + 0.5 * ARROW_PX * np.stack([-u[:, 1], u[:, 0]], axis=1)
        right = tip - ARROW_PX * u - 0.5 * ARROW_PX * np.stack([-u[:, 1], u[:, 0]], axis=1)
        painter.setPen(pen(COLOR_PATH, 2))
        self._buf.draw_lines(
            painter,
            np.concatenate([np.concatenate([tip, left], axis=1), np.concatenate([tip, right], axis=1)]),
        )

    def _label_order(self, pts: FloatArray, depth: FloatArray) -> tuple[list[int], int]:
        """Rows whose names may be written, most important first, and how many of the first
        must be: the hovered point, the selected ones, then (when few points show or the view
        is zoomed in) the plan's points and the others, nearest the eye first."""
        w, h = self.width(), self.height()
        ids = self.point_ids
        must_ids = ([self.hovered_id] if self.hovered_id is not None else []) + sorted(
            self.selected_ids - {self.hovered_id}
        )
        row_of = {int(pid): row for row, pid in enumerate(ids)}
        must = [row_of[pid] for pid in must_ids if pid in row_of]
        inside = np.flatnonzero(
            np.isfinite(pts).all(axis=1)
            & (pts[:, 0] >= 0)
            & (pts[:, 0] < w)
            & (pts[:, 1] >= 0)
            & (pts[:, 1] < h)
        )
        zoomed = self.camera.pixels_per_mm(h) >= LABEL_MIN_PX_PER_MM
        if len(inside) > MAX_LABELS and not zoomed:
            return must, len(must)
        in_plan = np.isin(ids[inside], list(self.plan_ids)) if self.plan_ids else np.zeros(len(inside), bool)
        ranked = inside[np.lexsort((depth[inside], ~in_plan))]  # the plan's first, then nearest first
        taken = set(must)
        rest = [int(r) for r in ranked[: MAX_LABELS * 2 + len(must)] if int(r) not in taken]
        return must + rest, len(must)

    def _draw_labels(self, painter: QPainter) -> None:
        """The points' names (after a full static layer: drawn["points"] holds every point), each
        on a light backing so that it reads over the arm and the path."""
        pts = self.drawn.get("points", np.zeros((0, 2)))
        if not len(pts) or len(pts) != len(self.point_ids):
            self.label_rects = []
            return
        order, must = self._label_order(pts, self._point_depth)
        font = QFont(self.font().family(), LABEL_FONT_PT)
        metrics = QFontMetricsF(font)
        sizes = np.zeros((len(pts), 2))
        for row in order:
            sizes[row] = (metrics.horizontalAdvance(self.point_names[row]) + 2.0, metrics.height())
        blocked = [(r.x(), r.y(), r.width(), r.height()) for r in [*self._badge_rects(), self._scale()[2]]]
        placed = place_labels(pts, sizes, order, (self.width(), self.height()), must, blocked)
        self.label_rects = [(int(self.point_ids[row]), QRectF(*rect)) for row, rect in placed]
        painter.setFont(font)
        for (_pid, rect), (row, _r) in zip(self.label_rects, placed, strict=True):
            must_show = row in order[:must]
            painter.fillRect(rect, LABEL_BACKING)
            painter.setPen(QColor(COLOR_INK if must_show else COLOR_INK_SOFT))
            painter.drawText(rect, Qt.AlignmentFlag.AlignCenter, self.point_names[row])

    def _draw_dynamic(self, painter: QPainter) -> None:
        painter.setRenderHint(QPainter.RenderHint.Antialiasing, True)
        cam, w, h = self.camera, self.width(), self.height()
        # the segment being run
        if self.active_segment is not None and len(self.path_xyz):
            rows = self.path_segment == self.active_segment
            painter.setPen(pen(COLOR_HIGHLIGHT, 5, round_cap=True))
            self._buf.draw_polyline(painter, cam.project(self.path_xyz[rows], w, h)[0])
        # selected points (projected here: a few, and right while dragging too)
        sel = np.isin(self.point_ids, list(self.selected_ids)) if self.selected_ids else None
        selected = cam.project(self.point_xyz[sel], w, h)[0] if sel is not None else np.zeros((0, 2))
        self.drawn["selected"] = selected
        painter.setPen(pen(COLOR_HIGHLIGHT, 2.5))
        painter.setBrush(Qt.BrushStyle.NoBrush)
        for x, y in selected[np.isfinite(selected).all(axis=1)][:200]:
            painter.drawEllipse(QPointF(x, y), 8, 8)
        # live TCP trace
        if len(self.trace) > 1:
            painter.setPen(pen(COLOR_TRAIL, 2))
            self._buf.draw_polyline(painter, cam.project(self.trace, w, h)[0])
        self._draw_arm(painter, self.arm, self.flange, COLOR_ARM, "flange")
        self._draw_arm(painter, self.ghost_arm, self.ghost_flange, COLOR_GHOST_ARM, "ghost_flange")

    def _draw_arm(
        self, painter: QPainter, links: FloatArray | None, flange: FloatArray | None, color: str, key: str
    ) -> None:
        cam, w, h = self.camera, self.width(), self.height()
        if links is None or flange is None:
            self.drawn.pop(key, None)
            return
        xy = cam.project(links, w, h)[0]
        painter.setPen(pen(color, 7, round_cap=True))
        self._buf.draw_polyline(painter, xy)
        painter.setPen(pen(COLOR_INK, 10, round_cap=True))
        self._buf.draw_points(painter, xy[:-1])
        # TCP triad at the flange: as long in mm as TRIAD_PX pixels at the flange's depth
        origin = flange[:3, 3]
        length = TRIAD_PX / cam.pixels_per_mm_at(origin, h)
        ends = origin[None, :] + flange[:3, :3].T * length
        tri = cam.project(np.vstack([origin, ends]), w, h)[0]
        for i, axis_color in enumerate(AXIS_COLORS):
            painter.setPen(pen(axis_color, 2.5))
            self._buf.draw_lines(painter, np.concatenate([tri[0], tri[i + 1]])[None, :])
        painter.setPen(pen(COLOR_HIGHLIGHT, 9, round_cap=True))
        self._buf.draw_points(painter, tri[:1])
        self.drawn[key] = tri[:1]
        self.drawn[f"{key}_triad"] = tri

    def _badge_font(self) -> QFont:
        font = QFont(self.font())
        font.setBold(True)
        return font

    def _badge_rects(self) -> list[QRectF]:
        """Where the badges go (top left, side by side)."""
        metrics = QFontMetricsF(self._badge_font())
        rects, x = [], 8.0
        for text, _color in self.badges:
            width = float(int(metrics.horizontalAdvance(text) + 12))
            rects.append(QRectF(x, 8, width, metrics.height() + 6))
            x += width + 6
        return rects

    def _scale(self) -> tuple[float, str, QRectF]:
        """The scale bar: its length in pixels, its words and the rectangle both take (bottom
        left): the grid step at the target's depth, rounded to a nice length."""
        ppm = self.camera.pixels_per_mm(self.height())
        length = nice_step(80.0 / max(ppm, 1e-9))
        bar = length * ppm
        text = f"{length:g} mm · {self.scale_text}"
        width = 16 + bar + QFontMetricsF(QFont(self.font().family(), LABEL_FONT_PT)).horizontalAdvance(text)
        return bar, text, QRectF(0, self.height() - 26, width + 4, 26)

    def _draw_overlay(self, painter: QPainter) -> None:
        """Badges (top left) and the grid's scale (bottom left)."""
        painter.setRenderHint(QPainter.RenderHint.Antialiasing, True)
        painter.setFont(self._badge_font())
        for (text, color), rect in zip(self.badges, self._badge_rects(), strict=True):
            painter.setPen(pen(color, 1.5))
            painter.setBrush(QColor(COLOR_WHITE))
            painter.drawRoundedRect(rect, 4, 4)
            painter.setPen(QColor(color))
            painter.drawText(rect, Qt.AlignmentFlag.AlignCenter, text)
        bar, text, _rect = self._scale()
        y = self.height() - 14
        painter.setPen(pen(COLOR_AXIS, 2))
        painter.drawLine(QPointF(10, y), QPointF(10 + bar, y))
        painter.drawLine(QPointF(10, y - 4), QPointF(10, y + 4))
        painter.drawLine(QPointF(10 + bar, y - 4), QPointF(10 + bar, y + 4))
        painter.setPen(QColor(COLOR_INK))
        painter.setFont(QFont(self.font().family(), LABEL_FONT_PT))
        painter.drawText(QPointF(16 + bar, y + 4), text)

    # --- mouse -----------------------------------------------------------------------------
    def mousePressEvent(self, event: QMouseEvent) -> None:
        self._press = self._last = event.position()
        self._moved = False
        self._button = event.button()

    def mouseMoveEvent(self, event: QMouseEvent) -> None:
        if self._last is None or self._press is None:
            self.hover_at(event.position().x(), event.position().y())
            return
        pos = event.position()
        if not self._moved and (pos - self._press).manhattanLength() < CLICK_SLOP_PX:
            return
        self._moved = self._dragging = True
        self.auto_camera = False  # the operator moves the camera: the scene no longer re-fits it
        dx, dy = pos.x() - self._last.x(), pos.y() - self._last.y()
        self._last = pos
        pan = self._button in (Qt.MouseButton.RightButton, Qt.MouseButton.MiddleButton) or bool(
            event.modifiers() & Qt.KeyboardModifier.ShiftModifier
        )
        if pan:
            self.set_camera(self.camera.panned(dx, dy, self.height()))
        else:
            self.set_camera(self.camera.orbited(-dx * ROTATE_DEG_PER_PX, dy * ROTATE_DEG_PER_PX))

    def mouseReleaseEvent(self, event: QMouseEvent) -> None:
        was_drag = self._moved
        self._press = self._last = None
        self._moved = False
        if self._dragging:
            self._dragging = False
            self.invalidate()
        if not was_drag and event.button() == Qt.MouseButton.LeftButton:
            self.click_at(event.position().x(), event.position().y())

    def click_at(self, x: float, y: float) -> int | None:
        """Pick the point under (x, y) and say so with ``pointClicked``."""
        pts = self.drawn.get("points")
        if pts is None or len(pts) != len(self.point_ids):
            pts = self.project(self.point_xyz) if len(self.point_xyz) else np.zeros((0, 2))
        row = pick(pts, (x, y))
        self.pointClicked.emit(-1 if row is None else int(self.point_ids[row]))
        return None if row is None else int(self.point_ids[row])

    def hover_at(self, x: float, y: float) -> int | None:
        """The point under (x, y) is hovered: its name shows."""
        pts = self.drawn.get("points")
        row = pick(pts, (x, y)) if pts is not None and len(pts) == len(self.point_ids) else None
        self.set_hovered(None if row is None else int(self.point_ids[row]))
        return self.hovered_id

    def leaveEvent(self, event: QEvent) -> None:
        super().leaveEvent(event)
        self.set_hovered(None)

    def wheelEvent(self, event: QWheelEvent) -> None:
        """Zoom about the cursor: the world point under it stays under it."""
        steps = event.angleDelta().y() / 120.0
        if steps:
            pos = event.position()
            self.zoom_at(ZOOM_PER_WHEEL_STEP**steps, pos.x(), pos.y())

    def zoom_at(self, factor: float, x: float, y: float) -> None:
        self.auto_camera = False
        self.set_camera(self.camera.zoomed_at(factor, x, y, self.width(), self.height()))

    def set_dragging(self, dragging: bool) -> None:
        """Level of detail on or off (the benchmark simulates a drag with it)."""
        self._dragging = dragging
        self.invalidate()
