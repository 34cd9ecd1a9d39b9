"""Start-up margin (issue 10): what the first paint does not need waits for after it, and the
garbage collector is paused until then (ui/startup_gc.py); from then on the GUI thread collects
(ui/gui_gc.py, issue 18)."""

from __future__ import annotations

import gc
import json
import sys
import textwrap
from typing import Any

import pytest

from app.connection import ConnectionSettings
from app.link.transport import Transport
from app.safety.location import ENVELOPE_NAME
from app.safety.profile import SafetyProfile, save_profile
from app.view3d.profile import default_profile
from tests.cli.ctrl_c import untraced_env
from tests.ui.gui_child import run_gui_child
from ui.panels.view3d_robot import RobotModelSource
from ui.startup_gc import StartupGcPause, gc_paused

# Imported by their first use, after the window's first paint (not by the window's modules)
DEFERRED = (
    "socket",  # the transport's byte streams: when a Transport is made
    "app.link.streams",
    "ui.panels.monitor_plots",  # the monitor's plots: built after the first paint
    "app.plan.checks",  # the first plan checked (IssueKind: app/plan/issue_kind.py)
    "app.view3d.profile",  # robot profiles: the first one read (3D view, planner checks)
    "importlib.resources",  # the shipped robot profile: read by its first use
    "ui.keypad",  # the on-screen keypad: touch mode on, or a field that has one
    "hashlib",  # passwords (OpenSSL): the first one set or checked
    "app.points.diff",  # File → Compare with…: the first comparison
    "app.points.csv_io",  # a points CSV or a project: the first file read or written
    "ui.controllers.new_point",  # the first point added by hand
    "app.watchlist.plan",  # the watch list's reads: the worker's, once connected
    "statistics",  # the measured-stopping report's medians: the first report
)
# Imported before ui/main.py enters TeachPad's modules in PySide's feature table (ui/pyside_scan.py):
# the only ones of TeachPad whose source PySide reads
SCANNED_BEFORE = {"ui", "ui.pyside_scan"}
# and of the standard library's top-level modules (the rest are entered with ours), the ones
# ui/main.py and ui/pyside_scan.py import first, and io (importlib's loader, reading that file)
STANDARD_SCANNED_BEFORE = {"__future__", "io", "sys"}
# Qt classes made ready (shiboken) by their first use: the dialogs, when one is shown
# (PySide6 makes a class when it is first looked up: its module's namespace holds only those made)
DEFERRED_QT = ("QDialog", "QMessageBox", "QFileDialog", "QInputDialog")


# An install's first start reads the robot model (app.view3d.profile, the shipped file) before its
# first paint, to make its safety envelope (~10 ms), which every later start reads instead; the
# envelope is saved and audited (hashlib) after the paint (tests/ui/controllers/test_fresh_envelope.py)
READ_BY_A_FIRST_INSTALL = ("app.view3d.profile", "importlib.resources")


