"""How the planner's boxes share its room, at 1280×800 as at 1920×1080.

* The run strip (:class:`~ui.panels.planner_widgets.PlanRunBox`) spans the bottom at every size:
  Run and Stop are always in the same place and never scroll. Above it, as wide, the checks'
  words (errors, points to upload) with Upload now and Check: read whole, before a run.
* The plans list is a side pane on the left, shown when the panel is wide enough
  (:data:`PLANS_SHOWN_MIN_WIDTH`) and hidden on a narrow one; *Plans* (a toggle in the segments'
  row of buttons) shows or hides it, and from then on the operator's choice stays. The segments'
  title names the plan on display, so the list is not needed to know it.
* The work area holds the segment table and the preview: one above the other with the three
  projections side by side when it is wide (:data:`WIDE_WORK_MIN_WIDTH`), else side by side with
  the preview a column of one projection at a time (its tabs), at least
  :data:`~ui.panels.plan_preview.PLOT_MIN_SIDE` px a side.
"""

from __future__ import annotations

from PySide6.QtCore import QSize, Qt
from PySide6.QtGui import QAction, QResizeEvent
from PySide6.QtWidgets import QSplitter, QVBoxLayout, QWidget

PLANS_SHOWN_MIN_WIDTH = 900  # px of planner: narrower, the plans list starts hidden
WIDE_WORK_MIN_WIDTH = 860  # px of work area: wider, the segments sit above three projections
PLANS_WIDTH = 220  # px, the plans pane when shown
PREVIEW_COLUMN_WIDTH = 232  # px: the preview's share beside the segments in the narrow arrangement


class PlannerLayout(QWidget):
    """The plans pane | (segments and preview) over the checks and the run strip (see the module docstring).

    Public: ``plans_action`` (checkable: the plans list shown), ``outer`` and ``work`` (the
    splitters), :meth:`wide` (the segments above the preview)."""

    def __init__(
        self,
        plans_box: QWidget,
        segments_box: QWidget,
        preview_box: QWidget,
        checks_bar: QWidget,
        run_box: QWidget,
        plans_action: QAction,
        parent: QWidget | None = None,
    ) -> None:
        super().__init__(parent)
        self.setObjectName("PlannerLayout")
        self._plans_box = plans_box
        self._chosen = False  # the operator showed or hid the plans list: keep it so
        self.plans_action = plans_action
        self.plans_action.setChecked(True)
        self.plans_action.triggered.connect(self._on_plans_toggled)

        self.work = QSplitter(Qt.Orientation.Horizontal, self)
        self.work.setObjectName("PlannerWork")
        self.work.addWidget(segments_box)
        self.work.addWidget(preview_box)
        self.work.setChildrenCollapsible(False)
        self.work.setHandleWidth(4)
        work_area = QWidget(self)
        column = QVBoxLayout(work_area)
        column.setContentsMargins(0, 0, 0, 0)
        column.setSpacing(4)
        column.addWidget(self.work, 1)
        column.addWidget(checks_bar)
        column.addWidget(run_box)

        self.outer = QSplitter(Qt.Orientation.Horizontal, self)
        self.outer.setObjectName("PlannerSplitter")
        self.outer.addWidget(plans_box)
        self.outer.addWidget(work_area)
        self.outer.setStretchFactor(0, 0)
        self.outer.setStretchFactor(1, 1)
        self.outer.setChildrenCollapsible(False)
        self.outer.setHandleWidth(4)
        self.outer.setSizes([PLANS_WIDTH, 1000])
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.outer)
        self._wide: bool | None = None
        self.retranslate()

    def retranslate(self) -> None:
        self.plans_action.setText(self.tr("Plans"))
        self.plans_action.setToolTip(self.tr("Show or hide the list of plans"))

    @property
    def plans_shown(self) -> bool:
        return self.plans_action.isChecked()

    def set_plans_shown(self, shown: bool) -> None:
        """Show or hide the plans list (the operator's choice: it stays over resizes)."""
        self._chosen = True
        self._show_plans(shown)

    def _on_plans_toggled(self, checked: bool) -> None:
        self.set_plans_shown(checked)

    def _show_plans(self, shown: bool) -> None:
        self.plans_action.setChecked(shown)
        self._plans_box.setVisible(shown)
        self._arrange(self.width())

    def wide(self) -> bool:
        """The segments above the three projections (else side by side with one of them)."""
        return bool(self._wide)

    def minimumSizeHint(self) -> QSize:
        return self.outer.minimumSizeHint()

    def resizeEvent(self, event: QResizeEvent) -> None:
        if not self._chosen:
            shown = event.size().width() >= PLANS_SHOWN_MIN_WIDTH
            if shown != self.plans_action.isChecked() or shown != self._plans_box.isVisibleTo(self):
                self.plans_action.setChecked(shown)
                self._plans_box.setVisible(shown)
        self._arrange(event.size().width())
        super().resizeEvent(event)

    def _arrange(self, width: int) -> None:
        plans = PLANS_WIDTH + self.outer.handleWidth() if self.plans_shown else 0
        wide = width - plans >= WIDE_WORK_MIN_WIDTH
        if wide == self._wide:
            return
        self._wide = wide
        work = self.work
        if wide:
            work.setOrientation(Qt.Orientation.Vertical)
            work.setStretchFactor(0, 1)
            work.setStretchFactor(1, 1)
            work.setSizes([320, 300])
        else:
            work.setOrientation(Qt.Orientation.Horizontal)
            work.setStretchFactor(0, 1)
            work.setStretchFactor(1, 0)
            work.setSizes([max(width - plans - PREVIEW_COLUMN_WIDTH, 100), PREVIEW_COLUMN_WIDTH])
