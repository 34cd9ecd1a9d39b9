"""A number is shown whole or visibly not at all (issue 18): the monitor's readouts and the pose
strip, against the simulator, at every size the README names and in both languages.

Two values from the issue: an external axis at -1000 (the CLI prints ``J7 -1000.000``; the
small readouts used to cut it to "1000.000") and a joint that reads as -6.1e29 when the host
reads the other word order (it used to read "1200.000"). Asserted on the text the readouts draw
(``shown_text()``, the text their paint event draws; a pose strip value is a QLabel, whose text
is what it draws): the whole value, or ``######`` with the whole value in the tooltip, and
never wider than the room the widget has.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from typing import Any

import pytest
from PySide6.QtCore import QCoreApplication, QEvent, QObject
from PySide6.QtWidgets import QApplication, QLabel, QMainWindow
from pytestqt.exceptions import TimeoutError as WaitTimeout

from app.models import Pose
from app.protocol.codec import WordOrder, float_to_registers, registers_to_float
from tests.ui.fake_link import FakeLink
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    SIGNAL_TIMEOUT_MS,
    app_settings_fixture,
    connect,
    fast_reconnect_fixture,
    link_fixture,
    project_dialogs_fixture,
    translator_fixture,
)
from ui.dialogs.stop_first import StopFirst
from ui.main_window import TAB_MONITOR, MainWindow
from ui.panels.monitor_panel import MonitorPanel
from ui.panels.pose_strip import PoseStrip
from ui.widgets.number_text import OVERFLOW
from ui.widgets_common import NumericReadout

pytestmark = [pytest.mark.timeout(60), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]

SIZES = ((1024, 768), (1280, 800), (1920, 1080))
LANGUAGES = ("en", "zh_CN")
FAR_EXTERNAL = -1000.0  # J7 (GV212) at the end of the simulator's external-axis range
GARBLED = -6.1e29  # what J2 reads as with the other word order


def _float32(value: float) -> float:
    return registers_to_float(float_to_registers(value))


def held_for(read_as: float) -> float:
    """The value the simulator (low word first) must hold for a host that reads high word first
    to read ``read_as``."""
    return registers_to_float(float_to_registers(read_as, WordOrder.HIGH_FIRST), WordOrder.LOW_FIRST)


def settle() -> None:
    for _ in range(3):
        QCoreApplication.sendPostedEvents()
        QApplication.processEvents()


@pytest.fixture(name="make_window")
def make_window_fixture(
    qtbot: Any, link: Any, app_settings: Any, translator: Any, project_dialogs: Any, tmp_path: Any
) -> Iterator[Any]:
    def make(language: str, size: tuple[int, int]) -> MainWindow:
        assert translator.set_language(language)
        window = MainWindow(
            link,
            app_settings,
            translator,
            project_dialogs=project_dialogs,
            autosave_dir=tmp_path / "autosave",
        )
        qtbot.addWidget(window)
        window.link_guard.ask = lambda _question: StopFirst.STOP  # the close asks when the arm moved
        window.resize(*size)
        window.show()
        qtbot.waitExposed(window)
        window.show_tab(TAB_MONITOR)
        settle()
        return window

    yield make


def readout_problem(readout: NumericReadout) -> str | None:
    """Why ``readout`` does not show its value whole or visibly not at all (None: it does)."""
    whole, shown = readout.text(), readout.shown_text()
    number = readout._number
    room = number.width()
    if number.fontMetrics().horizontalAdvance(shown) > room:
        return f"{readout.caption()} draws {shown!r}, wider than its {room} px"
    if shown == whole:
        return None
    if set(shown) != {"#"}:
        return f"{readout.caption()} draws {shown!r} for {whole!r}"
    if whole not in number.toolTip():
        return f"{readout.caption()} hides {whole!r} without it in the tooltip ({number.toolTip()!r})"
    return None


def strip_problem(name: str, label: QLabel, value: float) -> str | None:
    whole = f"{value:.2f}"
    shown = label.text()
    if label.fontMetrics().horizontalAdvance(shown) > label.contentsRect().width():
        return f"pose strip {name} draws {shown!r}, wider than its {label.contentsRect().width()} px"
    if shown == whole or (whole == "-0.00" and shown == "0.00"):
        return None
    if shown != OVERFLOW:
        return f"pose strip {name} draws {shown!r} for {whole!r}"
    if whole not in label.toolTip():
        return f"pose strip {name} hides {whole!r} without it in the tooltip"
    return None


def problems(window: MainWindow) -> list[str]:
    found = [readout_problem(r) for r in window.monitor_panel.readouts.values() if r.isVisible()]
    pose = window.link.state.pose
    assert pose is not None
    strip = window.pose_strip
    found += [strip_problem(n, strip.values[n], v) for n, v in zip("XYZABC", pose.xyzabc, strict=True)]
    return [p for p in found if p is not None]


def assert_whole_or_hidden(qtbot: Any, window: MainWindow) -> None:
    """Every readout draws its value whole or ``######`` (the pose strip draws in the display
    clock's frames: the latest pose within a frame or two)."""
    try:
        qtbot.waitUntil(lambda: not problems(window), timeout=SIGNAL_TIMEOUT_MS)
    except WaitTimeout:  # say which readout, in words
        found = problems(window)
        raise AssertionError("\n".join(found)) from None


