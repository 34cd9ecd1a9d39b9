"""PlanPreview: the three projections, arcs through their middle point, selection, live TCP,
and a 1,000-segment plan drawn with one curve item per projection."""

from __future__ import annotations

import itertools
from typing import Any

import numpy as np
import pyqtgraph as pg
import pytest

from app.models import Pose
from app.plan.geometry import plan_path
from app.plan.segments import Plan, Segment
from app.points.ledger import PointLedger
from app.points.point import make_point
from ui.panels.plan_preview import PROJECTIONS, PlanPreview


@pytest.fixture
def ledger() -> PointLedger:
    return PointLedger(
        [
            make_point(1, "home", (400, 0, 450, 180, 0, 0)),
            make_point(5, "W", (300, 0, 300, 180, 0, 0)),
            make_point(6, "N", (400, 100, 320, 180, 0, 0)),
            make_point(7, "E", (500, 0, 300, 180, 0, 0)),
        ]
    )


@pytest.fixture
def preview(qtbot: Any) -> PlanPreview:
    widget = PlanPreview()
    qtbot.addWidget(widget)
    widget.resize(1000, 320)
    return widget


def curve_xy(item: pg.PlotCurveItem) -> tuple[np.ndarray, np.ndarray]:
    x, y = item.getData()
    return np.asarray(x, dtype=float), np.asarray(y, dtype=float)


def test_projections_and_items(preview: PlanPreview, ledger: PointLedger) -> None:
    plan = Plan("p", [Segment.line(5), Segment.arc(6, 7), Segment.line(1)])
    path = plan_path(plan, ledger, (400, 0, 450))
    preview.set_path(path)
    preview.set_points([(p.x, p.y, p.z) for p in ledger], [f"P{p.id}" for p in ledger])
    preview.set_start((400, 0, 450))
    assert list(preview.projections) == [key for key, _, _ in PROJECTIONS] == ["top", "front", "side"]
    for proj in preview.projections.values():
        x, y = curve_xy(proj.path)
        assert x.shape == (path.xyz.shape[0],)
        np.testing.assert_allclose(x, path.xyz[:, proj.h])
        np.testing.assert_allclose(y, path.xyz[:, proj.v])
        assert len(proj.labels) == 4
        assert proj.points.data.shape[0] == 4 and proj.start.data.shape[0] == 1
        items = proj.plot.getPlotItem().items
        assert proj.path in items and proj.selected in items and proj.tcp in items


def test_arc_passes_through_its_middle_point(preview: PlanPreview, ledger: PointLedger) -> None:
    plan = Plan("p", [Segment.line(5), Segment.arc(6, 7)])
    preview.set_path(plan_path(plan, ledger, (400, 0, 450)))
    middle = (400.0, 100.0, 320.0)
    for proj in preview.projections.values():
        x, y = curve_xy(proj.path)
        distance = np.hypot(x - middle[proj.h], y - middle[proj.v])
        assert np.nanmin(distance) < 1e-9
    # and it is a circle: every sample of the arc is at the same distance from its centre
    path = preview.path
    assert path is not None
    arc = path.xyz[path.segment == 1]
    s, m, e = arc[0], np.array(middle), arc[-1]
    from app.plan.geometry import arc_geometry

    geo = arc_geometry(s[None, :], m[None, :], e[None, :])
    radii = np.linalg.norm(arc - geo.centre[0], axis=1)
    np.testing.assert_allclose(radii, geo.radius[0], rtol=1e-9)


def test_selected_segment_is_highlighted(preview: PlanPreview, ledger: PointLedger) -> None:
    plan = Plan("p", [Segment.line(5), Segment.arc(6, 7), Segment.line(1)])
    path = plan_path(plan, ledger, (400, 0, 450))
    preview.set_path(path)
    preview.set_selected(1)
    x, _ = curve_xy(preview.projections["top"].selected)
    np.testing.assert_allclose(x, path.xyz[path.segment == 1][:, 0])
    preview.set_selected(None)
    assert curve_xy(preview.projections["top"].selected)[0].size == 0


def test_unknown_segments_leave_a_gap(preview: PlanPreview, ledger: PointLedger) -> None:
    plan = Plan("p", [Segment.line(99), Segment.line(5), Segment.line(7)])
    preview.set_path(plan_path(plan, ledger, (400, 0, 450)))
    x, _ = curve_xy(preview.projections["top"].path)
    assert np.isnan(x).any() and np.isfinite(x).any()


