"""The planner tab at 1280×800 and 1920×1080, in English and Chinese (issue 21, Layout).

In the window, with the sample project open: every projection on screen is at least 200 px a
side and whole; the segment table has room for six rows; no text is cut and no two widgets
overlap (``layout_audit``); the point labels of every projection are placed so that no two cover
each other on screen (at the sample's front view P2 and P3 fall on the same spot: "P2P3"); the
checks' words wrap at word boundaries (in English; Chinese may break between any characters); and
after a real stop at the simulator the run box shows *Resume from k* and how the run ended
without scrolling, and nothing in it moved.
"""

from __future__ import annotations

from collections.abc import Callable
from itertools import combinations
from pathlib import Path
from typing import Any

import pytest
from PySide6.QtCore import QPoint, QRect, QRectF
from PySide6.QtGui import QTextLayout, QTextOption
from PySide6.QtWidgets import QAbstractButton, QAbstractScrollArea, QLabel, QWidget

from app.plan.segments import Plan, Segment
from tests.ui.layout_audit import clipped_texts, overlapping_siblings
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    SIGNAL_TIMEOUT_MS,
    app_settings_fixture,
    fast_reconnect_fixture,
    link_fixture,
    project_dialogs_fixture,
    step_by_link,
    teach_here,
    translator_fixture,
)
from tests.ui.test_layout import (  # noqa: F401 - fixtures
    LANGUAGES,
    LAPTOP,
    SIZES,
    cjk_font_installed,
    make_window_fixture,
    problems,
    settle,
)
from ui.main_window import TAB_PLANNER, TAB_POINTS, MainWindow
from ui.panels.plan_projection import Projection
from ui.panels.planner_panel import PlannerPanel

pytestmark = [pytest.mark.timeout(120), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]

SAMPLE = Path(__file__).resolve().parents[2] / "resources" / "samples" / "demo.teachpad.json"
PREVIEW_MIN_SIDE = 200  # px, each projection on screen
MIN_SEGMENT_ROWS = 6
RUN_TIMEOUT_MS = 30_000


def open_planner(make_window: Callable[..., MainWindow], language: str, size: tuple[int, int]) -> MainWindow:
    window = make_window(language, size)
    assert window.project.open_file(SAMPLE)
    window.show_tab(TAB_PLANNER)
    settle()
    return window


def shown_projections(panel: PlannerPanel) -> list[Projection]:
    return [p for p in panel.preview.projections.values() if p.plot.isVisible()]


def each_view(panel: PlannerPanel) -> list[Projection]:
    """Every projection in turn, as the operator can bring it on screen (its tab on a narrow preview)."""
    seen: list[Projection] = []
    tabs = getattr(panel.preview, "view_tabs", None)
    for index in range(tabs.count() if tabs is not None and tabs.isVisible() else 1):
        if tabs is not None and tabs.isVisible():
            tabs.setCurrentIndex(index)
            settle()
        seen += [p for p in shown_projections(panel) if p not in seen]
    return seen


def label_boxes(projection: Projection) -> list[tuple[str, QRectF]]:
    """The shown point labels of ``projection`` and where they are on screen (scene pixels)."""
    boxes = []
    to_screen = projection.plot.viewportTransform()
    for label in projection.labels:
        if label.isVisible():  # where Qt paints it (its size in pixels, whatever the zoom)
            boxes.append((label.text(), label.deviceTransform(to_screen).mapRect(label.boundingRect())))
    return boxes


def whole(widget: QWidget) -> bool:
    """``widget`` lies wholly inside each of its ancestors (nothing of it is cut away or scrolled off)."""
    window = widget.window()
    rect = QRect(widget.mapTo(window, QPoint(0, 0)), widget.size())
    parent = widget.parentWidget()
    while parent is not None and parent is not window:
        if not QRect(parent.mapTo(window, QPoint(0, 0)), parent.size()).contains(rect):
            return False
        parent = parent.parentWidget()
    return window.rect().contains(rect)


@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
@pytest.mark.parametrize("language", LANGUAGES)
def test_the_planner_fits(
    make_window: Callable[..., MainWindow], language: str, size: tuple[int, int]
) -> None:
    window = open_planner(make_window, language, size)
    panel = window.planner_panel
    assert panel.current_plan() is not None and len(panel.current_plan() or []) == 3

    # the previews: usable, whole; all three side by side on a large screen
    shown = shown_projections(panel)
    assert shown
    for projection in shown:
        plot = projection.plot
        assert plot.width() >= PREVIEW_MIN_SIDE and plot.height() >= PREVIEW_MIN_SIDE, plot.size()
        assert whole(plot)
    if size[0] >= 1920:
        assert len(shown) == 3

    # the segment table: room for six rows under its header
    view = panel.segment_view
    rows = view.viewport().height() / view.verticalHeader().defaultSectionSize()
    assert rows >= MIN_SEGMENT_ROWS, rows
    assert whole(view)

    # the run box: every button whole, and nothing in the planner cut or overlapping
    for button in panel.run_box.findChildren(QAbstractButton):
        if button.isVisible():
            assert whole(button), button.text()
    found = problems(panel, language, touch=False)
    assert not found, "\n".join(found)

    # the point labels: none covers another, in every projection the operator can show
    for projection in each_view(panel):
        boxes = label_boxes(projection)
        assert boxes, "no label shown"
        for (first, a), (second, b) in combinations(boxes, 2):
            assert not a.intersects(b), f"{first} and {second} overlap: {a} {b}"
        # a label left out where labels would pile up is still on its point, on hover
        assert len(boxes) <= len(projection.labels)


