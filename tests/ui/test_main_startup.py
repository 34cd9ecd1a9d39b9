"""Start-up work that the first paint does not need runs after it (ui/main.py)."""

from __future__ import annotations

import textwrap
from pathlib import Path

from tests.ui.gui_child import run_gui_child


def test_nothing_heavy_is_imported_before_the_first_paint(tmp_path: Path) -> None:
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
    seen, built = run_gui_child(code, tmp_path, expect="FIRST_PAINT")["FIRST_PAINT"]
    assert seen == []  # none of HEAVY
    # Points, Planner, the link's worker (--host connects after), Step, Program
    assert built == [False, False, False, False, False]
