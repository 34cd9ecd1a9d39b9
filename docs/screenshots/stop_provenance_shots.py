"""Issue 24's screenshots at 1280×800, English and Chinese: the monitor's "last stop" line after a
measured Stop, a point's provenance in the points table's tooltip, and *Compare with…*.

Run from the repository root (offscreen is enough; a CJK font must be installed for Chinese)::

    QT_QPA_PLATFORM=offscreen .venv/bin/python docs/screenshots/stop_provenance_shots.py

It starts the simulator in-process, connects, teaches two points, types a third, edits one,
stops a 100 mm/s move with the Stop button, then compares the project with a CSV in which one
point moved 0.2 mm, one was removed and one added. The tooltip and the dialog are painted onto
the window's picture where they show.
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

from PySide6.QtCore import QPoint, Qt
from PySide6.QtGui import QPainter, QPixmap
from PySide6.QtWidgets import QApplication, QLabel, QToolTip, QWidget

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO))

from app import timing  # noqa: E402
from app.link.client import ConnectionSettings  # noqa: E402
from app.link.ops import Step  # noqa: E402
from app.link.robot_link import RobotLink  # noqa: E402
from app.link.types import StepFrame  # noqa: E402
from app.points.point import make_point  # noqa: E402
from app.points.project import write_points_csv  # noqa: E402
from app.sim.config import SimConfig  # noqa: E402
from app.sim.server import SimController  # noqa: E402
from ui.i18n import Translator  # noqa: E402
from ui.main_window import MainWindow  # noqa: E402
from ui.models.point_columns import COL_NAME  # noqa: E402
from ui.settings import AppSettings  # noqa: E402

OUT = REPO / "docs" / "screenshots"
SIZE = (1280, 800)


def _spin(seconds: float) -> None:
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        QApplication.processEvents()
        time.sleep(0.01)


def _wait(condition: object, timeout: float = 10.0) -> None:
    end = time.monotonic() + timeout
    while not condition() and time.monotonic() < end:  # type: ignore[operator]
        QApplication.processEvents()
        time.sleep(0.01)


def _with(window: MainWindow, widget: QWidget) -> QPixmap:
    """The window's picture with ``widget`` (a tooltip, a dialog) painted where it shows."""
    picture = window.grab()
    painter = QPainter(picture)
    painter.drawPixmap(widget.mapToGlobal(QPoint(0, 0)) - window.mapToGlobal(QPoint(0, 0)), widget.grab())
    painter.end()
    return picture


def _tooltip() -> QWidget | None:
    return next(
        (
            w
            for w in QApplication.topLevelWidgets()
            if isinstance(w, QLabel) and w.isVisible() and w.inherits("QTipLabel")
        ),
        None,
    )


def main() -> None:
    _app = QApplication(sys.argv[:1])
    sim = SimController(SimConfig(host="127.0.0.1", port=0))
    sim.start()
    link = RobotLink(poll_hz=timing.POLL_HZ_DEFAULT, canary_gv=None)
    tmp = Path(tempfile.mkdtemp())
    window = MainWindow(link, AppSettings.from_file(tmp / "t.ini"), Translator(), autosave_dir=tmp / "auto")
    window.confirm = lambda _title, _text: True
    window.resize(*SIZE)
    window.show()
    link.connect_to(ConnectionSettings(host="127.0.0.1", port=sim.port, timeout=1.0))
    _wait(lambda: window.motion_enabled and link.state.status is not None)
    model = window.project.points_model
    for dx in (-50.0, 50.0):
        link.submit(Step(StepFrame.BASE, (dx, 0, 0, 0, 0, 0), speed=200.0))
        _wait(lambda: sim.state().moving, 2.0)
        _wait(lambda: not sim.state().moving, 5.0)
        _spin(0.3)
        n = len(model.ledger)
        window.point_sync.teach()
        _wait(lambda: len(model.ledger) > n)
    row = model.add_point(name="approach", pose=(420.0, 30.0, 380.0, 180.0, 0.0, 90.0))
    model.edit_field(row, "z", 385.0)
    # a Stop during a 100 mm/s move: the monitor's line
    link.submit(Step(StepFrame.BASE, (0.0, 0.0, -100.0, 0.0, 0.0, 0.0), speed=100.0))
    _wait(lambda: sim.state().moving)
    _spin(0.4)
    window.control_bar.stop_button.click()
    _wait(lambda: len(window.stop_timing.log) > 0)
    csv_path = tmp / "cell 3 points.csv"
    points = list(model.ledger)
    moved = make_point(2, points[1].name, (points[1].x + 0.2, *points[1].xyzabc[1:]))
    write_points_csv(
        csv_path, [points[0], moved, make_point(7, "drop", (500.0, -80.0, 300.0, 180.0, 0.0, 0.0))]
    )
    for lang in ("en", "zh_CN"):
        window.set_language(lang)
        window.show_tab("monitor")
        _spin(0.6)
        window.grab().save(str(OUT / f"stop_last_{lang}_1280x800.png"))
        window.show_tab("points")
        _spin(0.6)
        view = window.points_panel.table
        index = view.model().index(0, COL_NAME)
        rect = view.visualRect(index)
        tip = str(index.data(Qt.ItemDataRole.ToolTipRole))
        QToolTip.showText(view.viewport().mapToGlobal(rect.center()), tip, view.viewport())
        _spin(0.5)
        label = _tooltip()
        (_with(window, label) if label is not None else window.grab()).save(
            str(OUT / f"provenance_tooltip_{lang}_1280x800.png")
        )
        QToolTip.hideText()
        dialog = window.compare.compare_with(csv_path)
        assert dialog is not None
        _spin(0.3)
        dialog.move(window.geometry().center() - dialog.rect().center())
        _spin(0.3)
        _with(window, dialog).save(str(OUT / f"compare_{lang}_1280x800.png"))
        dialog.close()
    link.shutdown()  # no close: it would ask to save the untitled project
    sim.stop()


if __name__ == "__main__":
    main()
