"""The status bar's words about the controller's silence last as long as the silence (issue 21,
"Words that say what happened"): "did not answer within … s" goes when the controller answers
again, and the round trip reads "—" while it does not answer or the link is down (the last
figure is not today's), in the status bar and the status dock. Window against the simulator,
made silent; both languages."""

from __future__ import annotations

from typing import Any

import pytest

from app import timing
from app.link.types import LinkState
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    SIGNAL_TIMEOUT_MS,
    app_settings_fixture,
    connection_settings,
    fast_reconnect_fixture,
    is_state,
    link_fixture,
    project_dialogs_fixture,
    translator_fixture,
    window_fixture,
)
from tests.ui.test_messages import assert_chinese
from ui.main_window import MainWindow

pytestmark = [pytest.mark.timeout(120), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]


def _connect(qtbot: Any, window: MainWindow, sim: Any) -> None:
    with qtbot.waitSignal(
        window.link.state.connectionChanged, check_params_cb=lambda s: s.connected, timeout=SIGNAL_TIMEOUT_MS
    ):
        window.connect_with(connection_settings(sim, poll_timeout=0.3))
    qtbot.waitUntil(lambda: window.link.state.rtt is not None, timeout=SIGNAL_TIMEOUT_MS)


def _until(window: MainWindow, state: LinkState, timeout: int = SIGNAL_TIMEOUT_MS) -> dict[str, Any]:
    return {"signal": window.link.connectionChanged, "check_params_cb": is_state(state), "timeout": timeout}


def _silent_then_back(qtbot: Any, window: MainWindow, sim: Any, until: LinkState) -> None:
    bar = window.statusBar()
    with qtbot.waitSignal(**_until(window, until)):
        sim.set_silent(True)
    qtbot.waitUntil(lambda: "did not answer within 0.3 s" in bar.currentMessage(), timeout=SIGNAL_TIMEOUT_MS)
    assert window.status_bar.rtt_label.text() == "RTT —"
    with qtbot.waitSignal(**_until(window, LinkState.CONNECTED)):
        sim.set_silent(False)
    assert bar.currentMessage() == ""  # the silence is over: its words are gone at once


def test_the_silence_is_forgotten_when_the_controller_answers_again(
    qtbot: Any, window: MainWindow, sim: Any
) -> None:
    _connect(qtbot, window, sim)
    rtt = window.status_bar.rtt_label.text()
    assert rtt.startswith("RTT ") and rtt.endswith(" ms") and "—" not in rtt
    _silent_then_back(qtbot, window, sim, LinkState.NOT_ANSWERING)
    qtbot.waitUntil(lambda: "—" not in window.status_bar.rtt_label.text(), timeout=SIGNAL_TIMEOUT_MS)


def test_the_round_trip_reads_a_dash_while_the_link_is_down_in_both_languages(
    qtbot: Any, window: MainWindow, sim: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(timing, "NOT_ANSWERING_DOWN_AFTER", 0.5)
    _connect(qtbot, window, sim)
    window.set_language("zh_CN")
    bar = window.statusBar()
    with qtbot.waitSignal(**_until(window, LinkState.DOWN)):
        sim.set_silent(True)
    rtt = window.status_bar.rtt_label.text()
    assert rtt == "往返 —", rtt
    assert window.status_panel.rtt_label.text() == "—"
    if bar.currentMessage():
        assert_chinese(bar.currentMessage())
    with qtbot.waitSignal(**_until(window, LinkState.CONNECTED, 4 * SIGNAL_TIMEOUT_MS)):
        sim.set_silent(False)
    assert bar.currentMessage() == ""
