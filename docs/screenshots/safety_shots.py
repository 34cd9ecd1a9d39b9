"""Make the guard rails' screenshots (docs/screenshots/safety_*.png) in English and Chinese.

Run from the repository root under a real X server with a CJK font::

    xvfb-run -a -s "-screen 0 1600x1000x24" .venv/bin/python docs/screenshots/safety_shots.py

It starts the simulator, opens the demo project, connects, sets an envelope with a keep-out
zone, jogs a little (audited writes) and saves: the envelope dialog, the audit viewer, the
points tab as an operator (Add disabled, its tooltip naming the role) and the planner with a
plan blocked by the keep-out zone.
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

from PySide6.QtCore import QPoint
from PySide6.QtWidgets import QApplication, QToolTip

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO))

from app import timing  # noqa: E402
from app.link.client import ConnectionSettings  # noqa: E402
from app.link.ops import JogPress, JogRelease  # noqa: E402
from app.link.robot_link import RobotLink  # noqa: E402
from app.link.types import JogRequest  # noqa: E402
from app.protocol.enums import TeachFrame  # noqa: E402
from app.safety.envelope import Box, Envelope  # noqa: E402
from app.safety.roles import Action, Role  # noqa: E402
from app.sim.config import SimConfig  # noqa: E402
from app.sim.server import SimController  # noqa: E402
from ui.controllers.safety_menu import install_safety  # noqa: E402
from ui.dialogs.envelope_dialog import EnvelopeDialog  # noqa: E402
from ui.i18n import Translator  # noqa: E402
from ui.main_window import MainWindow  # noqa: E402
from ui.panels.audit_viewer import AuditViewer  # noqa: E402
from ui.settings import AppSettings  # noqa: E402

OUT = REPO / "docs" / "screenshots"
PASSWORD = "cell-42"


def _spin(seconds: float) -> None:
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        QApplication.processEvents()
        time.sleep(0.01)


def main() -> None:
    app = QApplication(sys.argv)
    sim = SimController(SimConfig(host="127.0.0.1", port=0))
    sim.start()
    link = RobotLink(poll_hz=timing.POLL_HZ_DEFAULT, canary_gv=None)
    tmp = Path(tempfile.mkdtemp())
    translator = Translator()
    window = MainWindow(link, AppSettings.from_file(tmp / "t.ini"), translator, autosave_dir=tmp / "auto")
    menu = getattr(window, "safety_menu", None) or install_safety(window, scrypt_n=2**4)
    safety = menu.safety
    safety.session.store.scrypt_n = 2**4
    for role in (Role.ADMINISTRATOR, Role.ENGINEER):
        safety.session.store.set_password(role, PASSWORD, by=Role.ADMINISTRATOR)
    window.resize(1400, 880)
    window.show()
    window.project.open_file(REPO / "resources" / "samples" / "demo.teachpad.json")
    link.connect_to(ConnectionSettings(host="127.0.0.1", port=sim.port, timeout=1.0))
    _spin(1.5)
    safety.login(Role.ENGINEER, PASSWORD)
    ledger = window.project.points_model.ledger
    xs = sorted(p.xyz[0] for p in ledger)
    ys = sorted(p.xyz[1] for p in ledger)
    zs = sorted(p.xyz[2] for p in ledger)
    mid = (xs[len(xs) // 2], ys[len(ys) // 2], zs[len(zs) // 2])
    safety.save_envelope(Envelope(
        keep_in=Box("cell", (xs[0] - 300, ys[0] - 300, 0.0), (xs[-1] + 300, ys[-1] + 300, zs[-1] + 400)),
        keep_out=(Box("fixture", (mid[0] - 60, mid[1] - 60, zs[0] - 200), (mid[0] + 60, mid[1] + 60, mid[2])),),
        max_jog_ratio=50.0, max_speed=500.0))
    link.submit(JogPress(JogRequest(TeachFrame.BASE, 0, 1, 10.0)))
    _spin(0.6)
    link.submit(JogRelease())
    _spin(0.5)
    safety.logout()
    safety.allowed(Action.CONNECTION)  # an operator tries: refused, audited
    for lang in ("en", "zh_CN"):
        window.set_language(lang)
        suffix = "zh" if lang != "en" else "en"
        _spin(0.3)
        # the envelope dialog (an engineer's)
        safety.login(Role.ENGINEER, PASSWORD)
        dialog = EnvelopeDialog(safety, window)
        dialog.resize(900, 640)
        dialog.show()
        _spin(0.4)
        dialog.grab().save(str(OUT / f"safety_envelope_{suffix}.png"))
        dialog.close()
        # the planner: the circle plan crosses the keep-out zone
        window.work_tabs.setCurrentWidget(window.planner_panel)
        window.planner_panel.select_plan(1)
        _spin(0.5)
        window.work_tabs.grab().save(str(OUT / f"safety_planner_keepout_{suffix}.png"))
        # the audit viewer
        viewer = AuditViewer(safety.audit_dir, window)
        viewer.resize(1100, 560)
        viewer.show()
        _spin(0.4)
        viewer.grab().save(str(OUT / f"safety_audit_{suffix}.png"))
        viewer.close()
        # an operator: Add is disabled and says which role it needs
        safety.logout()
        window.work_tabs.setCurrentWidget(window.points_panel)
        _spin(0.4)
        button = next(b for b in window.points_panel.findChildren(type(window.points_panel.upload_button))
                      if b.defaultAction() is window.points_panel.action_add)
        at = button.mapToGlobal(QPoint(button.width() // 2, button.height()))
        QToolTip.showText(at, window.points_panel.action_add.toolTip(), button)
        _spin(0.6)
        screen = app.primaryScreen()
        shot = screen.grabWindow(0, window.x(), window.y(), window.frameGeometry().width(),
                                 min(window.frameGeometry().height(), 420))
        shot.save(str(OUT / f"safety_role_disabled_{suffix}.png"))
        QToolTip.hideText()
    window.close()
    link.shutdown()
    sim.stop()


if __name__ == "__main__":
    main()
