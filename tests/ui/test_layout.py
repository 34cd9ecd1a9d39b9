"""The layout check: every panel and dialog, in English and Chinese, at 1280×800 and 1920×1080.

On every tab (and the states that change a layout: jog frames, the step panel's external
axes, the points banner and upload progress, the planner after a stop) no visible text is
clipped, no two visible siblings overlap, motion buttons are tall enough (``layout_audit``);
connected, again with the alarm banner up (an emergency stop raised at the simulator).
``make test-fonts`` (``tests/fonts/run.py``) runs it again under three font sets, on more
screens (``TEACHPAD_LAYOUT_SCREENS``) and at 125 % and 150 % (``QT_SCALE_FACTOR``).

Chinese text is measured with the font Qt really uses. Where no CJK font is installed (the
DejaVu-only font set, a machine without one), Qt measures missing glyphs as narrow boxes, so a clipped
Chinese text cannot be told from a fitting one: the text check is skipped for zh_CN there,
and only overlap and sizes are checked (they do not depend on glyph widths being right).
"""

from __future__ import annotations

import os
import re
from collections.abc import Callable, Iterable, Iterator
from typing import Any

import pytest
from PySide6.QtCore import QCoreApplication, QPoint, QSize, Qt
from PySide6.QtGui import QFontDatabase
from PySide6.QtWidgets import QApplication, QLabel, QMessageBox, QWidget

from app.protocol.enums import Alarm, TeachFrame
from tests.ui.layout_audit import clipped_texts, overlapping_siblings, small_motion_buttons
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
from ui.dialogs.connection_dialog import ConnectionDialog
from ui.keypad import KeypadDialog
from ui.main_window import (
    TAB_MONITOR,
    TAB_PLANNER,
    TAB_POINTS,
    MainWindow,
)
from ui.touch import MOTION_MIN_HEIGHT, TOUCH_MOTION_HEIGHT, motion_height
from ui.window_docks import DOCK_MIN_ROWS, STATUS_DOCK_WIDTH

pytestmark = [pytest.mark.timeout(60), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]

# Known problems in panels owned elsewhere, each with its reason; the check stays strict for the
# rest. Remove an entry when its panel is fixed (an entry that no longer matches fails the test).
KNOWN_ISSUES: dict[str, str] = {}
SCREENS = ((1280, 800), (1920, 1080))
# Decided (issue 20): the README promises the layout from 1280×800 device-independent pixels up,
# the size that holds under every font set (tests/fonts). Under it (1024×768, or 1920×1080 at
# 150 % = 1280×720) the window still opens down to MIN_SIZE but squeezes or scrolls parts: the
# control column, the planner and the status dock need ~850 + 320 px across, and the work tabs
# ~480 px of height under Noto's taller lines.
PROMISED_MIN = (1280, 800)


def screens() -> tuple[tuple[int, int], ...]:
    """The screen sizes to check: ``TEACHPAD_LAYOUT_SCREENS`` ("1024x768,1280x800", set by the
    font-set run, ``tests/fonts/run.py``) or :data:`SCREENS`."""
    listed = os.environ.get("TEACHPAD_LAYOUT_SCREENS", "")
    if not listed:
        return SCREENS
    return tuple((int(w), int(h)) for w, h in (size.split("x") for size in listed.split(",")))


def window_sizes() -> tuple[tuple[int, int], ...]:
    """The window filling each screen, in Qt's device-independent pixels: a screen's pixels over
    ``QT_SCALE_FACTOR`` (1920×1080 at 150 % is a 1280×720 window). Windows under the size the
    README promises the layout at (:data:`PROMISED_MIN`) are not checked."""
    scale = float(os.environ.get("QT_SCALE_FACTOR", "") or 1.0)
    sizes = ((int(w / scale), int(h / scale)) for w, h in screens())
    return tuple(s for s in sizes if s[0] >= PROMISED_MIN[0] and s[1] >= PROMISED_MIN[1])


