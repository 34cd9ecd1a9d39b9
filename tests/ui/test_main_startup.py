"""Start-up work that the first paint does not need runs after it (ui/main.py)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[2]


def test_nothing_heavy_is_imported_before_the_first_paint(tmp_path: Any) -> None:
    """``teachpad`` (ui.main.main) up to the window's first paint imports neither pymodbus nor
    numpy nor pyqtgraph (nor the plan runner or the project lock), makes no link worker and builds
    neither Points nor Planner, nor the Step and Program motion tabs: the start-up figure of
    issue 10 (first paint vs a bare QMainWindow) depends on it."""
    code = textwrap.dedent("""
        import json, sys
        from PySide6.QtWidgets import QApplication
        import ui.main as teachpad

        class Probe(teachpad.MainWindow):
            def paintEvent(self, event):
                if not hasattr(self, "seen"):
                    self.seen = sorted(m for m in HEAVY if m in sys.modules)
                    self.built = [self.points_tab.built, self.planner_tab.built, self.link._made is not None,
                                  self.step_tab.built, self.program_tab.built]
                    print("FIRST_PAINT " + json.dumps([self.seen, self.built]), flush=True)
                    QApplication.instance().exit(0)
                super().paintEvent(event)

        HEAVY = ("numpy", "pymodbus", "pyqtgraph", "asyncio", "app.link.worker", "app.link.client",
                 "ui.panels.points_panel", "ui.panels.planner_panel", "ui.panels.view3d_panel",
                 "ui.panels.traffic_panel", "app.plan.runner", "app.points.lock",
                 "ui.panels.step_panel", "ui.panels.program_panel")
        teachpad.MainWindow = Probe
        sys.exit(teachpad.main(["--settings", sys.argv[1], "--host", "127.0.0.1", "--port", "9"]))
    """)
    env = {
        **os.environ,
        "QT_QPA_PLATFORM": "offscreen",
        **{f"XDG_{d}_HOME": str(tmp_path / d.lower()) for d in ("CONFIG", "DATA", "STATE", "CACHE")},
    }
    out = subprocess.run(
        [sys.executable, "-c", code, str(tmp_path / "teachpad.ini")],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
        env=env,
        check=False,
    )
    line = next((x for x in out.stdout.splitlines() if x.startswith("FIRST_PAINT ")), None)
    assert out.returncode == 0 and line is not None, out.stderr[-2000:]
    seen, built = json.loads(line[len("FIRST_PAINT ") :])
    assert seen == []  # none of HEAVY
    # Points, Planner, the link's worker (--host connects after), Step, Program
    assert built == [False, False, False, False, False]
