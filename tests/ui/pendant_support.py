"""Fixtures and helpers shared by the pendant's GUI/worker tests (imported explicitly)."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any

import pytest
from pytestqt.exceptions import TimeoutError as WaitTimeout

from app import timing
from app.connection import ConnectionSettings
from app.link.ops import Step
from app.link.robot_link import RobotLink
from app.link.types import ConnectionState, LinkState, StepFrame
from app.models import CommandResult
from app.protocol.codec import WordOrder, registers_to_float

SIGNAL_TIMEOUT_MS = 5000
#: A test's setup waits (a step, a teach) this long: a loaded machine is slow there, not wrong
SETUP_TIMEOUT_MS = 4 * SIGNAL_TIMEOUT_MS
# The offscreen platform warns when a top-level window gets size constraints; not our concern.
QT_LOG_IGNORE = ("This plugin does not support propagateSizeHints",)
# Roomy timeouts (s), as tests/link/harness.py: the simulator runs in the test process, and a
# loaded machine (coverage, a CI neighbour) can hold an answer past the product's 0.15 s poll
# timeout; the product then rightly says "not answering" and a plan run or an upload ends -- a
# test about something else fails (CI, stop 18: a plan run never started). Tests about silence
# pass ``poll_timeout=None`` (the product's figure) or their own short timeouts.
REQUEST_TIMEOUT = 1.0
POLL_TIMEOUT = 1.0


@pytest.fixture(name="fast_reconnect")
def fast_reconnect_fixture(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(timing, "RECONNECT_BACKOFF", (0.05, 0.1, 0.2))


@pytest.fixture(name="link")
def link_fixture(qtbot: Any, fast_reconnect: None) -> Iterator[RobotLink]:
    """A RobotLink (worker thread running), shut down after the test. The restart canary is off
    here, so tests can say "nothing was written"; ``canary_link`` has it on (GV99, the default)."""
    robot_link = RobotLink(poll_hz=timing.POLL_HZ_DEFAULT, canary_gv=None)
    try:
        yield robot_link
    finally:
        robot_link.shutdown()
        assert not robot_link.is_running


@pytest.fixture(name="canary_link")
def canary_link_fixture(
    qtbot: Any, fast_reconnect: None, monkeypatch: pytest.MonkeyPatch
) -> Iterator[RobotLink]:
    """A RobotLink with the restart canary on its default GV, checked every 0.1 s."""
    monkeypatch.setattr(timing, "CLOCK_POLL_PERIOD", 0.1)
    robot_link = RobotLink(poll_hz=timing.POLL_HZ_DEFAULT)
    try:
        yield robot_link
    finally:
        robot_link.shutdown()
        assert not robot_link.is_running


def is_state(state: LinkState) -> Callable[[ConnectionState], bool]:
    return lambda s: s.state is state


def connection_settings(sim: Any, **overrides: Any) -> ConnectionSettings:
    values: dict[str, Any] = {
        "host": "127.0.0.1",
        "port": sim.port,
        "timeout": REQUEST_TIMEOUT,
        "poll_timeout": POLL_TIMEOUT,
    }
    values.update(overrides)
    return ConnectionSettings(**values)


def connect(qtbot: Any, robot_link: RobotLink, sim: Any, **overrides: Any) -> ConnectionSettings:
    """Connect ``robot_link`` to ``sim`` and wait until the link is up."""
    settings = connection_settings(sim, **overrides)
    with qtbot.waitSignal(
        robot_link.connectionChanged, check_params_cb=is_state(LinkState.CONNECTED), timeout=SIGNAL_TIMEOUT_MS
    ):
        robot_link.connect_to(settings)
    return settings


def gv_writes(sim: Any, gv: int) -> list[tuple[int, float]]:
    """(index in ``sim.writes``, value) of every write that covered both registers of GVn."""
    low = 2 * gv
    out: list[tuple[int, float]] = []
    for index, write in enumerate(list(sim.writes)):
        start = low - write.address
        if start >= 0 and start + 2 <= len(write.values):
            regs = write.values[start : start + 2]
            out.append((index, registers_to_float(regs, WordOrder.LOW_FIRST)))
    return out


def ratio_writes(sim: Any) -> list[float]:
    """Every value written to GV203 (the teach speed ratio), in order."""
    return [value for _, value in gv_writes(sim, 203)]


def register_writes(sim: Any, address: int) -> list[tuple[int, int]]:
    """(index in ``sim.writes``, value) of the writes to one control register (440..445)."""
    out: list[tuple[int, int]] = []
    for index, write in enumerate(list(sim.writes)):
        if write.address <= address < write.address + len(write.values):
            out.append((index, write.values[address - write.address]))
    return out


def step_by_link(qtbot: Any, robot_link: RobotLink, dx: float, *, speed: float = 200.0) -> None:
    """The arm stepped ``dx`` mm along X (base frame) by ``robot_link`` itself, to its outcome.

    Not by a helper client: to the link that is another Modbus master, and a command of the link's
    during which its poller *notices* the helper's earlier writes is rightly "outcome unknown"
    (issue 19; the notice may come late on a loaded machine). Tests that taught a point right after
    a helper's step failed so beside busy loops ("Teach P1 failed: ... the outcome is unknown")."""
    pending = robot_link.track(
        robot_link.submit(Step(StepFrame.BASE, (dx, 0.0, 0.0, 0.0, 0.0, 0.0), speed=speed))
    )
    outcome: list[object] = []
    pending.finished.connect(outcome.append)
    pending.failed.connect(outcome.append)
    qtbot.waitUntil(lambda: bool(outcome), timeout=SETUP_TIMEOUT_MS)
    assert isinstance(outcome[0], CommandResult) and outcome[0].ok, outcome[0]


