"""``teachpad``: the desktop teach pendant.

teachpad --sim                      the simulator, in its own process, on a free loopback port
teachpad --host H --port P [--unit U]   a real controller (Modbus TCP)
teachpad --lang zh_CN               language for this run (the menu remembers a choice)
teachpad --project FILE             open this project (default: the last one)
teachpad --sim --screenshot out.png --size 1400x900 [--tab planner]   render once connected, save, exit
"""

from __future__ import annotations

# First: PySide (imported by whoever imports this) reads the source of none of the modules below,
# ours nor the standard library's (ui/pyside_scan.py)
from ui.pyside_scan import skip_source_scan

skip_source_scan()

# Second: the methods dataclasses generate are compiled once, not at every start (ui/dataclass_code.py)
from ui.dataclass_code import DATACLASS_CODE

DATACLASS_CODE.install()

import argparse
import dataclasses
import os
import re
import sys
import threading
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from PySide6.QtCore import QObject, QTimer, Signal
from PySide6.QtWidgets import QApplication, QWidget

from ui.first_paint import AfterFirstPaint
from ui.gui_gc import GuiThreadCollector
from ui.startup_gc import StartupGcPause, gc_paused

with gc_paused(freeze=True):  # the window's modules: many objects made, none freed (ui/startup_gc.py)
    from app.connection import ConnectionSettings
    from app.link.ops import RunProgram
    from app.link.robot_link import RobotLink, wait_for_detached_threads
    from app.link.types import ConnectionState
    from app.models import Pose
    from app.protocol.enums import ProgramMotionMode
    from app.version import VersionAction
    from ui.i18n import LANGUAGE_NAMES, Translator
    from ui.main_window import TAB_NAMES, MainWindow
    from ui.settings import APPLICATION, ORGANIZATION, AppSettings
    from ui.text_fit import defer_other_languages, measure_other_languages

if TYPE_CHECKING:  # subprocess and queue: imported when a simulator is started (--sim)
    import subprocess

SCREENSHOT_SETTLE_MS = 1500  # after the first pose: let the plots fill and the panels paint
SCREENSHOT_TIMEOUT_MS = 20_000  # give up when no pose arrives
DEMO_PROGRAM = 1  # the simulator's "square 100 mm in XY"
SIM_START_TIMEOUT = 20.0  # s for the simulator process to say which port it listens on
SIM_START_LATEST_MS = 5000  # start the simulator then, even when the window has not painted yet
STARTUP_GC_LATEST_MS = 5000  # the GUI thread's garbage collection starts then, even with no paint yet
SIM_STOP_TIMEOUT = 10.0  # s for it to stop after its stdin closed, before it is terminated (a loaded
# machine needs seconds to wind an interpreter down; this waits after the window has closed)
THREADS_EXIT_WAIT = 5.0  # s at exit for a worker thread still stuck in a network call

# The simulator's process: ``teachpad-sim`` on a free port, told to stop when its stdin -- a
# pipe from this process -- ends (``--stop-with-stdin``). The pipe closes when the window closes
# (SimProcess.stop) and also when this process dies, however it dies: the simulator then stops
# by itself, the same way on every platform (no signal). In the venv it is this interpreter
# running ``app.sim.cli``; in the bundle (frozen: sys.executable is the bundle's ``teachpad``,
# which runs nothing but the GUI) it is the bundle's own ``teachpad-sim`` beside it.
SIM_ARGS = ("--host", "127.0.0.1", "--port", "0", "--no-stdin", "--stop-with-stdin")
_LISTENING = re.compile(r"listening on (?P<host>[^\s:]+):(?P<port>\d+)")