def test_thousand_segments_one_item_per_projection(preview: PlanPreview, ledger: PointLedger) -> None:
    segments = [Segment.arc(6, 7) if k % 3 == 1 else Segment.line((5, 1, 7)[k % 3]) for k in range(1000)]
    plan = Plan("big", segments)
    path = plan_path(plan, ledger, (400, 0, 450))
    for _ in range(2):  # redraw
        preview.set_path(path)
        preview.set_selected(500)
    for proj in preview.projections.values():
        curves = [item for item in proj.plot.getPlotItem().items if isinstance(item, pg.PlotCurveItem)]
        assert len(curves) == 3  # path, selection, live trail
        assert curve_xy(proj.path)[0].shape == (path.xyz.shape[0],)
    preview.grab()  # paints without error


def test_live_tcp(qtbot: Any, preview: PlanPreview) -> None:
    top = preview.projections["top"]
    preview.show()
    preview.on_pose(Pose(1.0, 2.0, 3.0, 0.0, 0.0, 0.0))  # not live: only remembered
    assert top.tcp.data.shape[0] == 0
    preview.start_live()  # draws the latest pose at once
    assert preview.live
    assert list(top.tcp.data["x"]) == [1.0] and list(top.tcp.data["y"]) == [2.0]
    for k in range(5):
        preview.on_pose(Pose(10.0 + k, 20.0, 30.0, 0.0, 0.0, 0.0))
    qtbot.waitUntil(lambda: list(top.tcp.data["x"]) == [14.0])
    preview.stop_live()
    assert not preview.live
    x, _ = curve_xy(top.trail)
    assert x.size >= 1 and x[-1] == 14.0
    side = preview.projections["side"]
    assert list(side.tcp.data["x"]) == [20.0] and list(side.tcp.data["y"]) == [30.0]
    preview.clear()
    assert top.tcp.data.shape[0] == 0


# --- fitting every change (issue 9) -----------------------------------------------------------------


def shows_all(preview: PlanPreview, xyz: list[tuple[float, float, float]]) -> bool:
    """Every projection's view range holds every point of ``xyz``."""
    for proj in preview.projections.values():
        (x0, x1), (y0, y1) = proj.plot.getViewBox().viewRange()
        for p in xyz:
            if not (x0 <= p[proj.h] <= x1 and y0 <= p[proj.v] <= y1):
                return False
    return True


def wheel(qtbot: Any, preview: PlanPreview, key: str = "top") -> None:
    """The operator zooms one projection with the mouse wheel (a real wheel event)."""
    from PySide6.QtCore import QPoint, QPointF, Qt
    from PySide6.QtGui import QWheelEvent
    from PySide6.QtWidgets import QApplication

    plot = preview.projections[key].plot
    centre = QPointF(plot.viewport().rect().center())
    event = QWheelEvent(
        centre,
        QPointF(plot.viewport().mapToGlobal(centre.toPoint())),
        QPoint(0, 0),
        QPoint(0, 240),
        Qt.MouseButton.NoButton,
        Qt.KeyboardModifier.NoModifier,
        Qt.ScrollPhase.NoScrollPhase,
        False,
    )
    QApplication.sendEvent(plot.viewport(), event)


def test_a_new_plan_shows_the_points_it_can_use(preview: PlanPreview, ledger: PointLedger) -> None:
    preview.show_plan(Plan("new"), ledger, None, None)
    top = preview.projections["top"]
    assert top.points.data.shape[0] == len(ledger) and len(top.labels) == len(ledger)
    assert shows_all(preview, [p.xyz for p in ledger])  # not an empty view fitted to nothing


