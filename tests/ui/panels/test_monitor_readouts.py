"""The monitor's readout sizes (ui/panels/monitor_readouts.py): the largest size at which every
readout of a row fits is found by bisecting the steps (a few fonts measured before the first
paint, not up to twenty), and it is the size a step-by-step descent finds."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest
from PySide6.QtWidgets import QWidget

from ui.panels.monitor_readouts import (
    BIG_POINTS_MIN,
    POINTS_STEP,
    SMALL_POINTS_MIN,
    ReadoutBoxes,
    readout_point_sizes,
)
from ui.widgets_common import NumericReadout

pytestmark = pytest.mark.timeout(60)


def _descent(readouts: list[NumericReadout], wanted: float, least: float, room: float) -> float:
    """The sizes tried one step at a time from ``wanted`` down (what the panel did before)."""
    points = wanted
    while points > least and max(r.width_for(points) for r in readouts) > room:
        points = max(least, round(points - POINTS_STEP, 1))
    return points


@pytest.fixture
def boxes(qtbot: Any) -> Iterator[ReadoutBoxes]:
    parent = QWidget()  # held here: the readouts are its children
    qtbot.addWidget(parent)
    yield ReadoutBoxes(parent)


def test_the_bisected_size_is_the_largest_that_fits(boxes: ReadoutBoxes) -> None:
    smalls = [*boxes.joint_readouts, *boxes.external_readouts]
    for width in range(240, 2400, 23):  # every room from "nothing fits" to "the wanted size fits"
        big, small = readout_point_sizes(width)
        rows = ((boxes.cartesian, big, BIG_POINTS_MIN), (smalls, small, SMALL_POINTS_MIN))
        for readouts, wanted, least in rows:
            room = width / 3 if readouts is boxes.cartesian else width / 6
            found = boxes._largest_fitting(readouts, wanted, least, room)
            assert found == _descent(readouts, wanted, least, room), (width, wanted, room)


def test_a_few_sizes_are_measured_not_every_step(
    boxes: ReadoutBoxes, monkeypatch: pytest.MonkeyPatch
) -> None:
    measured: set[float] = set()
    width_for = NumericReadout.width_for

    def counting(readout: NumericReadout, points: float) -> int:
        measured.add(points)
        return width_for(readout, points)

    monkeypatch.setattr(NumericReadout, "width_for", counting)
    wanted, least = 30.0, 6.0  # 49 steps
    boxes._largest_fitting(boxes.cartesian, wanted, least, room=1.0)  # nothing fits: least
    assert len(measured) <= 7  # log2(49) rounded up, and the last
    assert boxes._largest_fitting(boxes.cartesian, wanted, least, room=1e6) == wanted