class SimProcess:
    """The simulated controller in a child process (like a real controller: its own GIL)."""

    def __init__(
        self, process: subprocess.Popen[str], host: str, port: int, reader: threading.Thread | None = None
    ) -> None:
        self.process = process
        self.host = host
        self.port = port
        self._reader = reader

    @staticmethod
    def command() -> tuple[list[str], dict[str, str]]:
        """The child's command line and environment (its stdin and stdout are pipes from us)."""
        env = dict(os.environ)
        env["PYTHONUNBUFFERED"] = "1"
        if getattr(sys, "frozen", False):  # the bundle (PyInstaller): its executables side by side
            suffix = ".exe" if sys.platform == "win32" else ""
            return [str(Path(sys.executable).with_name(f"teachpad-sim{suffix}")), *SIM_ARGS], env
        root = str(Path(__file__).resolve().parent.parent)  # where ``app`` is, installed or not
        env["PYTHONPATH"] = os.pathsep.join(p for p in (root, env.get("PYTHONPATH", "")) if p)
        return [sys.executable, "-m", "app.sim.cli", *SIM_ARGS], env

    @classmethod
    def start(cls, timeout: float = SIM_START_TIMEOUT) -> SimProcess:
        """Start ``teachpad-sim --port 0`` and wait until it says its port. Raises RuntimeError."""
        import queue
        import subprocess

        command, env = cls.command()
        # Windows: teachpad-sim is a console program; started from a pendant whose console is
        # hidden (the bundle's teachpad from Explorer) it would open a console window of its own
        no_window = getattr(subprocess, "CREATE_NO_WINDOW", 0) if sys.platform == "win32" else 0
        process = subprocess.Popen(
            command,
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
            env=env,
            creationflags=no_window,
        )
        lines: queue.Queue[str] = queue.Queue()

        def read_stdout() -> None:
            assert process.stdout is not None
            for line in process.stdout:  # drained to the end, so the child never blocks on it
                lines.put(line)
            lines.put("")

        reader = threading.Thread(target=read_stdout, name="sim-stdout", daemon=True)
        reader.start()
        deadline = time.monotonic() + timeout  # one deadline: a child that only chatters ends too
        try:
            while True:
                line = lines.get(timeout=max(0.0, deadline - time.monotonic()))
                if not line:
                    try:
                        code: int | str = process.wait(SIM_STOP_TIMEOUT)
                    except subprocess.TimeoutExpired:
                        code = "none yet"  # its output closed, it has not ended: stop() below
                    raise RuntimeError(f"the simulator exited at start (exit code {code})")
                found = _LISTENING.search(line)
                if found:
                    return cls(process, found["host"], int(found["port"]), reader)
        except queue.Empty:
            cls(process, "", 0, reader).stop()
            raise RuntimeError(f"the simulator did not start within {timeout:g} s") from None
        except BaseException:
            cls(process, "", 0, reader).stop()
            raise

    def stop(self, timeout: float = SIM_STOP_TIMEOUT) -> int:
        """Close its stdin (it stops by itself), terminate it if it does not; its exit code."""
        import subprocess

        process = self.process
        if process.stdin is not None and not process.stdin.closed:
            try:
                process.stdin.close()
            except OSError:
                pass
        try:
            code = process.wait(timeout)
        except subprocess.TimeoutExpired:
            process.terminate()
            try:
                code = process.wait(timeout)
            except subprocess.TimeoutExpired:
                process.kill()
                code = process.wait(timeout)  # SIGKILL: it ends (an error after that long says so)
        if self._reader is not None:
            self._reader.join(timeout)  # it ends at the pipe's end of file
        if process.stdout is not None:
            process.stdout.close()
        return code


class _SimStarter(QObject):
    """Starts the simulator process after the window's first paint, off the GUI thread.

    The child needs ~0.5 s (an interpreter, pymodbus) before it says its port: waiting for it
    before building the window made the first paint that much later. Here the window paints
    first; then a thread starts the child and waits for its port; ``started`` (GUI thread,
    queued) carries the SimProcess, or ``failed`` the reason.
    """

    started = Signal(object)
    failed = Signal(str)

    def __init__(self, window: QWidget) -> None:
        super().__init__()
        self.sim: SimProcess | None = None
        self._thread: threading.Thread | None = None
        self._closed = False
        self._lock = threading.Lock()
        AfterFirstPaint(window, self.start)  # after the paint, on the next turn of the loop
        # a window that is not painted (minimized, on another desktop) still gets its simulator
        QTimer.singleShot(SIM_START_LATEST_MS, self, self.start)

    def start(self) -> None:
        if self._thread is None and not self._closed:
            self._thread = threading.Thread(target=self._run, name="sim-start", daemon=True)
            self._thread.start()

    def _run(self) -> None:
        try:
            sim = SimProcess.start()
        except Exception as exc:  # any failure ends the wait for it (a window waiting for a pose)
            with self._lock:
                closed = self._closed
            if not closed:  # after close() nobody listens: a late exit would end someone else's loop
                self.failed.emit(str(exc) or type(exc).__name__)
            return
        with self._lock:
            closed = self._closed
            if not closed:
                self.sim = sim
        if closed:  # the window closed meanwhile
            sim.stop()
            return
        self.started.emit(sim)

    def close(self, timeout: float = SIM_START_TIMEOUT) -> None:
        """Stop the simulator (and one still starting: it is stopped as soon as it is up)."""
        with self._lock:
            self._closed = True
            sim, self.sim = self.sim, None
        if sim is not None:
            sim.stop()
        elif self._thread is not None:
            self._thread.join(timeout)


