"""The watch list's screenshots (docs/screenshots/watch_list_<lang>_1280x800.png), English and
Chinese: the main window at 1280×800 with *View → Watch list* open, five values of the
simulator (the live X and Z, a tool length, the mode register, the alarm bits), one of them
moving in the plot.

Run from the repository root (offscreen is enough; a CJK font must be installed)::

    QT_QPA_PLATFORM=offscreen .venv/bin/python docs/screenshots/watch_list_shots.py
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QApplication

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO))

from app import timing  # noqa: E402
from app.connection import ConnectionSettings  # noqa: E402
from app.link.client import RobotClient  # noqa: E402
from app.link.ops import Step  # noqa: E402
from app.link.robot_link import RobotLink  # noqa: E402
from app.link.types import StepFrame  # noqa: E402
from app.sim.config import SimConfig  # noqa: E402
from app.sim.server import SimController  # noqa: E402
from app.watchlist.entry import Source, ValueType, WatchEntry  # noqa: E402
from ui.i18n import Translator  # noqa: E402
from ui.main_window import MainWindow  # noqa: E402
from ui.settings import AppSettings  # noqa: E402

OUT = REPO / "docs" / "screenshots"
ENTRIES = (
    WatchEntry.make(Source.GV, 206, name="X"),
    WatchEntry.make(Source.GV, 208, name="Z"),
    WatchEntry.make(Source.GV, 10, name="tool length / 工具长度"),
    WatchEntry.make(Source.REGISTER, 560, ValueType.INT16, "mode"),
    WatchEntry.make(Source.REGISTER, 562, ValueType.BITS, "alarms"),
)


def _spin(seconds: float) -> None:
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        QApplication.processEvents()
        time.sleep(0.01)


def main() -> None:
    _app = QApplication(sys.argv[:1])  # kept alive to the end
    sim = SimController(SimConfig(host="127.0.0.1", port=0))
    sim.start()
    with RobotClient(ConnectionSettings(host="127.0.0.1", port=sim.port)) as client:
        client.write_gv(10, [152.5])
    link = RobotLink(poll_hz=timing.POLL_HZ_DEFAULT, canary_gv=None)
    tmp = Path(tempfile.mkdtemp())
    translator = Translator()
    window = MainWindow(link, AppSettings.from_file(tmp / "t.ini"), translator, autosave_dir=tmp / "auto")
    window.confirm = lambda _title, _text: True
    window.resize(1280, 800)
    window.show()
    link.connect_to(ConnectionSettings(host="127.0.0.1", port=sim.port, timeout=1.0))
    host = window.watch_list
    host.dock.toggleViewAction().trigger()
    _spin(0.5)
    host.set_entries(ENTRIES)
    window.resizeDocks([host.dock], [330], Qt.Orientation.Vertical)
    _spin(1.0)
    for dx in (80.0, -80.0, 60.0):
        link.submit(Step(StepFrame.BASE, [dx, 0, dx / 4, 0, 0, 0], speed=60.0))
        _spin(2.2)
    assert host.panel is not None
    host.panel.select_row(2)
    for lang in ("en", "zh_CN"):
        window.set_language(lang)
        _spin(0.8)
        window.grab().save(str(OUT / f"watch_list_{lang}_1280x800.png"))
    link.shutdown()
    sim.stop()


if __name__ == "__main__":
    main()