def teach_here(qtbot: Any, point_sync: Any) -> int:
    """Teach the next point where the arm is (``PointSyncController.teach``) and wait until it is
    taught; a teach that fails fails the test with what the points panel said."""
    said: list[str] = []
    taught: list[int] = []
    point_sync.statusMessage.connect(lambda text, _level: said.append(text))
    point_sync.pointTaught.connect(taught.append)
    assert point_sync.teach() is not None, said
    try:
        qtbot.waitUntil(lambda: bool(taught), timeout=SETUP_TIMEOUT_MS)
    except WaitTimeout:
        pytest.fail(f"the point was not taught; the points panel said: {said}")
    return taught[0]


def jogging(sim: Any) -> bool:
    state = sim.state()
    return bool(state.teach_enabled and state.jogging and state.teach_ratio > 0)


@pytest.fixture(name="app_settings")
def app_settings_fixture(tmp_path: Any) -> Any:
    """Settings in a temporary INI file: tests never touch the user's settings."""
    from ui.settings import AppSettings

    return AppSettings.from_file(tmp_path / "teachpad.ini")


@pytest.fixture(name="translator")
def translator_fixture(qapp: Any) -> Iterator[Any]:
    from ui.i18n import Translator

    translator = Translator()
    try:
        yield translator
    finally:
        translator.uninstall()  # the next test starts in English


class FakeProjectDialogs:
    """Answers the project's questions without showing anything; records what was asked."""

    def __init__(self) -> None:
        self.save_choice = "discard"  # "save" | "discard" | "cancel"
        self.recover = False
        self.open_answer: str | None = None
        self.save_answer: str | None = None
        self.asked: list[str] = []
        self.errors: list[tuple[str, str]] = []

    def open_path(self, title: str, filters: str) -> str | None:
        self.asked.append("open")
        return self.open_answer

    def save_path(self, title: str, filters: str, suggested: str) -> str | None:
        self.asked.append("save path")
        return self.save_answer

    def error(self, title: str, text: str) -> None:
        self.errors.append((title, text))

    def ask_save_changes(self, name: str) -> str:
        self.asked.append("save changes")
        return self.save_choice

    def ask_recover(self, autosave: Any, project_path: Any) -> bool:
        self.asked.append("recover")
        return self.recover

    def ask_import_mode(self) -> Any:
        return None


@pytest.fixture(name="project_dialogs")
def project_dialogs_fixture() -> FakeProjectDialogs:
    return FakeProjectDialogs()


@pytest.fixture(name="window")
def window_fixture(
    qtbot: Any,
    link: RobotLink,
    app_settings: Any,
    translator: Any,
    project_dialogs: FakeProjectDialogs,
    tmp_path: Any,
) -> Any:
    """The main window on ``link``, shown and active; confirmations answer yes (and "stop
    first?" stop), project questions go to ``project_dialogs``, autosaves to ``tmp_path``."""
    from ui.dialogs.stop_first import StopFirst
    from ui.main_window import MainWindow

    main_window = MainWindow(
        link, app_settings, translator, project_dialogs=project_dialogs, autosave_dir=tmp_path / "autosave"
    )
    main_window.confirm = lambda _title, _text: True
    # "stop first?" (Disconnect, the close, with motion under way): stop, as the dialog's default
    main_window.link_guard.ask = lambda _question: StopFirst.STOP
    qtbot.addWidget(main_window)
    main_window.show()
    qtbot.waitExposed(main_window)
    main_window.activateWindow()
    qtbot.waitActive(main_window)
    # as once painted: a fresh install's envelope saved and audited (ui/controllers/safety.py)
    qtbot.waitUntil(lambda: not main_window.safety_menu.safety.fresh_unsaved, timeout=5000)
    return main_window


TEST_PASSWORD = "cell-42"
CHEAP_SCRYPT = 2**4  # tests only: the real cost is 2**14


def log_in(window: Any, role: Any) -> None:
    """Log ``window`` in as ``role`` (an :class:`app.safety.roles.Role`), its password set first."""
    from app.safety.roles import Role

    safety = window.safety_menu.safety
    store = safety.session.store
    store.scrypt_n = CHEAP_SCRYPT
    store.set_password(role, TEST_PASSWORD, by=Role.ADMINISTRATOR)
    safety.login(role, TEST_PASSWORD)