SIZES = window_sizes()
LAPTOP = (1280, 800)  # the touch, reduced-speed and joint jog checks
LANGUAGES = ("en", "zh_CN")
STOP_MESSAGE = "Stopped: the operator pressed STOP during segment 3 of 12 (the controller reported ESTOP)"


def cjk_font_installed() -> bool:
    return bool(QFontDatabase.families(QFontDatabase.WritingSystem.SimplifiedChinese))


def settle() -> None:
    """Let the posted layout requests run (no time passes: only queued events)."""
    for _ in range(3):
        QCoreApplication.sendPostedEvents()
        QApplication.processEvents()


def problems(root: QWidget, language: str, touch: bool) -> list[str]:
    found = overlapping_siblings(root) + small_motion_buttons(root, motion_height(touch))
    if language == "en" or cjk_font_installed():
        found += clipped_texts(root)
    return found


@pytest.fixture(name="make_window")
def make_window_fixture(
    qtbot: Any, link: Any, app_settings: Any, translator: Any, project_dialogs: Any, tmp_path: Any, sim: Any
) -> Callable[..., MainWindow]:
    def make(
        language: str, size: tuple[int, int], *, touch: bool = False, connected: bool = True
    ) -> MainWindow:
        assert translator.set_language(language)
        app_settings.touch_mode = touch
        window = MainWindow(
            link,
            app_settings,
            translator,
            project_dialogs=project_dialogs,
            autosave_dir=tmp_path / "autosave",
        )
        window.confirm = lambda _title, _text: True
        qtbot.addWidget(window)
        window.resize(*size)
        window.show()
        qtbot.waitExposed(window)
        settle()
        window.resizeDocks([window.status_dock], [STATUS_DOCK_WIDTH], Qt.Orientation.Horizontal)
        settle()
        assert (window.width(), window.height()) == size
        if connected:  # the status panel shows real values (wider), the motion banner goes
            connect_window(qtbot, window, sim)
        return window

    return make


def connect_window(qtbot: Any, window: MainWindow, sim: Any) -> None:
    connect(qtbot, window.link, sim)
    qtbot.waitUntil(
        lambda: window.motion_enabled and window.link.state.status is not None, timeout=SIGNAL_TIMEOUT_MS
    )
    settle()


def motion_states(window: MainWindow) -> Iterator[str]:
    """Put the control column in each of its layouts in turn; yields a name for each."""
    jog, step = window.jog_panel, window.step_panel
    window.tabs.setCurrentWidget(jog)
    for frame in (TeachFrame.BASE, TeachFrame.USER, TeachFrame.TOOL, TeachFrame.JOINT):
        jog.set_frame(frame)
        yield f"jog {frame.name.lower()}"
    window.tabs.setCurrentWidget(step)
    for external in (False, True):
        step.external_check.setChecked(external)
        yield f"step external={external}"
    window.tabs.setCurrentWidget(window.program_panel)
    yield "program"


def work_states(window: MainWindow) -> Iterator[str]:
    """Each work tab, the points tab also with its restore banner and upload progress, the
    planner also after a stop (the run box shows the reason)."""
    window.show_tab(TAB_MONITOR)
    yield "monitor"
    window.show_tab(TAB_POINTS)
    yield "points"
    sync = window.point_sync
    sync.restoreOffered.emit(True)
    sync.uploadProgress.emit(3, 12)
    yield "points with banner and progress"
    window.show_tab(TAB_PLANNER)
    yield "planner"
    window.planner_panel.run_box.show_ended(STOP_MESSAGE)
    yield "planner after a stop"


def squeezed(window: MainWindow) -> list[str]:
    """Qt squeezes widgets below their minimum (and clips them) when the window cannot give
    every part its minimum: the central area and the status dock must both get theirs."""
    found = []
    central = window.centralWidget()
    assert central is not None
    for part, least in (
        (central, central.minimumSizeHint()),
        (window.status_dock, QSize(STATUS_DOCK_WIDTH, 0)),
    ):
        if part.width() < least.width() or part.height() < least.height():
            found.append(
                f"{part.objectName() or 'central area'} is {part.width()}×{part.height()}, "
                f"needs {least.width()}×{least.height()}"
            )
    return found


