"""The main window's screenshots: every tab at 1280×800 and 1920×1080, English and Chinese,
an emergency stop, a silent controller and touch mode (and the README's pictures).

Run from the repository root under a real X server with a CJK font::

    xvfb-run -a -s "-screen 0 2000x1200x24" .venv/bin/python docs/screenshots/layout_shots.py OUT_DIR
    xvfb-run -a -s "-screen 0 2000x1200x24" .venv/bin/python docs/screenshots/layout_shots.py --readme

It starts the simulator in-process, opens the demo project and connects. OUT_DIR gets every
state (``<size>_<lang>_<work tab>+<motion tab>.png`` and the special states); ``--readme``
writes only the README's pictures into docs/screenshots/.
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
from app.protocol.enums import Alarm, TeachFrame  # noqa: E402
from app.sim.config import SimConfig  # noqa: E402
from app.sim.server import SimController  # noqa: E402
from ui.i18n import Translator  # noqa: E402
from ui.main_window import MainWindow  # noqa: E402
from ui.settings import AppSettings  # noqa: E402

SIZES = ((1280, 800), (1920, 1080))
LANGUAGES = ("en", "zh_CN")
# each work tab beside one motion tab (the joint frame is the tallest jog layout)
PAIRS = (("monitor", 0, TeachFrame.JOINT), ("points", 1, None), ("planner", 2, None),
         ("view3d", 0, TeachFrame.BASE))
README = {"main_en_1280x800": ("en", SIZES[0], "monitor"),
          "main_zh_CN_1920x1080": ("zh_CN", SIZES[1], "monitor"),
          "planner_en_1280x800": ("en", SIZES[0], "planner"),
          "planner_en_1920x1080": ("en", SIZES[1], "planner"),
          "points_zh_CN_1920x1080": ("zh_CN", SIZES[1], "points")}


def _spin(seconds: float) -> None:
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        QApplication.processEvents()
        time.sleep(0.01)


def _show(window: MainWindow, work: str, motion: int, frame: TeachFrame | None) -> None:
    if work == "view3d":
        window.work_tabs.setCurrentWidget(window.view3d.panel)
    else:
        window.show_tab(work)
    window.tabs.setCurrentIndex(motion)
    if frame is not None:
        window.jog_panel.set_frame(frame)
    _spin(0.6)


def _wait(condition: object, timeout: float = 10.0) -> None:
    end = time.monotonic() + timeout
    while not condition() and time.monotonic() < end:  # type: ignore[operator]
        QApplication.processEvents()
        time.sleep(0.01)


def main() -> None:
    readme = "--readme" in sys.argv
    out = REPO / "docs" / "screenshots" if readme else Path(next(a for a in sys.argv[1:] if a != "--readme"))
    out.mkdir(parents=True, exist_ok=True)
    _app = QApplication(sys.argv[:1])  # kept alive to the end
    sim = SimController(SimConfig(host="127.0.0.1", port=0))
    sim.start()
    link = RobotLink(poll_hz=timing.POLL_HZ_DEFAULT, canary_gv=None)
    tmp = Path(tempfile.mkdtemp())
    translator = Translator()
    window = MainWindow(link, AppSettings.from_file(tmp / "t.ini"), translator, autosave_dir=tmp / "auto")
    window.confirm = lambda _title, _text: True
    window.resize(*SIZES[0])
    window.show()
    window.project.open_file(REPO / "resources" / "samples" / "demo.teachpad.json")
    link.connect_to(ConnectionSettings(host="127.0.0.1", port=sim.port, timeout=1.0))
    _wait(lambda: window.motion_enabled and link.state.status is not None)
    window.planner_panel.select_plan(0)
    _spin(1.0)

    def save(name: str) -> None:
        window.grab().save(str(out / f"{name}.png"))

    if readme:
        for name, (lang, size, work) in README.items():
            window.set_language(lang)
            window.resize(*size)
            _show(window, work, 0, TeachFrame.BASE)
            save(name)
    else:
        for size in SIZES:
            window.resize(*size)
            for lang in LANGUAGES:
                window.set_language(lang)
                for work, motion, frame in PAIRS:
                    _show(window, work, motion, frame)
                    save(f"{size[0]}x{size[1]}_{lang}_{work}+{window.tabs.tabText(motion)}")
    # the special states, at 1280×800
    window.resize(*SIZES[0])
    for lang in ("en",) if readme else LANGUAGES:
        window.set_language(lang)
        window.set_touch_mode(True)
        _show(window, "monitor", 0, TeachFrame.JOINT)
        save("touch_en_1280x800" if readme else f"touch_{lang}_1280x800")
        _show(window, "planner", 2, None)
        if not readme:
            save(f"touch_{lang}_1280x800_planner")
        window.set_touch_mode(False)
        sim.set_alarm(Alarm.ESTOP, True)
        _wait(lambda: window.alarm_banner.isVisible())
        _show(window, "points", 0, TeachFrame.BASE)
        save("alarm_en_1280x800" if readme else f"alarm_{lang}_1280x800")
        if not readme:  # the tallest layouts under the banner, and the larger size
            _show(window, "monitor", 0, TeachFrame.JOINT)
            save(f"alarm_{lang}_1280x800_monitor+joint")
            window.resize(*SIZES[1])
            _show(window, "planner", 0, TeachFrame.BASE)
            save(f"alarm_{lang}_1920x1080_planner")
            window.resize(*SIZES[0])
        sim.set_alarm(Alarm.ESTOP, False)
        _spin(1.0)
    for lang in ("zh_CN",) if readme else LANGUAGES:
        window.set_language(lang)
        _show(window, "monitor", 0, TeachFrame.BASE)
        sim.set_silent(True)
        _wait(lambda: not window.pose_strip.is_live(), 5.0)
        _spin(1.2)  # the age counts up once
        save("stale_zh_CN_1280x800" if readme else f"stale_{lang}_1280x800")
        sim.set_silent(False)
        _wait(lambda: window.motion_enabled, 15.0)
        _spin(1.0)
    window.close()
    link.shutdown()
    sim.stop()


if __name__ == "__main__":
    main()
