"""The alarm banner: red, laid over the window while any alarm bit (register 562) is set.

It names every set alarm in the operator's language with what to do about it, and says when the
motion controls are held. It cannot be moved or hidden by hand: it shows exactly while the
controller reports an alarm (the last known word when the link is stale, marked as such) and
hides itself when every bit is clear.

Decided (issue 21): it is laid over the window, not a row of its own. As a tool bar above
everything it pushed the whole window 24 px down when an alarm came (STOP moved at the worst
moment), and at 1280×800 it had one elided line, so "Make the cell safe, release the emergency stop
button, …" was never read whole. Now nothing moves: it lies over the top of the bottom docks
(the event log, the Alarms list; without a bottom dock, over the bottom of the central area),
right under the jog panel and the work tabs, as many lines as its text needs: the names and the
hold, then one line per alarm with what to do. STOP, the pose strip, the jog panel and the work
tabs are never covered.
"""

from __future__ import annotations

from PySide6.QtCore import QCoreApplication, QEvent, QObject, QRect, Qt, QTimer, Slot
from PySide6.QtWidgets import QDockWidget, QFrame, QLabel, QMainWindow, QVBoxLayout, QWidget

from app.alarm_history import (
    ALARM_ADVICE,
    TR_ALARMS,
    UNKNOWN_ADVICE,
    alarm_bits,
    blocks_motion,
)
from app.link.state import RobotState
from app.protocol.enums import ALARM_TEXT, TR_CONTEXT
from ui.joins import join_names, labelled
from ui.palette import COLOR_ALARM_BANNER, COLOR_ALARM_BANNER_TEXT, COLOR_ERROR_DARK

__all__ = ["AlarmBanner", "alarm_name"]

BANNER_FONT_SCALE = 1.15  # a little larger than the window's text: it must not be missed
BANNER_PADDING_PX = 2  # px above and below the line (the toolbar adds no chrome of its own)
# the window's layout changed: the banner follows the bottom docks
_RELAYOUT_EVENTS = (
    QEvent.Type.Resize,
    QEvent.Type.Move,
    QEvent.Type.LayoutRequest,
    QEvent.Type.Show,
    QEvent.Type.ZOrderChange,  # a dock raised (a tab of the bottom docks chosen) covered the banner
)


def _anchor(window: QMainWindow) -> tuple[QRect, bool]:
    """Where the banner lies: the bottom docks' area (True), or the central area (False)."""
    docks = [
        d
        for d in window.findChildren(QDockWidget, options=Qt.FindChildOption.FindDirectChildrenOnly)
        if d.isVisible()
        and not d.isFloating()
        and window.dockWidgetArea(d) == Qt.DockWidgetArea.BottomDockWidgetArea
        and window.rect().contains(d.geometry())  # a tab behind another lies outside the window
    ]
    if docks:
        area = QRect(docks[0].geometry())
        for dock in docks[1:]:
            area = area.united(dock.geometry())
        return area, True
    central = window.centralWidget()
    return (central.geometry() if central is not None else window.rect()), False


def alarm_name(bit: int) -> str:
    """The translated name of one alarm bit (an undocumented one by its number)."""
    for alarm, text in ALARM_TEXT.items():
        if int(alarm) == bit:
            return QCoreApplication.translate(TR_CONTEXT, text)
    return QCoreApplication.translate("AlarmBanner", "alarm bit {bit}").format(bit=bit.bit_length() - 1)


def alarm_advice(bit: int) -> str:
    for alarm, text in ALARM_ADVICE.items():
        if int(alarm) == bit:
            return QCoreApplication.translate(TR_ALARMS, text)
    return QCoreApplication.translate(TR_ALARMS, UNKNOWN_ADVICE)


