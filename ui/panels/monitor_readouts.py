"""The monitor's big readouts: the TCP box (X Y Z A B C) and the joints / external axes box,
and the font sizes that follow the panel's width."""

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


def readout_scale(width: int) -> float:
    """Readout size factor for a panel ``width`` px wide (1.0 at REFERENCE_WIDTH)."""
    return min(max((width - 40) / (REFERENCE_WIDTH - 40), MIN_SCALE), BIG_POINTS_MAX / BIG_POINTS)


def readout_point_sizes(width: int) -> tuple[float, float]:
    """(big, small) point sizes for a panel ``width`` px wide: readable from a distance at
    1920 px, still whole at 1280 px."""
    scale = readout_scale(width)
    big = round(BIG_POINTS * scale, 1)
    # six small readouts share a row: about 13 character cells each at ~0.85 pt per px
    fit = (width - 60) / 6 / (13 * 0.85)
    small = round(min(SMALL_POINTS * scale, SMALL_POINTS_MAX, fit), 1)
    return big, max(small, 8.0)


class ReadoutBoxes:
    """The two boxes of readouts; ``readouts`` by name (X.. C, J1..J6, EJ1..EJ5)."""

    def __init__(self, parent: QWidget) -> None:
        self.readouts: dict[str, NumericReadout] = {}
        self.cart_box = QGroupBox(parent)
        grid = QGridLayout(self.cart_box)
        grid.setContentsMargins(6, 6, 6, 6)
        grid.setHorizontalSpacing(8)
        grid.setVerticalSpacing(6)
        for i, name in enumerate(CARTESIAN):
            readout = NumericReadout(name, "", point_size=BIG_POINTS, parent=self.cart_box)
            self.readouts[name] = readout
            grid.addWidget(readout, i // 3, i % 3)

        # Joints (when published) above the external axes, six columns, one box.
        self.axes_box = QGroupBox(parent)
        axes_grid = QGridLayout(self.axes_box)
        axes_grid.setContentsMargins(6, 4, 6, 4)
        axes_grid.setHorizontalSpacing(6)
        axes_grid.setVerticalSpacing(4)
        self.joint_readouts: list[NumericReadout] = []
        for i in range(1, 7):
            readout = self._small(f"J{i}")
            readout.setVisible(False)  # shown once a pose carries joint angles
            self.joint_readouts.append(readout)
            axes_grid.addWidget(readout, 0, i - 1)
        for i in range(1, 6):
            axes_grid.addWidget(self._small(f"EJ{i}"), 1, i - 1)
        for column in range(6):
            axes_grid.setColumnStretch(column, 1)

    def _small(self, name: str) -> NumericReadout:
        readout = NumericReadout(
            name, "", point_size=SMALL_POINTS, width_chars=8, unit_room="", parent=self.axes_box
        )
        self.readouts[name] = readout
        return readout

    def fit_width(self, width: int) -> None:
        """Font sizes for a panel ``width`` px wide."""
        big, small = readout_point_sizes(width)
        for name, readout in self.readouts.items():
            readout.set_point_size(big if name in CARTESIAN else small)