@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
@pytest.mark.parametrize("language", LANGUAGES)
def test_readouts_show_a_number_whole_or_not_at_all(
    qtbot: Any, sim: Any, make_window: Any, language: str, size: tuple[int, int]
) -> None:
    sim.set_joint(7, FAR_EXTERNAL)
    sim.set_joint(2, held_for(GARBLED))  # read right: a nonsense angle, shown whole or hidden
    window = make_window(language, size)
    readouts = window.monitor_panel.readouts
    connect(qtbot, window.link, sim)
    qtbot.waitUntil(lambda: readouts["J7"].value == FAR_EXTERNAL, timeout=SIGNAL_TIMEOUT_MS)
    settle()
    assert_whole_or_hidden(qtbot, window)
    if size != SIZES[0]:  # room is kept for it where the README promises the layout
        assert readouts["J7"].shown_text() == "-1000.000"

    # the host reads the other word order: J2 reads -6.1e29, the pose is garbage too
    connect(qtbot, window.link, sim, word_order=WordOrder.HIGH_FIRST)
    garbled = _float32(GARBLED)
    qtbot.waitUntil(lambda: readouts["J2"].value == garbled, timeout=SIGNAL_TIMEOUT_MS)
    settle()
    assert_whole_or_hidden(qtbot, window)
    j2 = readouts["J2"]
    assert j2.shown_text() == OVERFLOW
    assert f"{garbled:.3f}" in j2._number.toolTip()


class _LayoutRequests(QObject):
    def __init__(self, watched: QObject) -> None:
        super().__init__()
        self.count = 0
        watched.installEventFilter(self)

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        if event.type() == QEvent.Type.LayoutRequest:
            self.count += 1
        return False


@pytest.fixture(name="fake_link")
def fake_link_fixture(qtbot: Any) -> Iterator[FakeLink]:
    fake = FakeLink(connected=True)
    yield fake
    fake.set_connected(False)  # stops the state's freshness timer


def test_values_that_come_and_go_past_their_room_do_not_relayout_the_window(
    qtbot: Any, fake_link: FakeLink
) -> None:
    """While values stream, a value that does not fit (and its tooltip) repaints the readout only."""
    window = QMainWindow()
    qtbot.addWidget(window)
    monitor = MonitorPanel()
    window.setCentralWidget(monitor)
    strip = PoseStrip(window)
    window.setMenuWidget(strip)
    state = fake_link.state
    monitor.bind(state)
    strip.bind(state)
    window.resize(1280, 800)
    window.show()
    qtbot.waitExposed(window)
    joints = (0.0, 20.0, 20.0, 0.0, 50.0, 0.0)

    def stream(i: int, *, past: bool = True) -> None:
        x = _float32(GARBLED) if past and i % 3 == 2 else 500.0 + i
        y = -12345.678 if past and i % 3 == 1 else 1.0
        state.set_pose(Pose(x, y, 300.0, 180.0, 0.0, 90.0, (FAR_EXTERNAL,) * 5, joints))
        state.note_good_poll(time.monotonic())
        monitor.refresh()
        QApplication.processEvents()

    for i in range(3):  # the first values, the plots built after the first paint
        stream(i, past=False)
        qtbot.wait(50)  # a re-layout climbs one level per turn of the event loop: let it settle
    relayouts = _LayoutRequests(window)
    for i in range(3, 33):
        stream(i)
    # the strip draws in the display clock's frames: the last pose (X garbled) in the next one
    qtbot.waitUntil(lambda: strip.values["X"].text() == OVERFLOW, timeout=SIGNAL_TIMEOUT_MS)
    assert relayouts.count == 0
    assert monitor.readouts["X"].shown_text() == OVERFLOW
    assert strip.values["Y"].toolTip() == ""  # fits again: its tooltip went with the overflow
    assert monitor.readouts["J7"].shown_text() == "-1000.000"


@pytest.mark.parametrize(("caption", "unit"), [("X", "mm"), ("C", "°"), ("J4", "°"), ("J7", "mm")])
def test_a_readout_needs_no_more_than_the_width_the_monitor_is_told(
    qtbot: Any, caption: str, unit: str
) -> None:
    """The monitor picks the largest point size whose ``width_for`` fits a column (issue 20): a
    readout that really needs more than that is squeezed by its layout and its digits run into
    the unit ("_Digits and QLabel 'mm' overlap by 1×32 px" under Noto Sans Mono). At every size,
    in the font in use, the width told covers the width the layout gives it at least."""
    readout = NumericReadout(caption, unit)
    qtbot.addWidget(readout)
    readout.show()
    short = []
    for tenths in range(80, 320, 5):
        points = tenths / 10
        readout.set_point_size(points)
        if readout.minimumSizeHint().width() > readout.width_for(points):
            short.append(
                f"{points} pt: needs {readout.minimumSizeHint().width()}, told {readout.width_for(points)}"
            )
    assert not short, "\n".join(short)