def test_every_change_refits_until_the_operator_zooms(
    qtbot: Any, preview: PlanPreview, ledger: PointLedger
) -> None:
    preview.show()
    qtbot.waitExposed(preview)
    ledger.append(make_point(8, "far", (2400, -1800, 1200, 180, 0, 0)))
    plan = Plan("p", [Segment.line(5), Segment.line(7)])
    preview.show_plan(plan, ledger, (400, 0, 450), None)
    assert shows_all(preview, [(300, 0, 300), (500, 0, 300)]) and preview.follows_changes
    plan.append(Segment.line(8))  # a segment added far away: the same plan, refitted
    preview.show_plan(plan, ledger, (400, 0, 450), None)
    assert shows_all(preview, [(2400, -1800, 1200), (300, 0, 300)])
    plan.remove(2)
    preview.show_plan(plan, ledger, (400, 0, 450), None)
    assert not shows_all(preview, [(2400, -1800, 1200)])  # shrunk back to the plan

    wheel(qtbot, preview)  # the operator zooms: their view stays through the next changes
    assert not preview.follows_changes
    zoomed = preview.projections["top"].plot.getViewBox().viewRange()
    plan.append(Segment.line(8))
    preview.show_plan(plan, ledger, (400, 0, 450), None)
    assert preview.projections["top"].plot.getViewBox().viewRange() == zoomed
    preview.fit_button.click()  # Fit: everything again, and the view follows the changes again
    assert preview.follows_changes and shows_all(preview, [(2400, -1800, 1200), (300, 0, 300)])
    preview.show_plan(Plan("other", [Segment.line(1)]), ledger, None, None)  # another plan: fitted
    assert not shows_all(preview, [(2400, -1800, 1200)])


def test_the_envelopes_boxes_are_drawn_but_the_view_fits_the_plan(
    qtbot: Any, preview: PlanPreview, ledger: PointLedger
) -> None:
    """A fresh install's keep-in box is the robot's whole reach (2.8 m wide): drawn, but a 200 mm
    plan still fills the view (issue 18's defaults)."""
    from app.safety.profile import default_envelope
    from app.view3d.profile import default_profile

    preview.show()
    qtbot.waitExposed(preview)
    preview.set_envelope(default_envelope(default_profile()))
    preview.show_plan(Plan("p", [Segment.line(5), Segment.line(7)]), ledger, (400, 0, 450), None)
    top = preview.projections["top"]
    assert top.keep_in is not None and len(top.keep_in.getData()[0]) > 0  # the box is drawn
    (x0, x1), _ = top.plot.getViewBox().viewRange()
    assert shows_all(preview, [(300, 0, 300), (500, 0, 300)]) and x1 - x0 < 1000  # fitted to the plan


def label_gaps(axis: pg.AxisItem, span: tuple[float, float], width: int) -> list[float]:
    """The gaps (px) between the X axis' tick labels as pyqtgraph lays them out at ``width``."""
    from PySide6.QtGui import QImage, QPainter

    axis.setRange(*span)
    axis.resize(width, 40)
    image = QImage(width + 20, 60, QImage.Format.Format_ARGB32)
    painter = QPainter(image)
    try:
        specs = axis.generateDrawSpecs(painter)
    finally:
        painter.end()
    assert specs is not None
    rects = sorted((rect for rect, _flags, _text in specs[2]), key=lambda r: r.left())
    assert rects
    return [b.left() - a.right() for a, b in itertools.pairwise(rects)]


SPANS = [(-1625.0, 925.0), (-234.0, 1134.0), (180.0, 620.0), (-12.0, 8.0), (-2500.0, 2500.0)]


def test_x_axis_labels_never_touch_in_a_narrow_preview(preview: PlanPreview) -> None:
    from ui.panels.plan_projection import MIN_LABEL_SPACING_PX

    for proj in preview.projections.values():
        axis = proj.plot.getPlotItem().getAxis("bottom")
        for span in SPANS:
            for width in range(50, 400, 10):
                gaps = label_gaps(axis, span, width)
                assert all(gap >= 6 for gap in gaps), (span, width, gaps)
                if width >= 5 * MIN_LABEL_SPACING_PX:
                    assert gaps, (span, width)  # a wide axis still has several labels


def test_spaced_levels_widen_only_the_labelled_level() -> None:
    from ui.panels.plan_projection import spaced_levels, wider_interval

    wider = [wider_interval(v) for v in (1.0, 2.0, 5.0, 0.2, 50.0)]
    assert wider == pytest.approx([2.0, 5.0, 10.0, 0.5, 100.0])
    # 500 mm over 65 px: 200 mm is 26 px, too close; 500 mm (65 px) is not
    assert spaced_levels([(200.0, 0.0), (100.0, 0.0)], 500.0, 65.0)[0] == (500.0, 0.0)
    assert spaced_levels([(200.0, 0.0), (100.0, 0.0)], 500.0, 650.0) == [(200.0, 0.0), (100.0, 0.0)]