class AlarmBanner(QFrame):
    """See the module docstring. ``bind(state)``; ``text()`` is what it says (plain)."""

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("AlarmBanner")
        self.setProperty("overlay", True)  # laid over the window on purpose (the layout check)
        self.setAutoFillBackground(True)
        self.setStyleSheet(
            f"QFrame#AlarmBanner {{ background: {COLOR_ALARM_BANNER};"
            f" border: none; border-bottom: 2px solid {COLOR_ERROR_DARK}; }}"
        )
        self.label = QLabel(self)
        self.label.setObjectName("AlarmBannerText")
        self.label.setWordWrap(True)
        self.label.setTextFormat(Qt.TextFormat.PlainText)
        font = self.label.font()
        font.setBold(True)
        font.setPointSizeF(font.pointSizeF() * BANNER_FONT_SCALE)
        self.label.setFont(font)
        self.label.setStyleSheet(f"QLabel {{ color: {COLOR_ALARM_BANNER_TEXT}; padding: 0px 8px; }}")
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, BANNER_PADDING_PX, 0, BANNER_PADDING_PX + 2)  # + the border
        layout.addWidget(self.label)
        self._state: RobotState | None = None
        self._alarms = 0
        self._plain = ""
        self._watched: list[QWidget] = []  # the parts whose moves and raises the banner follows
        self.setVisible(False)
        if parent is not None:
            parent.installEventFilter(self)

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        """Follow the window's layout (a resize, a dock moved or shown): the banner keeps its place
        over the top of the bottom docks."""
        if event.type() in _RELAYOUT_EVENTS and self.isVisible():
            self._later()
        return False

    @Slot()
    def _later(self) -> None:
        QTimer.singleShot(0, self.place)

    def place(self) -> None:
        """Lay the banner over the top of the bottom docks (without one, over the bottom of the
        central area), as tall as its text needs, raised above them."""
        window = self.parentWidget()
        if not isinstance(window, QMainWindow) or self.isHidden():
            return
        central = window.centralWidget()
        docks = window.findChildren(QDockWidget, options=Qt.FindChildOption.FindDirectChildrenOnly)
        for part in (central, *docks):  # the central area moves when a dock does; a dock raised
            if part is not None and part not in self._watched:
                part.installEventFilter(self)
                self._watched.append(part)
                if isinstance(part, QDockWidget):  # a tab of the bottom docks chosen
                    part.visibilityChanged.connect(self._later)
        area, over_docks = _anchor(window)
        need = self._height_for(area.width())
        top = area.top() if over_docks else area.bottom() + 1 - need
        top = max(min(top, area.bottom() + 1 - need), 0)
        self.setGeometry(area.left(), top, area.width(), need)
        self.raise_()

    def _height_for(self, width: int) -> int:
        layout = self.layout()
        assert layout is not None
        return layout.totalHeightForWidth(width)

    def bind(self, state: RobotState) -> None:
        self._state = state
        state.alarmsChanged.connect(self.on_alarms)
        state.freshnessChanged.connect(self._on_freshness)
        self.on_alarms(state.alarms or 0)

    @property
    def alarms(self) -> int:
        return self._alarms

    @property
    def active(self) -> bool:
        return bool(self._alarms)

    def text(self) -> str:
        return self._plain

    @Slot(int)
    def on_alarms(self, alarms: int) -> None:
        self._alarms = int(alarms) & 0xFFFF
        self._render()
        self.sync()

    @Slot(bool)
    def _on_freshness(self, _fresh: bool) -> None:
        if self._alarms:
            self._render()

    def sync(self) -> None:
        """Show exactly while an alarm is set (also after the window restored a saved layout)."""
        self.setVisible(self.active)
        self.place()

    def changeEvent(self, event: QEvent) -> None:
        if event.type() == QEvent.Type.LanguageChange:
            self._render()
        super().changeEvent(event)

    def _render(self) -> None:
        if not self._alarms:
            self._plain = ""
            self.label.setText("")
            self.label.setToolTip("")
            return
        bits = alarm_bits(self._alarms)
        names = join_names(alarm_name(b) for b in bits)
        title = self.tr("ALARM: {names}").format(names=names)
        if self._state is not None and not self._state.fresh:
            title += " " + self.tr("(last known: the link is not live)")
        held = ""
        if blocks_motion(self._alarms):
            held = self.tr("Motion controls are held until the alarm is reset. STOP stays available.")
        lines = [labelled(alarm_name(b), alarm_advice(b)) for b in bits]
        head = f"{title} — {held}" if held else title
        self._plain = "\n".join([head, *lines])
        self.label.setText(self._plain)
        self.label.setToolTip(self._plain)
        self.place()
        self.setToolTip(self.tr("Register 562 = {word}").format(word=f"0x{self._alarms:04X}"))