def check_window(window: MainWindow, language: str, touch: bool) -> list[str]:
    """Every work state beside the joint jog, then every motion state beside the planner
    after a stop (the two sides only share the window's width, which neither state changes)."""
    found: list[str] = []
    window.jog_panel.set_frame(TeachFrame.JOINT)
    for work in work_states(window):
        settle()
        found += [f"[jog joint | {work}] {p}" for p in problems(window, language, touch) + squeezed(window)]
    for motion in motion_states(window):
        settle()
        found += [
            f"[{motion} | planner after a stop] {p}"
            for p in problems(window, language, touch) + squeezed(window)
        ]
    return sorted(set(found))


def without_known(found: list[str], key: str) -> list[str]:
    known = KNOWN_ISSUES.get(key)
    if known is None:
        return found
    rest = [p for p in found if not re.match(known, p)]
    assert len(rest) < len(found), f"known issue {key} no longer occurs: remove it from KNOWN_ISSUES"
    return rest


@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
@pytest.mark.parametrize("language", LANGUAGES)
def test_main_window_layout(
    qtbot: Any, sim: Any, make_window: Callable[..., MainWindow], language: str, size: tuple[int, int]
) -> None:
    window = make_window(language, size, connected=False)
    found = check_window(window, language, touch=False)
    assert not found, "\n".join(found)
    connect_window(qtbot, window, sim)
    key = f"{language}-{size[0]}x{size[1]}-connected"
    found = without_known(check_window(window, language, touch=False), key)
    assert not found, "\n".join(found)


def raise_estop(qtbot: Any, window: MainWindow, sim: Any) -> None:
    """An emergency stop at the simulator: the banner is up and the motion controls are held."""
    sim.set_alarm(Alarm.ESTOP, True)
    qtbot.waitUntil(
        lambda: window.alarm_banner.isVisible() and not window.jog_panel.axes_box.isEnabled(),
        timeout=SIGNAL_TIMEOUT_MS,
    )
    settle()


@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
@pytest.mark.parametrize("language", LANGUAGES)
def test_main_window_layout_with_an_alarm(
    qtbot: Any, sim: Any, make_window: Callable[..., MainWindow], language: str, size: tuple[int, int]
) -> None:
    window = make_window(language, size)
    raise_estop(qtbot, window, sim)
    found = check_window(window, language, touch=False)
    assert window.alarm_banner.isVisible()
    assert not found, "\n".join(found)
    # more alarms add their lines to the banner (laid over the bottom docks): nothing is squeezed
    banner = window.alarm_banner
    for bit in (Alarm.SERVO, Alarm.ENCODER):
        sim.set_alarm(bit, True)
    qtbot.waitUntil(
        lambda: banner.alarms == int(Alarm.ESTOP | Alarm.SERVO | Alarm.ENCODER), timeout=SIGNAL_TIMEOUT_MS
    )
    settle()
    assert not squeezed(window) and not clipped_texts(banner)
    assert banner.label.text().count("\n") == 3  # the whole text, one line per alarm