def broken_words(label: QLabel) -> list[str]:
    """Lines of ``label`` (laid out at its width, as shown) that end inside a word."""
    layout = QTextLayout(label.text().replace("\n", "\u2028"), label.font())
    option = QTextOption()
    option.setWrapMode(QTextOption.WrapMode.WrapAtWordBoundaryOrAnywhere)  # as QLabel wraps
    layout.setTextOption(option)
    text = layout.text()
    broken = []
    layout.beginLayout()
    while True:
        line = layout.createLine()
        if not line.isValid():
            break
        line.setLineWidth(label.contentsRect().width())
        end = line.textStart() + line.textLength()
        inside = 0 < end < len(text) and not text[end - 1].isspace() and not text[end].isspace()
        if inside and text[end - 1] not in "\u2028—-":
            broken.append(text[line.textStart() : end])
    layout.endLayout()
    return broken


@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
@pytest.mark.parametrize("language", LANGUAGES)
def test_the_checks_read_whole(
    make_window: Callable[..., MainWindow], language: str, size: tuple[int, int]
) -> None:
    """A plan with an error and points to upload: the summary and the first error are whole,
    wrapped at word boundaries in English, and the table still has room for six rows."""
    window = open_planner(make_window, language, size)
    panel = window.planner_panel
    plans = window.project.plans_model
    row = plans.add_plan(
        Plan("checks", [Segment.line(1, 100.0), Segment.line(42, 100.0), Segment.arc(2, 3, 100.0)])
    )
    panel.select_plan(row)
    settle()
    summary = panel.summary
    assert "P42" in summary.text() or "42" in summary.text(), summary.text()
    assert summary.isVisible() and whole(summary)
    found = overlapping_siblings(panel)
    if language == "en" or cjk_font_installed():
        found += clipped_texts(panel)
    assert not found, "\n".join(found)
    if language == "en":
        assert not broken_words(summary), broken_words(summary)
    view = panel.segment_view
    assert view.viewport().height() / view.verticalHeader().defaultSectionSize() >= MIN_SEGMENT_ROWS


def geometries(panel: PlannerPanel) -> dict[str, QRect]:
    """Where the run box and each of its buttons are, in the planner's coordinates."""
    box = panel.run_box
    found = {"run box": QRect(box.mapTo(panel, box.rect().topLeft()), box.size())}
    for button in box.findChildren(QAbstractButton):
        if button is not panel.resume_from_button:
            found[button.text()] = QRect(button.mapTo(panel, button.rect().topLeft()), button.size())
    return found


@pytest.mark.parametrize("language", LANGUAGES)
def test_the_run_box_neither_scrolls_nor_moves_after_a_stop(
    qtbot: Any, sim: Any, make_window: Callable[..., MainWindow], language: str
) -> None:
    """A real run at the simulator, stopped by the operator in segment 2 of loop 1 of 2."""
    from ui.dialogs.stop_first import StopFirst

    window = make_window(language, LAPTOP)
    window.link_guard.ask = lambda _question: StopFirst.STOP  # the close after a stopped run asks
    window.show_tab(TAB_POINTS)
    for _ in range(2):  # P1, P2 taught 20 mm apart along X
        step_by_link(qtbot, window.link, 20.0)
        teach_here(qtbot, window.point_sync)
    row = window.project.plans_model.add_plan(
        Plan("slow", [Segment.line(1, 200.0), Segment.line(2, 4.0), Segment.line(1, 200.0)], loops=2)
    )
    window.show_tab(TAB_PLANNER)
    panel = window.planner_panel
    panel.select_plan(row)
    settle()
    before = geometries(panel)
    runs = window.run_controller
    with qtbot.waitSignal(
        runs.segmentPrepared, check_params_cb=lambda i, _ids: i == 1, timeout=RUN_TIMEOUT_MS
    ):
        assert panel.run(0)
    qtbot.waitUntil(lambda: sim.state().moving, timeout=SIGNAL_TIMEOUT_MS)
    with qtbot.waitSignal(runs.runFinished, timeout=RUN_TIMEOUT_MS):
        panel.stop()
    qtbot.waitUntil(lambda: not sim.state().moving, timeout=SIGNAL_TIMEOUT_MS)
    settle()

    assert panel.resume_from_button.isVisible() and whole(panel.resume_from_button)
    assert "2" in panel.resume_from_button.text()
    assert panel.run_label.text(), "the run box says how the run ended"
    scrolls = [
        area
        for area in panel.findChildren(QAbstractScrollArea)
        if area.isAncestorOf(panel.run_box) and area.verticalScrollBar().isVisible()
    ]
    assert not scrolls, "the run box scrolls"
    assert geometries(panel) == before, "the run box or a button in it moved"
    found = overlapping_siblings(panel.run_box)
    if language == "en" or cjk_font_installed():
        found += clipped_texts(panel.run_box)
    assert not found, "\n".join(found)
