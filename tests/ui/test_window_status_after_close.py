"""A window's status bar stops following the link's state when the window is gone: the link (and
its state) may outlive a window -- the benchmarks open several on one link -- and a follower left
behind raised "Internal C++ object (LiveLabel) already deleted" at every RTT report."""

from __future__ import annotations

from typing import Any

from PySide6.QtCore import QCoreApplication, QEvent

from app.link.robot_link import RobotLink
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    app_settings_fixture,
    fast_reconnect_fixture,
    link_fixture,
    project_dialogs_fixture,
)
from ui.i18n import Translator
from ui.main_window import MainWindow


def test_an_rtt_report_after_the_window_is_gone_reaches_no_label(
    qtbot: Any, link: RobotLink, app_settings: Any, project_dialogs: Any, tmp_path: Any
) -> None:
    translator = Translator()
    window = MainWindow(
        link, app_settings, translator, project_dialogs=project_dialogs, autosave_dir=tmp_path
    )
    link.state.rttChanged.emit(1.5)  # followed while the window lives
    window.deleteLater()
    QCoreApplication.sendPostedEvents(None, QEvent.Type.DeferredDelete)
    link.state.rttChanged.emit(2.5)  # an exception in a slot fails the test (pytest-qt)
    translator.uninstall()