@pytest.mark.parametrize("first_install", [False, True], ids=["a later start", "an install's first"])
def test_deferred_modules_wait_and_the_collector_is_paused_until_the_first_paint(
    tmp_path: Any, first_install: bool
) -> None:
    if not first_install:
        (tmp_path / "config" / "teachpad").mkdir(parents=True)  # the child's XDG_CONFIG_HOME (below)
        save_profile(tmp_path / "config" / "teachpad" / ENVELOPE_NAME, SafetyProfile())
    deferred = tuple(m for m in DEFERRED if not (first_install and m in READ_BY_A_FIRST_INSTALL))
    code = textwrap.dedent("""
        import gc, json, sys
        import PySide6.QtWidgets
        from PySide6.QtCore import QTimer
        from PySide6.QtWidgets import QApplication

        feature = sys.modules["shibokensupport.feature"]  # PySide's source scan, noted
        scanned, scan = [], feature._mod_uses_pyside
        feature._mod_uses_pyside = lambda module: scanned.append(module.__name__) or scan(module)
        import ui.main as teachpad

        DEFERRED, DEFERRED_QT = json.loads(sys.argv[2])
        after_import = gc.isenabled()  # the pause over the imports has ended with them
        frozen_after_import = gc.get_freeze_count() > 0  # and froze what they made
        own_scanned = sorted(m for m in scanned if m.split(".")[0] in ("app", "ui"))
        standard_scanned = sorted(m for m in scanned if m in sys.stdlib_module_names)

        class Probe(teachpad.MainWindow):
            def paintEvent(self, event):
                if not hasattr(self, "seen"):
                    self.seen = sorted(m for m in DEFERRED if m in sys.modules)
                    self.seen += sorted(c for c in DEFERRED_QT if c in vars(PySide6.QtWidgets))
                    self.gc_at_paint = gc.isenabled()
                    self.languages_at_paint = sorted(sys.modules["ui.text_fit"]._translators)
                    QTimer.singleShot(50, self._report)
                super().paintEvent(event)

            def _report(self):
                print("STARTUP " + json.dumps([self.seen, after_import, self.gc_at_paint, gc.isenabled(),
                                               gc.get_freeze_count() > 0]), flush=True)
                imported = [frozen_after_import, own_scanned, standard_scanned]
                print("IMPORT " + json.dumps(imported), flush=True)
                languages = [self.languages_at_paint, sorted(sys.modules["ui.text_fit"]._translators)]
                print("LANGUAGES " + json.dumps(languages), flush=True)
                QApplication.instance().exit(0)

        teachpad.MainWindow = Probe
        code = teachpad.main(["--settings", sys.argv[1]])
        print("AFTER_MAIN " + json.dumps(gc.isenabled()), flush=True)
        sys.exit(code)
    """)
    # untraced: coverage's tracer, started in every child by `make test`, imports socket and
    # hashlib itself (this test failed under coverage: ['hashlib', 'socket'] before the paint)
    lines = run_gui_child(
        code, tmp_path, json.dumps([deferred, DEFERRED_QT]), env=untraced_env(), expect="STARTUP"
    )
    seen, after_import, gc_at_paint, gc_after_paint, frozen_after_paint = lines["STARTUP"]
    assert seen == []  # none of DEFERRED (nor of DEFERRED_QT) before the first paint
    assert after_import is True  # importing ui.main leaves the collector as it found it
    assert gc_at_paint is False  # paused while the window was built and painted first
    # after it, automatic collection stays off: the GUI thread collects (ui/gui_gc.py), the
    # objects of the start-up frozen
    assert gc_after_paint is False and frozen_after_paint is True
    assert lines["AFTER_MAIN"] is True
    frozen_after_import, own_scanned, standard_scanned = lines["IMPORT"]
    assert frozen_after_import is True  # the modules' objects are not walked by the next collection
    # PySide read the source of none of the window's modules (ui/pyside_scan.py; it read ~140)
    assert set(own_scanned) <= SCANNED_BEFORE, own_scanned
    # nor of the standard modules it imports after Qt (~55 read before: typing, inspect, argparse, ...)
    assert set(standard_scanned) <= STANDARD_SCANNED_BEFORE, standard_scanned
    # an English window's widths for Chinese (its fonts) are measured after the paint (ui/text_fit.py)
    assert lines["LANGUAGES"] == [[], ["zh_CN"]]


def test_a_pause_resumes_once_and_only_a_collector_that_was_on() -> None:
    assert gc.isenabled()
    pause = StartupGcPause()
    assert not gc.isenabled()
    pause.resume()
    assert gc.isenabled()
    gc.disable()
    try:
        pause.resume()  # a second resume does nothing
        assert not gc.isenabled()
        StartupGcPause().resume()  # paused while off: stays off
        assert not gc.isenabled()
    finally:
        gc.enable()


def test_gc_paused_resumes_after_an_error() -> None:
    with pytest.raises(RuntimeError), gc_paused():
        assert not gc.isenabled()
        raise RuntimeError("boom")
    assert gc.isenabled()


def test_the_default_robot_profile_is_read_by_its_first_use() -> None:
    robot = RobotModelSource()
    assert robot._default is None  # not read at construction (start-up)
    assert robot.profile == default_profile()
    assert robot.default is robot.profile
    assert robot.restore()  # nothing remembered: the default stays
    robot.use_default()
    assert robot.profile == default_profile()


def test_a_transport_picks_its_stream_when_made() -> None:
    tcp = Transport(ConnectionSettings(host="127.0.0.1", port=9))
    assert type(tcp._stream).__name__ == "TcpStream"
    assert "app.link.streams" in sys.modules
    serial = Transport(ConnectionSettings(serial_port="/dev/null-teachpad", framer="rtu"))
    assert type(serial._stream).__name__ == "SerialStream"