def _size(text: str) -> tuple[int, int]:
    try:
        width, height = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"size must look like 1400x900, got {text!r}") from None
    if width < 200 or height < 200:
        raise argparse.ArgumentTypeError("size must be at least 200x200")
    return width, height


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="teachpad", description="Teach pendant for Bochuang robot controllers"
    )
    parser.add_argument("--version", action=VersionAction)
    target = parser.add_mutually_exclusive_group()
    target.add_argument("--sim", action="store_true", help="start the built-in simulator and connect to it")
    target.add_argument("--host", help="controller address (Modbus TCP)")
    parser.add_argument("--port", type=int, default=502, help="Modbus TCP port (default 502)")
    parser.add_argument("--unit", type=int, help="Modbus unit id (default: the register profile's, 1)")
    parser.add_argument("--monitor-only", action="store_true", help="never write to the controller")
    parser.add_argument("--lang", choices=sorted(LANGUAGE_NAMES), help="user interface language")
    parser.add_argument("--poll-hz", type=float, help="pose/status poll rate (default 50)")
    parser.add_argument(
        "--settings",
        metavar="FILE",
        help="keep settings in this INI file (not the roles, the envelope nor the audit trail: "
        "they stay where Help > About says)",
    )
    parser.add_argument("--size", type=_size, metavar="WxH", help="window size, e.g. 1400x900")
    parser.add_argument(
        "--screenshot", metavar="PNG", help="save the window once connected with a pose, then exit"
    )
    parser.add_argument("--project", metavar="FILE", help="open this project (.teachpad.json) at start")
    parser.add_argument("--tab", choices=TAB_NAMES, help="work tab to show first")
    parser.add_argument(
        "--demo",
        action="store_true",
        help=f"with --sim: run the simulator's program {DEMO_PROGRAM} in a loop",
    )
    return parser


class _LoopExit:
    """``app.exit(code)`` for main()'s event loop, never lost and never stray. Qt drops an exit
    asked before ``app.exec()`` runs (exec starts afresh, and nothing would end it); here it is
    kept and ``exec`` returns it at once. One asked after exec returned (a signal queued late)
    is ignored: passed on, it would end the next event loop of this process instead."""

    def __init__(self, app: QApplication) -> None:
        self._app = app
        self._code: int | None = None
        self._running = False
        self._done = False

    def __call__(self, code: int) -> None:
        if self._done:
            return
        if self._code is None:
            self._code = code
        if self._running:
            self._app.exit(code)

    @property
    def ended(self) -> bool:
        """The loop has run and returned: what comes now is too late for it."""
        return self._done

    def exec(self) -> int:
        """Run the application's loop until an exit (or return the one asked already)."""
        if self._done:
            raise RuntimeError("the loop already ran")
        try:
            if self._code is not None:
                return self._code
            self._running = True
            return int(self._app.exec())
        finally:
            self._running = False
            self._done = True


