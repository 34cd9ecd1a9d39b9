"""The audit trail's error callback runs in whatever thread wrote -- mostly the link's worker. What
it says reaches the window through ``SafetyController.message``, whose receivers touch widgets:
that signal is emitted in the GUI thread only (issue 18: it was emitted from RobotWorker, and
reached the widgets in the GUI thread only because PySide 6.11 queues a lambda without a context
object to the sender's thread)."""

from __future__ import annotations

import threading
from pathlib import Path
from typing import Any

import pytest
from PySide6.QtCore import Qt

from app.link.ops import SetMode
from app.protocol.enums import WorkMode
from app.safety.location import safety_location
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

pytestmark = [pytest.mark.timeout(60), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]


@pytest.fixture(name="blocked_audit")
def blocked_audit_fixture(tmp_path: Path) -> Path:
    """A file where the window's audit folder goes (the test's own per-user folder): nothing can be
    recorded."""
    folder = safety_location().audit_dir
    folder.parent.mkdir(parents=True, exist_ok=True)
    folder.write_text("a file where the folder should be", encoding="utf-8")
    return folder


def test_an_audit_failure_in_the_worker_reaches_the_window_from_the_gui_thread(
    qtbot: Any, sim: Any, blocked_audit: Path, window: Any
) -> None:
    safety = window.safety_menu.safety
    heard: list[tuple[str, str]] = []  # (thread, text) of every emission of ``message``
    safety.message.connect(
        lambda text: heard.append((threading.current_thread().name, text)),
        Qt.ConnectionType.DirectConnection,  # runs where the signal is emitted
    )
    wrote: list[str] = []  # the threads the audit met its failure in
    report = safety.session.audit.on_error
    assert report is not None

    def on_error(text: str) -> None:
        wrote.append(threading.current_thread().name)
        report(text)

    safety.session.audit.on_error = on_error
    # a record of the window's start (a fresh install's envelope) met the failure first, in the GUI
    # thread: each problem is reported once, so forget it -- the next one is the worker's
    safety.session.audit.last_error = None
    connect(qtbot, window.link, sim)
    writes = len(sim.writes)
    window.link.submit(SetMode(WorkMode.MANUAL))  # a write: recorded by the worker, before it goes out
    qtbot.waitUntil(lambda: any("cannot be written" in text for _, text in heard), timeout=SIGNAL_TIMEOUT_MS)
    assert len(sim.writes) == writes  # no write without its record (issue 19): refused, not sent
    assert wrote and wrote[0] != threading.main_thread().name  # met in the worker thread
    assert {thread for thread, _ in heard} == {threading.main_thread().name}
    logged = [event.text for event in window.event_log.model.events()]
    assert any("cannot be written" in text for text in logged)
    assert "cannot be written" in window.statusBar().currentMessage()


def test_the_safety_messages_go_to_a_receiver_in_the_gui_thread(qtbot: Any, window: Any) -> None:
    """Their receiver is a slot of the Safety menu (its context object: GUI thread), not lambdas
    without one: a message emitted in another thread is still shown by the GUI thread."""
    menu = window.safety_menu
    shown: list[str] = []
    log = window.event_log.add_event

    def add_event(level: str, source: Any, text: Any) -> Any:
        shown.append(threading.current_thread().name)
        return log(level, source, text)

    window.event_log.add_event = add_event
    emitter = threading.Thread(target=menu.safety.message.emit, args=("the envelope file is damaged",))
    emitter.start()
    emitter.join()
    qtbot.waitUntil(lambda: bool(shown), timeout=SIGNAL_TIMEOUT_MS)
    assert shown == [threading.main_thread().name]
    assert "the envelope file is damaged" in window.statusBar().currentMessage()
    assert menu.safety.message.disconnect(menu.show_message)  # that receiver is the menu's slot
