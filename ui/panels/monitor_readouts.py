"""The monitor's big readouts: the TCP box (X Y Z A B C) and the joints / external axes box,
and the font sizes that follow the panel's width.

Every readout keeps room for a value of four integer digits, a sign and three decimals (the
external axes reach -1000.000), measured in the font in use. The sizes follow the panel's width
(:func:`readout_point_sizes`: readable from a distance on a wide panel), and are then lowered
until every readout of a row gets that room in the width it has (:meth:`ReadoutBoxes.fit_width`):
a narrow window gets smaller numbers, and a value that still does not fit shows ``######``, never
a cut number. When six small readouts no longer fit in a row at :data:`SMALL_POINTS_MIN`, the
joints and external axes go into three columns (two rows each): on a resize, never while values
stream."""

from __future__ import annotations

from PySide6.QtWidgets import QGridLayout, QGroupBox, QWidget

from ui.panels.monitor_figures import CARTESIAN
from ui.widgets_common import NumericReadout

__all__ = ["BIG_POINTS_MAX", "MIN_WIDTH", "ReadoutBoxes", "readout_point_sizes", "readout_scale"]

BIG_POINTS = 22.0  # readout sizes at REFERENCE_WIDTH; they follow the panel's width
SMALL_POINTS = 13.0
BIG_POINTS_MAX = 34.0
SMALL_POINTS_MAX = 18.0
REFERENCE_WIDTH = 760  # px of panel width at which the readouts use BIG_POINTS / SMALL_POINTS
MIN_SCALE = 0.55  # readouts shrink down to this on a narrow panel (then the panel's minimum width)
MIN_WIDTH = 420  # px: the panel's minimum width (the readouts' fonts shrink to fit)
BIG_POINTS_MIN = 7.0  # the big readouts shrink to this in a narrow panel
SMALL_POINTS_MIN = 7.0  # the small ones to this, then they take three columns
POINTS_STEP = 0.5
PANEL_MARGIN = 6  # px: the monitor panel's layout margin on each side (monitor_panel.py)
INTEGER_DIGITS = 4  # room for -9999.999 (the external axes go to +-1000)
SMALL_COLUMNS = (6, 3)  # joints and external axes per row: wide, then narrow panels


def readout_scale(width: int) -> float:
    """Readout size factor for a panel ``width`` px wide (1.0 at REFERENCE_WIDTH)."""
    return min(max((width - 40) / (REFERENCE_WIDTH - 40), MIN_SCALE), BIG_POINTS_MAX / BIG_POINTS)


def readout_point_sizes(width: int) -> tuple[float, float]:
    """(big, small) point sizes wanted for a panel ``width`` px wide: readable from a distance
    at 1920 px (:meth:`ReadoutBoxes.fit_width` lowers them until the values fit)."""
    scale = readout_scale(width)
    return round(BIG_POINTS * scale, 1), round(min(SMALL_POINTS * scale, SMALL_POINTS_MAX), 1)