class _Screenshot:
    """Saves the window once the link is up and a pose arrived, then quits the application."""

    def __init__(
        self,
        window: MainWindow,
        link: RobotLink,
        path: str,
        exit_: Callable[[int], None],
        starting_ms: int = 0,
    ) -> None:
        """``starting_ms``: the first wait for a pose also covers a simulator starting that long
        (:meth:`rearm` gives the full wait once it is up)."""
        self.window, self.link, self.path, self.exit = window, link, path, exit_
        self.connected = False
        self.scheduled = False
        self.ok = False
        link.connectionChanged.connect(self._on_connection)
        link.state.poseChanged.connect(self._on_pose)
        self.timeout = QTimer(window)
        self.timeout.setSingleShot(True)
        self.timeout.timeout.connect(self._give_up)
        self.timeout.start(SCREENSHOT_TIMEOUT_MS + starting_ms)
        self.settle = QTimer(window)
        self.settle.setSingleShot(True)
        self.settle.timeout.connect(self._save)

    def _on_connection(self, state: ConnectionState) -> None:
        self.connected = state.connected

    def _on_pose(self, _pose: Pose) -> None:
        if self.connected and not self.scheduled:
            self.scheduled = True
            self.settle.start(SCREENSHOT_SETTLE_MS)

    def rearm(self) -> None:
        """The link was just asked to connect (the simulator is up): the full wait for a pose."""
        if self.timeout.isActive():
            self.timeout.start(SCREENSHOT_TIMEOUT_MS)

    def _save(self) -> None:
        self.timeout.stop()
        try:  # the loop ends whatever happens here: its timeout is stopped
            self.ok = self.window.grab().save(self.path, "PNG")
            if not self.ok:
                print(f"teachpad: could not write {self.path}", file=sys.stderr)
        finally:
            self.exit(0 if self.ok else 1)

    def _give_up(self) -> None:
        self.settle.stop()
        try:
            print("teachpad: no pose from the controller, no screenshot taken", file=sys.stderr)
        finally:
            self.exit(1)

    def cancel(self) -> None:
        self.timeout.stop()
        self.settle.stop()


def _start_session(window: MainWindow, project: str | None, *, shot_run: bool) -> None:
    """After the first paint: the event log of earlier sessions (kept from now on), the project.
    A screenshot run shows its own events only and never stops on a question."""
    if not shot_run:
        window.event_log.keep_across_restarts()
    window.start_project(project, reopen_last=not shot_run, offer_recovery=not shot_run)


def main(argv: Sequence[str] | None = None) -> int:
    # No automatic garbage collection in this process while the window lives: from here until the
    # first paint none at all (ui/startup_gc.py), then only on the GUI thread (ui/gui_gc.py).
    # Automatic collection is back when main ends.
    startup_gc = StartupGcPause()
    try:
        return _main(argv, startup_gc)
    finally:
        startup_gc.resume()


def _main(argv: Sequence[str] | None, startup_gc: StartupGcPause) -> int:
    args_in = list(sys.argv[1:] if argv is None else argv)
    parser = build_parser()
    args, qt_args = parser.parse_known_args(args_in)
    if args.demo and not args.sim:
        parser.error("--demo needs --sim")

    app = _application(qt_args)
    settings = AppSettings.from_file(args.settings) if args.settings else AppSettings()
    translator = _translator(args.lang or settings.language)
    connection = _command_line_connection(args, settings)

    link = RobotLink(poll_hz=args.poll_hz or settings.poll_hz)
    defer_other_languages(translator.language)  # their fonts: measured after the first paint
    window = MainWindow(link, settings, translator)
    _arrange(window, args)
    exit_loop = _LoopExit(app)
    starting_ms = round(SIM_START_TIMEOUT * 1000) if args.sim else 0
    shot = _Screenshot(window, link, args.screenshot, exit_loop, starting_ms) if args.screenshot else None
    # the simulator starts after the first paint (see _SimStarter)
    starter = _sim_starter(window, link, args, exit_loop, shot) if args.sim else None

    collector = GuiThreadCollector(startup_gc, window)

    def after_first_paint() -> None:
        collector.start()
        measure_other_languages()  # the widths that fit every language (ui/text_fit.py)
        # The link's worker (pymodbus, the envelope) is made by the connection, after the paint.
        if connection is not None:
            link.connect_to(connection)
        # what this start compiled, for the next: after the connection is asked for (a first start's
        # write, synced, does not delay it), before a session's question can hold the loop
        DATACLASS_CODE.save()
        # A screenshot run never stops on a question: it opens only what it was given.
        _start_session(window, args.project, shot_run=bool(args.screenshot))

    AfterFirstPaint(window, after_first_paint)
    QTimer.singleShot(STARTUP_GC_LATEST_MS, collector, collector.start)  # a window never painted
    window.show()
    try:
        code = exit_loop.exec()
    finally:
        measure_other_languages(refit=False)  # (a window closed before its first paint)
        _close_down(window, link, translator, collector, shot=shot, starter=starter)
    return int(code)


