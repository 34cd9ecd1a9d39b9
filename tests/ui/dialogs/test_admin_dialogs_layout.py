"""The administrator's dialogs (register profile, passwords and lock, the connection dialog with
the register profile's note) in English and Chinese: nothing clipped, nothing overlapping, as the
layout check does for the other dialogs."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from PySide6.QtCore import QCoreApplication
from PySide6.QtGui import QFontDatabase
from PySide6.QtWidgets import QApplication, QDialog

from app.connection import ConnectionSettings
from app.safety.register_profile import RegisterProfile
from app.safety.roles import Action, Role
from tests.ui.layout_audit import clipped_texts, overlapping_siblings
from tests.ui.pendant_support import translator_fixture  # noqa: F401 - fixtures
from ui.controllers.safety import SafetyController
from ui.dialogs.connection_dialog import ConnectionDialog
from ui.dialogs.password_dialog import PasswordDialog
from ui.dialogs.register_profile_dialog import RegisterProfileDialog


def _problems(dialog: QDialog, language: str) -> list[str]:
    for _ in range(3):
        QCoreApplication.sendPostedEvents()
        QApplication.processEvents()
    found = overlapping_siblings(dialog)
    if language == "en" or QFontDatabase.families(QFontDatabase.WritingSystem.SimplifiedChinese):
        found += clipped_texts(dialog)
    return found


@pytest.mark.parametrize("language", ["en", "zh_CN"])
@pytest.mark.parametrize("role", [Role.OPERATOR, Role.ADMINISTRATOR])
def test_admin_dialogs_layout(qtbot: Any, translator: Any, tmp_path: Path, language: str, role: Role) -> None:
    assert translator.set_language(language)
    safety = SafetyController(None, scrypt_n=2**4)
    safety.set_idle_polling(False)
    safety.session.set_password(Role.ADMINISTRATOR, "root-pw")
    if role is Role.ADMINISTRATOR:
        safety.login(Role.ADMINISTRATOR, "root-pw")
    try:
        profile = RegisterProfile("cell 3", revision=2, saved="2026-11-24T05:40:00+00:00")
        dialogs: list[QDialog] = [
            RegisterProfileDialog(
                profile, lambda _p, _r: None, reason=safety.reason(Action.REGISTER_PROFILE), connected=True
            ),
            PasswordDialog(safety),
            ConnectionDialog(ConnectionSettings(), profile=profile),
        ]  # with the profile's note
        for dialog in dialogs:
            qtbot.addWidget(dialog)
            dialog.show()
            qtbot.waitExposed(dialog)
            assert _problems(dialog, language) == [], type(dialog).__name__
            dialog.close()
    finally:
        safety.close()
