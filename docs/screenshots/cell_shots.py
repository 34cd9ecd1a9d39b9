"""The cell view's screenshots: 16 simulated controllers in the main window's Cell tab (not the
"Whole window" mode), at 1280×800 and 1920×1080, English and Chinese (and the README's pictures).

Run from the repository root (offscreen is enough; a CJK font must be installed)::

    QT_QPA_PLATFORM=offscreen .venv/bin/python docs/screenshots/cell_shots.py OUT_DIR
    QT_QPA_PLATFORM=offscreen .venv/bin/python docs/screenshots/cell_shots.py --readme

It starts a fleet of 16 simulators in-process (their programs running), gives a few of them alarms,
silences one (its tile greys: "not answering N s"), opens the cell in the Cell tab and publishes it
(*Plant link…*) to a Mosquitto of its own (``mosquitto`` must be installed). OUT_DIR gets
``cell_<lang>_<size>.png`` for both sizes and languages; ``--readme`` writes them into
docs/screenshots/ (the README shows the 1280×800 ones).
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
from app.cell.cell_file import Cell, CellController  # noqa: E402
from app.cell.publish import PublishSettings  # noqa: E402
from app.link.robot_link import RobotLink  # noqa: E402
from app.protocol.enums import Alarm  # noqa: E402
from app.sim.fleet import SimFleet  # noqa: E402
from benchmarks.gateway import mosquitto  # noqa: E402
from ui.i18n import Translator  # noqa: E402
from ui.main_window import MainWindow  # noqa: E402
from ui.settings import AppSettings  # noqa: E402

SIZES = ((1280, 800), (1920, 1080))
LANGUAGES = ("en", "zh_CN")
COUNT = 16
SILENT = 5  # R6 stops answering


def _spin(seconds: float) -> None:
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        QApplication.processEvents()
        time.sleep(0.01)


def main() -> None:
    with mosquitto() as broker_port:
        shoot(broker_port)


def shoot(broker_port: int) -> None:
    readme = "--readme" in sys.argv
    out = REPO / "docs" / "screenshots" if readme else Path(next(a for a in sys.argv[1:] if a != "--readme"))
    out.mkdir(parents=True, exist_ok=True)
    _app = QApplication(sys.argv[:1])  # kept alive to the end
    fleet = SimFleet(COUNT, programs=True)
    fleet.start()
    fleet[0].set_alarm(Alarm.SERVO, True)
    fleet[4].set_alarm(Alarm.ENCODER, True)
    fleet[4].set_alarm(Alarm.ESTOP, True)
    fleet[9].set_alarm(Alarm.BRAKE, True)
    link = RobotLink(poll_hz=timing.POLL_HZ_DEFAULT, canary_gv=None)
    tmp = Path(tempfile.mkdtemp())
    translator = Translator()
    window = MainWindow(link, AppSettings.from_file(tmp / "t.ini"), translator, autosave_dir=tmp / "auto")
    window.resize(*SIZES[0])
    window.show()
    controllers = tuple(
        CellController(name=f"R{i + 1}", host="127.0.0.1", port=port) for i, port in enumerate(fleet.ports)
    )
    panel = window.cell.show_cell(Cell("cell 3", controllers))
    window.cell.set_publishing(True, PublishSettings(f"mqtt://127.0.0.1:{broker_port}", "plant", "pad1"))
    _spin(1.0)
    fleet[SILENT].set_silent(True)
    _spin(3.5)
    for size in SIZES:
        window.resize(*size)
        for lang in LANGUAGES:
            window.set_language(lang)
            _spin(1.0)
            panel.refresh()
            for _ in range(3):  # the layout passes the new texts ask for
                QApplication.sendPostedEvents()
                QApplication.processEvents()
            window.grab().save(str(out / f"cell_{lang}_{size[0]}x{size[1]}.png"))
    window.cell.set_publishing(False, PublishSettings(f"mqtt://127.0.0.1:{broker_port}", "plant", "pad1"))
    window.close()
    link.shutdown()
    fleet.stop()


if __name__ == "__main__":
    main()