@pytest.mark.parametrize("language", LANGUAGES)
def test_touch_mode_layout_at_1280x800(make_window: Callable[..., MainWindow], language: str) -> None:
    window = make_window(language, LAPTOP, touch=True)
    assert window.menus.touch_action.isChecked()
    found = without_known(check_window(window, language, touch=True), f"{language}-1280x800-connected")
    assert not found, "\n".join(found)
    # Issue 21 (was: the rows scrolled): touch mode lays the rows in three lines of two, X Y Z
    # beside A B C, J1 J2 J3 beside J4 J5 J6, and J7..J11 the same way behind the "J7–J11" switch
    jog = window.jog_panel
    window.tabs.setCurrentWidget(jog)
    for frame, external, axes in (
        (TeachFrame.BASE, False, range(6)),
        (TeachFrame.JOINT, False, range(6)),
        (TeachFrame.JOINT, True, range(6, 11)),
    ):
        jog.set_frame(frame)
        jog.external_check.setChecked(external)
        settle()
        assert not jog.axes_scroll.verticalScrollBar().isVisible(), (frame, external)
        assert jog.external_check.isVisible() == (frame is TeachFrame.JOINT)
        assert_rows_whole(jog, axes, TOUCH_MOTION_HEIGHT)
        hidden = set(range(11)) - set(axes)
        assert not any(jog.button(a, d).isVisible() for a in hidden for d in (0, 1))
    jog.external_check.setChecked(False)
    # the step increments at touch size
    window.tabs.setCurrentWidget(window.step_panel)
    settle()
    assert all(b.height() >= TOUCH_MOTION_HEIGHT for b in window.step_panel.preset_buttons)
    window.set_touch_mode(False)
    settle()
    assert all(b.height() < TOUCH_MOTION_HEIGHT for b in window.step_panel.preset_buttons)
    window.tabs.setCurrentWidget(jog)
    jog.set_frame(TeachFrame.JOINT)
    settle()
    assert not jog.external_check.isVisible()
    assert_rows_whole(jog, range(11), MOTION_MIN_HEIGHT)  # compact: J1..J6 beside J7..J11


def assert_rows_whole(jog: Any, axes: Iterable[int], height: int) -> None:
    """Each of ``axes`` shows both its buttons whole (nothing scrolled or cut away), ``height`` px high."""
    for axis in axes:
        for direction in (0, 1):
            button = jog.button(axis, direction)
            assert button.isVisible() and button.height() >= height, (axis, direction)
            assert button.visibleRegion().boundingRect() == button.rect(), (axis, direction)


@pytest.mark.parametrize("language", LANGUAGES)
def test_step_offsets_show_whole_at_1280x800(make_window: Callable[..., MainWindow], language: str) -> None:
    """Issue 21: in the base frame the exact offsets' arrows were cut off at the right ("X (mm)"
    took their room; the unit is in the field)."""
    from app.link.types import StepFrame

    window = make_window(language, LAPTOP)
    step = window.step_panel
    window.tabs.setCurrentWidget(step)
    for touch in (False, True):
        window.set_touch_mode(touch)
        for frame in (StepFrame.JOINT, StepFrame.BASE):
            step.set_frame(frame)
            settle()
            viewport = step.axes_scroll.viewport()
            for axis in range(6):
                spin = step.value_spins[axis]
                right = spin.mapTo(viewport, QPoint(spin.width(), 0)).x()
                assert right <= viewport.width(), (touch, frame, axis, right, viewport.width())


@pytest.mark.parametrize("touch", [False, True], ids=["mouse", "touch"])
@pytest.mark.parametrize("size", [LAPTOP, (1920, 1080)], ids=["1280x800", "1920x1080"])
@pytest.mark.parametrize("language", LANGUAGES)
def test_a_jog_permitted_alarm_clips_no_jog_row(
    qtbot: Any, sim: Any, make_window: Callable[..., MainWindow], language: str, size: Any, touch: bool
) -> None:
    """Issue 21: zh_CN with an alarm that lets the arm jog (the encoder alarm) cut the last jog rows.
    Both languages, 1280×800 and 1920×1080, mouse and touch mode: every row whole, no scroll bar."""
    window = make_window(language, size, touch=touch)
    sim.set_alarm(Alarm.ENCODER, True)
    qtbot.waitUntil(window.alarm_banner.isVisible, timeout=SIGNAL_TIMEOUT_MS)
    jog = window.jog_panel
    qtbot.waitUntil(jog.axes_box.isEnabled, timeout=SIGNAL_TIMEOUT_MS)
    window.tabs.setCurrentWidget(jog)
    views = (
        (
            (TeachFrame.BASE, False, range(6)),
            (TeachFrame.JOINT, False, range(6)),
            (TeachFrame.JOINT, True, range(6, 11)),
        )
        if touch
        else ((TeachFrame.BASE, False, range(6)), (TeachFrame.JOINT, False, range(11)))
    )
    for frame, external, axes in views:
        jog.set_frame(frame)
        jog.external_check.setChecked(external)
        settle()
        assert not jog.axes_scroll.verticalScrollBar().isVisible(), (frame, external)
        assert_rows_whole(jog, axes, motion_height(touch))
    jog.external_check.setChecked(False)


