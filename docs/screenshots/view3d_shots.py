"""Make the 3D view's screenshots (docs/screenshots/view3d_*.png) in English and Chinese.

Run from the repository root under a real X server with a CJK font::

    xvfb-run -a -s "-screen 0 1920x1080x24" .venv/bin/python docs/screenshots/view3d_shots.py

It starts the simulator, opens the demo project, connects, and saves: the live arm with the
ghost path of each demo plan, a dry run mid-way, and an unreachable point in red (the view
beside the planner, whose checks list shows the error and whose Run is disabled).
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

from PySide6.QtWidgets import QApplication

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO))

from app import timing  # noqa: E402
from app.link.client import ConnectionSettings  # noqa: E402
from app.link.robot_link import RobotLink  # noqa: E402
from app.sim.config import SimConfig  # noqa: E402
from app.sim.server import SimController  # noqa: E402
from app.view3d.camera import Preset  # noqa: E402
from ui.i18n import Translator  # noqa: E402
from ui.main_window import MainWindow  # noqa: E402
from ui.settings import AppSettings  # noqa: E402

OUT = REPO / "docs" / "screenshots"


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
    window.resize(1500, 950)
    window.show()
    window.project.open_file(REPO / "resources" / "samples" / "demo.teachpad.json")
    link.connect_to(ConnectionSettings(host="127.0.0.1", port=sim.port, timeout=1.0))
    panel = window.view3d.panel
    window.work_tabs.setCurrentWidget(panel)
    _spin(2.0)
    for lang in ("en", "zh_CN"):
        window.set_language(lang)
        suffix = "zh" if lang != "en" else "en"
        for row, name in ((0, "pick"), (1, "circle")):
            window.planner_panel.select_plan(row)
            _spin(0.3)
            panel.dry_bar.leave()
            panel.set_preset(Preset.ISO)
            _spin(0.3)
            window.work_tabs.grab().save(str(OUT / f"view3d_live_{name}_{suffix}.png"))
        window.planner_panel.select_plan(0)
        _spin(0.3)
        panel.dry_bar.slider.setValue(450)
        _spin(0.3)
        window.work_tabs.grab().save(str(OUT / f"view3d_dryrun_{suffix}.png"))
        panel.dry_bar.leave()
    # an unreachable point, used by the circle plan: red in the view, an error in the planner's
    # checks (the view beside the planner), Run disabled
    model = window.project.points_model
    model.add_point(name="far", pose=(1150.0, 250.0, 350.0, 180.0, 0.0, 180.0))
    planner = window.planner_panel
    planner.select_plan(1)
    far = max(p.id for p in model.ledger)
    row = planner.segments.insert_segment(2)  # a detour out of reach, for the picture
    planner.segments.edit_field(row, "end", far)
    planner.select_segments([row])
    window.resize(1900, 1040)  # room for the planner and the view beside it
    panel.beside_button.setChecked(True)
    _spin(0.5)
    for lang in ("en", "zh_CN"):
        window.set_language(lang)
        panel.set_preset(Preset.ISO)
        _spin(0.3)
        window.grab().save(str(OUT / f"view3d_unreachable_{'zh' if lang != 'en' else 'en'}.png"))
    panel.beside_button.setChecked(False)
    link.shutdown()
    sim.stop()
    window.project.dialogs.ask_save_changes = lambda _name: "discard"  # the detour is not kept
    window.close()
    app.processEvents()


if __name__ == "__main__":
    main()