class ReadoutBoxes:
    """The two boxes of readouts; ``readouts`` by name (X.. C, J1..J6, J7..J11 the external axes)."""

    def __init__(self, parent: QWidget) -> None:
        self.readouts: dict[str, NumericReadout] = {}
        self.cart_box = QGroupBox(parent)
        grid = QGridLayout(self.cart_box)
        grid.setContentsMargins(6, 6, 6, 6)
        grid.setHorizontalSpacing(8)
        grid.setVerticalSpacing(6)
        self._cart_grid = grid
        self.cartesian: list[NumericReadout] = []
        for i, name in enumerate(CARTESIAN):
            readout = NumericReadout(
                name, "", point_size=BIG_POINTS, integer_digits=INTEGER_DIGITS, parent=self.cart_box
            )
            self.readouts[name] = readout
            self.cartesian.append(readout)
            grid.addWidget(readout, i // 3, i % 3)

        # Joints (when published) above the external axes, six columns, one box.
        self.axes_box = QGroupBox(parent)
        axes_grid = QGridLayout(self.axes_box)
        axes_grid.setContentsMargins(6, 4, 6, 4)
        axes_grid.setHorizontalSpacing(6)
        axes_grid.setVerticalSpacing(4)
        self._axes_grid = axes_grid
        self.joint_readouts: list[NumericReadout] = []
        for i in range(1, 7):
            readout = self._small(f"J{i}")
            readout.setVisible(False)  # shown once a pose carries joint angles
            self.joint_readouts.append(readout)
        # J7..J11 as the jog panel, go to zero and the joint frame number them (GV212..GV216)
        self.external_readouts = [self._small(f"J{i}") for i in range(7, 12)]
        self.small_columns = 0
        self._place_small(SMALL_COLUMNS[0])
        self._widths: dict[tuple[str, str, float], int] = {}  # (caption, unit, points) -> px

    def _small(self, name: str) -> NumericReadout:
        readout = NumericReadout(
            name,
            "",
            point_size=SMALL_POINTS,
            integer_digits=INTEGER_DIGITS,
            unit_room="",
            compact=True,
            parent=self.axes_box,
        )
        self.readouts[name] = readout
        return readout

    def _place_small(self, columns: int) -> None:
        """Joints from the first row, external axes from the next free one, ``columns`` a row."""
        if columns == self.small_columns:
            return
        self.small_columns = columns
        grid = self._axes_grid
        for readout in (*self.joint_readouts, *self.external_readouts):
            grid.removeWidget(readout)
        joint_rows = -(-len(self.joint_readouts) // columns)
        for i, readout in enumerate(self.joint_readouts):
            grid.addWidget(readout, i // columns, i % columns)
        for i, readout in enumerate(self.external_readouts):
            grid.addWidget(readout, joint_rows + i // columns, i % columns)
        for column in range(max(SMALL_COLUMNS)):
            grid.setColumnStretch(column, 1 if column < columns else 0)

    def _width(self, readout: NumericReadout, points: float) -> int:
        key = (readout.caption(), readout.unit(), points)
        width = self._widths.get(key)
        if width is None:
            width = self._widths[key] = readout.width_for(points)
        return width

    def _largest_fitting(
        self, readouts: list[NumericReadout], wanted: float, least: float, room: float
    ) -> float:
        """The largest size of the steps from ``wanted`` down to ``least`` at which each of
        ``readouts`` fits ``room`` px (``least`` when none does). A readout's width grows with its
        size, so the steps are bisected: ~4 sizes measured, not up to 20 (each size of each readout
        is a font to make and measure, before the window's first paint)."""
        steps = [wanted]
        while steps[-1] > least:
            steps.append(max(least, round(steps[-1] - POINTS_STEP, 1)))
        low, high = 0, len(steps) - 1  # the answer's index; steps[high] (least) when none fits
        while low < high:
            middle = (low + high) // 2
            if max(self._width(r, steps[middle]) for r in readouts) <= room:
                high = middle
            else:
                low = middle + 1
        return steps[low]

    @staticmethod
    def _column_room(box: QGroupBox, grid: QGridLayout, width: int, columns: int) -> float:
        """Px for each of ``columns`` readouts in ``box`` when the panel is ``width`` px wide."""
        frame = box.contentsMargins()
        inner = grid.contentsMargins()
        room = width - 2 * PANEL_MARGIN - frame.left() - frame.right() - inner.left() - inner.right()
        return (room - (columns - 1) * grid.horizontalSpacing()) / columns

    def fit_width(self, width: int) -> None:
        """Font sizes (and the small readouts' columns) for a panel ``width`` px wide."""
        big, small = readout_point_sizes(width)
        big = self._largest_fitting(
            self.cartesian, big, BIG_POINTS_MIN, self._column_room(self.cart_box, self._cart_grid, width, 3)
        )
        smalls = [*self.joint_readouts, *self.external_readouts]
        for columns in SMALL_COLUMNS:
            room = self._column_room(self.axes_box, self._axes_grid, width, columns)
            fitted = self._largest_fitting(smalls, small, SMALL_POINTS_MIN, room)
            if max(self._width(r, fitted) for r in smalls) <= room:
                break
        self._place_small(columns)
        for readout in self.cartesian:
            readout.set_point_size(big)
        for readout in smalls:
            readout.set_point_size(fitted)