@pytest.mark.parametrize("language", LANGUAGES)
def test_reduced_speed_caps_fit_at_1280x800(make_window: Callable[..., MainWindow], language: str) -> None:
    """Reduced-speed mode shows its caps beside the jog slider, the program speed and the step speed
    (issue 18): they fit the control column without clipping, in both languages."""
    window = make_window(language, LAPTOP)
    assert window.safety_menu.safety.set_reduced(True)
    window.jog_panel.set_ratio(100)
    window.program_panel.speed_spin.setValue(100)
    window.step_panel.speed_spin.setValue(50.0)  # rpm: above the joint cap
    assert window.jog_panel.speed_value.text() == (
        "100 % → 10 %" + ("（降速模式）" if language != "en" else " (reduced speed)")
    )
    assert window.program_panel.speed_cap.isVisibleTo(window.program_panel)
    assert window.step_panel.speed_cap.isVisibleTo(window.step_panel)
    found = without_known(check_window(window, language, touch=False), f"{language}-1280x800-connected")
    assert not found, "\n".join(found)


@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
def test_points_primary_actions_and_docks_stay_visible(
    make_window: Callable[..., MainWindow], size: tuple[int, int]
) -> None:
    window = make_window("en", size)
    window.show_tab(TAB_POINTS)
    settle()
    points = window.points_panel
    for button in (
        points.teach_button,
        points.upload_button,
        points.restore_all_button,
        points.move_to_button,
    ):
        assert button.isVisible() and button.width() >= button.sizeHint().width(), button.text()
    for dock, panel in ((window.event_dock, window.event_log), (window.traffic_dock, window.traffic_panel)):
        dock.raise_()
        settle()
        rows = panel.view.viewport().height() / panel.view.verticalHeader().defaultSectionSize()
        assert rows >= DOCK_MIN_ROWS, dock.objectName()


@pytest.mark.parametrize("language", LANGUAGES)
def test_joint_jog_fits_1280x800_without_scrolling(
    language: str, make_window: Callable[..., MainWindow]
) -> None:
    window = make_window(language, LAPTOP)
    window.jog_panel.set_frame(TeachFrame.JOINT)
    settle()
    jog = window.jog_panel
    assert not jog.axes_scroll.verticalScrollBar().isVisible()
    for axis in range(11):
        for direction in (0, 1):
            button = jog.button(axis, direction)
            assert button.isVisible() and not button.visibleRegion().isEmpty()


@pytest.mark.parametrize("language", LANGUAGES)
def test_the_jog_rows_fit_1280x800_under_the_motion_banner(
    language: str, make_window: Callable[..., MainWindow], qtbot: Any, sim: Any
) -> None:
    """The "Not connected" banner takes the hints' height, not a jog row's: the six rows show
    whole, no scroll bar; connected, the hints come back."""
    window = make_window(language, LAPTOP, connected=False)
    jog = window.jog_panel
    settle()
    assert window.motion_banner.isVisible()
    assert not jog.axes_scroll.verticalScrollBar().isVisible()
    for axis in range(6):
        for direction in (0, 1):
            button = jog.button(axis, direction)
            assert button.isVisible() and not button.visibleRegion().isEmpty(), (axis, direction)
    connect_window(qtbot, window, sim)
    assert window.motion_banner.isHidden() and jog.keys_label.isVisible()  # the room given back
    assert not jog.axes_scroll.verticalScrollBar().isVisible()