def _application(qt_args: list[str]) -> QApplication:
    """The running QApplication (a test's), or a new one with Qt's own arguments."""
    existing = QApplication.instance()
    app = existing if isinstance(existing, QApplication) else QApplication([sys.argv[0], *qt_args])
    app.setOrganizationName(ORGANIZATION)
    app.setApplicationName(APPLICATION)
    return app


def _translator(language: str) -> Translator:
    """The GUI in ``language`` (English, said on stderr, when it has no translation)."""
    translator = Translator()
    if not translator.set_language(language):
        print(f"teachpad: no translation for {language}, using English", file=sys.stderr)
    return translator


def _command_line_connection(args: argparse.Namespace, settings: AppSettings) -> ConnectionSettings | None:
    """``--host`` (not with ``--sim``): the remembered connection to that host, remembered in
    turn; None: no connection asked for on the command line."""
    if not args.host or args.sim:
        return None
    remembered = settings.connection()  # with the register profile in force
    connection = dataclasses.replace(
        remembered,
        host=args.host,
        port=args.port,
        unit=remembered.unit if args.unit is None else args.unit,
        serial_port=None,
        framer="socket",
        monitor_only=args.monitor_only,
    )
    settings.save_connection(connection)
    return connection


def _arrange(window: MainWindow, args: argparse.Namespace) -> None:
    """``--size`` and ``--tab``."""
    if args.size:
        window.resize(*args.size)
    if args.tab:
        window.show_tab(args.tab)


def _sim_starter(
    window: MainWindow,
    link: RobotLink,
    args: argparse.Namespace,
    exit_loop: _LoopExit,
    shot: _Screenshot | None,
) -> _SimStarter:
    """``--sim``: the simulator started after the first paint; the link connects to it (and
    ``--demo`` runs the demo program), or the application ends when it cannot start."""
    starter = _SimStarter(window)

    def sim_started(sim: SimProcess) -> None:
        if exit_loop.ended:  # queued before the window closed: the starter stops that simulator
            return
        if shot is not None:
            shot.rearm()
        link.connect_to(
            ConnectionSettings(host=sim.host, port=sim.port, unit=1, monitor_only=args.monitor_only)
        )
        if args.demo:
            link.submit(RunProgram(DEMO_PROGRAM, ProgramMotionMode.CYCLE, 0, 100))

    def sim_failed(reason: str) -> None:
        print(f"teachpad: could not start the simulator: {reason}", file=sys.stderr)
        exit_loop(1)

    starter.started.connect(sim_started)
    starter.failed.connect(sim_failed)
    return starter


def _close_down(
    window: MainWindow,
    link: RobotLink,
    translator: Translator,
    collector: GuiThreadCollector,
    *,
    shot: _Screenshot | None,
    starter: _SimStarter | None,
) -> None:
    """After the event loop: the window closed (its state saved), the link shut down (any jog
    stopped), the simulator stopped, the worker threads awaited."""
    if shot is not None:
        shot.cancel()
    # saves the window state and shuts the link down (stops any jog); a screenshot run's
    # close is not an operator's: no "Save changes?" may block it
    if shot is not None:
        window.close_unattended()
    else:
        window.close()
    link.shutdown()
    if starter is not None:
        starter.close()
    if not wait_for_detached_threads(THREADS_EXIT_WAIT):
        print("teachpad: the link to the controller did not close in time", file=sys.stderr)
    DATACLASS_CODE.save()  # what the run compiled after its first paint (the worker's), if anything
    translator.uninstall()
    collector.stop()  # automatic collection is back when main() ends
    window.deleteLater()


if __name__ == "__main__":
    sys.exit(main())
