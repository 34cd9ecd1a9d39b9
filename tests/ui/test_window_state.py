"""The main window keeps no copy of the connection: every part that enables or shows something by
the link's state reads the link's RobotState when it changes (connect, link lost at the
simulator, reconnected)."""

from __future__ import annotations

from typing import Any

import pytest

from app.link.types import ConnectionState, LinkState
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    SIGNAL_TIMEOUT_MS,
    app_settings_fixture,
    connect,
    fast_reconnect_fixture,
    link_fixture,
    project_dialogs_fixture,
    translator_fixture,
    window_fixture,
)
from ui.main_window import MainWindow
from ui.widgets_common import connection_display

pytestmark = [pytest.mark.timeout(60), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]


def _shown(window: MainWindow) -> dict[str, object]:
    """What the window shows that depends on the connection."""
    menus = window.menus
    return {
        "pause": menus.pause_action.isEnabled(),
        "resume": menus.resume_action.isEnabled(),
        "disconnect": menus.disconnect_action.isEnabled(),
        "banner": window.motion_banner.isVisibleTo(window),
        "jog": window.jog_panel.axes_box.isEnabled(),
        "link label": window.status_link.text(),
    }


def _expected(window: MainWindow) -> dict[str, object]:
    """The same, derived from the link's RobotState alone."""
    state = window.link.state
    return {
        "pause": state.writable,
        "resume": state.writable,
        "disconnect": state.connection.state is not LinkState.DISCONNECTED,
        "banner": not state.writable,
        "jog": state.writable,
        "link label": connection_display(state.connection)[0],
    }


def _copies(obj: object) -> list[str]:
    """Attributes of ``obj`` that hold a connection state (a copy kept in step by hand)."""
    return [
        name
        for name, value in vars(obj).items()
        if isinstance(value, ConnectionState | LinkState) or ("connected" in name and isinstance(value, bool))
    ]


def test_connection_dependent_enabling_follows_the_robot_state(
    qtbot: Any, sim_factory: Any, window: MainWindow
) -> None:
    state = window.link.state
    seen: list[LinkState] = []
    mismatches: list[tuple[LinkState, dict[str, object], dict[str, object]]] = []

    def compare(connection: ConnectionState) -> None:
        # connected after the window's parts: Qt calls them first, each has read the state
        seen.append(connection.state)
        shown, expected = _shown(window), _expected(window)
        if shown != expected:
            mismatches.append((connection.state, shown, expected))

    state.connectionChanged.connect(compare)
    assert _shown(window) == _expected(window) and not state.connected

    sim = sim_factory()
    port = sim.port
    connect(qtbot, window.link, sim)
    assert _shown(window)["pause"] and not _shown(window)["banner"]

    sim.stop()  # the controller goes away: the link is lost, the worker retries by itself
    qtbot.waitUntil(lambda: not state.connected, timeout=SIGNAL_TIMEOUT_MS)
    shown = _shown(window)
    assert not shown["pause"] and not shown["jog"] and shown["disconnect"]  # still trying
    assert shown["banner"] and "Not connected" in window.motion_banner.text()

    with qtbot.waitSignal(window.link.controllerReconnected, timeout=SIGNAL_TIMEOUT_MS):
        sim_factory(port=port)  # back on the same port
    qtbot.waitUntil(lambda: state.connected, timeout=SIGNAL_TIMEOUT_MS)
    assert _shown(window)["pause"] and not _shown(window)["banner"]

    with qtbot.waitSignal(
        state.connectionChanged,
        timeout=SIGNAL_TIMEOUT_MS,
        check_params_cb=lambda c: c.state is LinkState.DISCONNECTED,
    ):
        window.menus.disconnect_action.trigger()
    assert not _shown(window)["disconnect"]

    assert mismatches == []
    assert seen[0] is not LinkState.CONNECTED and LinkState.CONNECTED in seen
    lost = seen.index(LinkState.CONNECTED)
    assert any(s is not LinkState.CONNECTED for s in seen[lost:])  # lost ...
    assert seen.count(LinkState.CONNECTED) >= 2  # ... and back
    for part in (window, window.control_column, window.menus, window.status_bar, window.docks):
        assert _copies(part) == [], type(part).__name__