@pytest.mark.parametrize("language", LANGUAGES)
def test_dialogs_layout(qtbot: Any, app_settings: Any, translator: Any, language: str) -> None:
    assert translator.set_language(language)
    parent = QWidget()
    qtbot.addWidget(parent)
    connection = ConnectionDialog(app_settings.connection(), parent)
    from PySide6.QtWidgets import QDoubleSpinBox

    field = QDoubleSpinBox(parent)
    field.setRange(-10_000.0, 10_000.0)
    field.setDecimals(3)
    keypad = KeypadDialog(field, parent)
    question = QMessageBox(
        QMessageBox.Icon.Question,
        "Confirm program run",
        "Run program 1 (single run) at 50 %? The arm will move.",
        QMessageBox.StandardButton.Yes | QMessageBox.StandardButton.Cancel,
        parent,
    )
    for dialog in (connection, keypad, question):
        dialog.show()
        qtbot.waitExposed(dialog)
        settle()
        assert problems(dialog, language, touch=False) == [], type(dialog).__name__
        dialog.close()


@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
@pytest.mark.parametrize("language", LANGUAGES)
def test_the_alarm_banner_moves_nothing(
    qtbot: Any, sim: Any, make_window: Callable[..., MainWindow], language: str, size: tuple[int, int]
) -> None:
    """Issue 21: the banner appeared above everything and pushed the window 24 px down, STOP with it,
    at the worst moment. It is laid over the window now: STOP, the pose strip and the work tabs
    keep their place on the screen while alarms come and go."""
    window = make_window(language, size)
    stop = window.control_bar.stop_button
    watched = (stop, window.pose_strip, window.tabs, window.work_tabs)

    def places() -> list[tuple[int, int, int, int]]:
        return [(w.mapToGlobal(w.rect().topLeft()).toTuple() + w.size().toTuple()) for w in watched]

    before = places()
    raise_estop(qtbot, window, sim)
    assert places() == before
    window.alarm_dock.raise_()  # the Alarms dock in view under the banner: nothing moves either
    settle()
    assert places() == before
    sim.set_alarm(Alarm.ENCODER, True)
    qtbot.waitUntil(
        lambda: window.alarm_banner.alarms == int(Alarm.ESTOP | Alarm.ENCODER), timeout=SIGNAL_TIMEOUT_MS
    )
    settle()
    assert places() == before
    for bit in (Alarm.ESTOP, Alarm.ENCODER):
        sim.set_alarm(bit, False)
    qtbot.waitUntil(lambda: not window.alarm_banner.isVisible(), timeout=SIGNAL_TIMEOUT_MS)
    settle()
    assert places() == before


def shown_whole(label: QLabel, sentence: str) -> bool:
    """``sentence`` is in what ``label`` paints (not elided), every line of it inside the label,
    and no sibling covers the label."""
    text = label.text().replace("\n", " ")
    if sentence not in " ".join(text.split()):
        return False
    needs = label.heightForWidth(label.width()) if label.wordWrap() else label.sizeHint().height()
    return label.height() >= needs and label.visibleRegion().boundingRect() == label.rect()


