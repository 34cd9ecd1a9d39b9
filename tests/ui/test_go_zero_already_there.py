"""Go to zero on an axis already at 0 says it is already there (issue 21, "Words that say what
happened"): against the simulator through RobotLink (the worker thread), twice on the same axis: the
second one reads "done (the axes were already at zero)", never a red "no motion within 2 s", and the
simulator's joint stays at 0. Both languages."""

from __future__ import annotations

from typing import Any

import pytest
from PySide6.QtCore import QCoreApplication, QTranslator

from app.link.ops import GoZero
from app.link.robot_link import RobotLink
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    SIGNAL_TIMEOUT_MS,
    connect,
    fast_reconnect_fixture,
    link_fixture,
)
from tests.ui.test_messages import QM, assert_chinese
from tests.ui.test_outcome_words import Results
from ui.messages import result_text

pytestmark = pytest.mark.timeout(60)


@pytest.fixture
def results(link: RobotLink) -> Results:
    return Results(link)


@pytest.mark.parametrize("axis", [1, None], ids=["J2", "all"])
def test_go_to_zero_when_already_there_says_so_in_both_languages(
    qtbot: Any, sim: Any, link: RobotLink, results: Results, axis: int | None
) -> None:
    connect(qtbot, link, sim)
    first = results.of(qtbot, link.submit(GoZero(axis)), timeout=10 * SIGNAL_TIMEOUT_MS)
    assert first.ok, first.message
    joints = sim.state().joints
    assert all(abs(j) < 0.01 for j in (joints if axis is None else [joints[axis]]))
    again = results.of(qtbot, link.submit(GoZero(axis)), timeout=10 * SIGNAL_TIMEOUT_MS)
    assert again.ok, again.message
    text = result_text(again)
    assert "already at zero" in text and "no motion" not in text, text
    assert sim.state().joints == pytest.approx(joints, abs=0.01)
    translator = QTranslator()
    assert translator.load(str(QM))
    QCoreApplication.installTranslator(translator)
    try:
        zh = result_text(again)
    finally:
        QCoreApplication.removeTranslator(translator)
    assert_chinese(zh)
    assert "失败" not in zh, zh
