"""Make the administrator's screenshots (docs/screenshots/admin_*.png) in English and Chinese.

Run from the repository root (offscreen is enough: only dialogs are grabbed; a CJK font must be
installed for the Chinese ones)::

    QT_QPA_PLATFORM=offscreen .venv/bin/python docs/screenshots/admin_shots.py

The register profile dialog (a high-word-first controller, unit 7, connected: "reconnect now"
offered), the same dialog as an operator sees it (every field disabled, the reason shown), and the
passwords and lock screen.
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

from PySide6.QtCore import QSettings
from PySide6.QtWidgets import QApplication

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO))

from app.protocol.codec import WordOrder  # noqa: E402
from app.safety.register_profile import RegisterProfile  # noqa: E402
from app.safety.roles import Action, Role  # noqa: E402
from ui.controllers.safety import SafetyController  # noqa: E402
from ui.dialogs.password_dialog import PasswordDialog  # noqa: E402
from ui.dialogs.register_profile_dialog import RegisterProfileDialog  # noqa: E402
from ui.i18n import Translator  # noqa: E402

OUT = REPO / "docs" / "screenshots"
PASSWORD = "cell-42"
PROFILE = RegisterProfile("cell 3 (BC-2000, ABCD)", word_order=WordOrder.HIGH_FIRST, unit=7,
                          completion="observe", poll_timeout=0.25, revision=3,
                          saved="2026-11-24T05:40:00+00:00")


def _spin(seconds: float) -> None:
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        QApplication.processEvents()
        time.sleep(0.01)


def main() -> None:
    app = QApplication(sys.argv)
    tmp = Path(tempfile.mkdtemp())
    safety = SafetyController(None, QSettings(str(tmp / "t.ini"), QSettings.Format.IniFormat), scrypt_n=2**4)
    safety.set_idle_polling(False)
    safety.session.set_password(Role.ADMINISTRATOR, PASSWORD)
    translator = Translator()
    for lang in ("en", "zh_CN"):
        translator.set_language(lang)
        suffix = "zh" if lang != "en" else "en"
        _spin(0.1)
        safety.login(Role.ADMINISTRATOR, PASSWORD)
        if not safety.session.store.has_password(Role.ENGINEER):
            safety.session.set_password(Role.ENGINEER, PASSWORD)
        shots = {
            f"admin_register_profile_{suffix}.png": RegisterProfileDialog(
                PROFILE, lambda _p, _r: None, reason=None, connected=True),
            f"admin_passwords_{suffix}.png": PasswordDialog(safety),
        }
        safety.logout()
        shots[f"admin_register_profile_operator_{suffix}.png"] = RegisterProfileDialog(
            PROFILE, lambda _p, _r: None, reason=safety.reason(Action.REGISTER_PROFILE))
        for name, dialog in shots.items():
            dialog.show()
            dialog.adjustSize()
            _spin(0.3)
            dialog.grab().save(str(OUT / name))
            dialog.close()
    translator.uninstall()
    safety.close()


if __name__ == "__main__":
    main()