@pytest.mark.parametrize("language", LANGUAGES)
def test_the_emergency_stop_instruction_reads_whole_at_1280x800(
    qtbot: Any, sim: Any, make_window: Callable[..., MainWindow], language: str
) -> None:
    """Issue 21: "Make the cell safe, release the emergency stop, …" was elided in the banner and the
    Alarms dock. The banner shows the whole sentence; more alarms add their lines (it lies over the
    bottom docks, the window below does not move)."""
    from app.alarm_history import ALARM_ADVICE, TR_ALARMS

    window = make_window(language, LAPTOP)
    raise_estop(qtbot, window, sim)
    advice = QCoreApplication.translate(TR_ALARMS, ALARM_ADVICE[Alarm.ESTOP])
    assert advice != ALARM_ADVICE[Alarm.ESTOP] or language == "en"
    label = window.alarm_banner.label
    assert shown_whole(label, advice), label.text()
    assert window.rect().contains(window.alarm_banner.geometry())
    for bit in (Alarm.SERVO, Alarm.ENCODER):
        sim.set_alarm(bit, True)
    qtbot.waitUntil(
        lambda: window.alarm_banner.alarms == int(Alarm.ESTOP | Alarm.SERVO | Alarm.ENCODER),
        timeout=SIGNAL_TIMEOUT_MS,
    )
    settle()
    for bit in (Alarm.ESTOP, Alarm.SERVO, Alarm.ENCODER):
        sentence = QCoreApplication.translate(TR_ALARMS, ALARM_ADVICE[bit])
        assert shown_whole(label, sentence), label.text()
    assert window.rect().contains(window.alarm_banner.geometry())


@pytest.mark.parametrize("language", LANGUAGES)
def test_the_login_dialog_keeps_its_fields_when_it_says_wrong_password(
    qtbot: Any, translator: Any, language: str
) -> None:
    """Issue 21: "Wrong password" squeezed the dialog's fields (it did not grow for the line)."""
    from app.safety.roles import Role
    from ui.controllers.safety import SafetyController
    from ui.dialogs.role_dialog import RoleDialog

    assert translator.set_language(language)
    safety = SafetyController(None, scrypt_n=2**4)
    safety.set_idle_polling(False)
    safety.session.set_password(Role.ADMINISTRATOR, "root-pw")  # the first one: anyone
    dialog = RoleDialog(safety)
    qtbot.addWidget(dialog)
    dialog.role_box.setCurrentIndex(dialog.role_box.findData(Role.ADMINISTRATOR))
    assert not dialog.error.text()  # no hint: the administrator has a password
    dialog.show()
    qtbot.waitExposed(dialog)
    settle()
    assert not problems(dialog, language, touch=False)
    fields = (dialog.role_box, dialog.password)
    heights = [f.height() for f in fields]
    dialog.password.setText("wrong")
    dialog.log_in()
    settle()
    assert dialog.error.text() and dialog.error.isVisible()
    assert [f.height() for f in fields] == heights
    assert all(f.height() >= f.sizeHint().height() for f in fields)
    found = problems(dialog, language, touch=False)
    error = dialog.error
    assert error.height() >= error.heightForWidth(error.width()), "the refusal is cut"
    assert not found, "\n".join(found)
    safety.close()


@pytest.mark.parametrize("language", LANGUAGES)
def test_the_alarms_dock_reads_what_to_do_whole_at_1280x800(
    qtbot: Any, sim: Any, make_window: Callable[..., MainWindow], language: str
) -> None:
    """Issue 21: the Alarms dock elided "Make the cell safe, release the emergency stop button, …":
    its rows wrap and are as tall as their text."""
    from PySide6.QtCore import QRect

    from ui.panels.alarm_list import COL_ADVICE, COL_MEANING

    window = make_window(language, LAPTOP)
    raise_estop(qtbot, window, sim)
    window.alarm_dock.raise_()
    settle()
    alarms = window.alarm_list
    # the banner stays above the dock raised under it (it says the same, whole)
    label = window.alarm_banner.label
    assert window.alarm_banner.isVisible() and shown_whole(label, label.text().split("\n")[-1])
    table = alarms.table
    metrics = table.fontMetrics()
    for bit in (int(b) for b in Alarm):
        for column in (COL_MEANING, COL_ADVICE):
            text = alarms.cell(bit, column)
            cell = table.visualRect(table.model().index(alarms.row_of(bit), column))
            room = cell.adjusted(3, 0, -3, 0)  # the item's text margins
            needs = metrics.boundingRect(QRect(0, 0, room.width(), 10_000), Qt.TextFlag.TextWordWrap, text)
            assert needs.height() <= cell.height() and needs.width() <= room.width(), (bit, column, text)
