"""The alarm banner: window-wide, red, above everything while any alarm bit (register 562) is set.

It names every set alarm in the operator's language with what to do about it, and says when the
motion controls are held. It is a toolbar that cannot be moved, floated or hidden by hand: it
shows exactly while the controller reports an alarm (the last known word when the link is stale,
marked as such) and hides itself when every bit is clear.

It is one line of fixed height whatever the number of alarms (the window below it must not
shrink as alarms come and go; at 1280×800 every pixel counts): the names and the hold first,
then what to do, elided at the window's edge; the tooltip and the Alarms dock have all of it.
"""

from __future__ import annotations

from PySide6.QtCore import QCoreApplication, QEvent, QSize, Qt, Slot
from PySide6.QtGui import QFontMetrics, QResizeEvent
from PySide6.QtWidgets import QLabel, QSizePolicy, QToolBar, QWidget

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

BANNER_HINT_WIDTH = 200  # px: the text's size hint in the toolbar (it stretches to the window)
BANNER_FONT_SCALE = 1.15  # a little larger than the window's text: it must not be missed
BANNER_PADDING_PX = 2  # px above and below the line (the toolbar adds no chrome of its own)
# a line of both scripts: the fixed height fits Latin and CJK glyphs (the CJK fallback is taller)
_SAMPLE = "ALARM Ågy 报警急停"


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


class _BannerText(QLabel):
    """One bold line of fixed height, elided at its width (``elide``: the layout check expects
    the tooltip to hold the whole text). It asks a toolbar for little width and takes what is
    there (Expanding): a toolbar moves a widget whose size hint does not fit into its overflow menu."""

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self._full = ""
        self.setProperty("elide", True)
        self.setWordWrap(False)
        self.setTextFormat(Qt.TextFormat.PlainText)
        font = self.font()
        font.setBold(True)
        font.setPointSizeF(font.pointSizeF() * BANNER_FONT_SCALE)
        self.setFont(font)
        self.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Fixed)
        self.setFixedHeight(QFontMetrics(font).boundingRect(_SAMPLE).height() + 2 * BANNER_PADDING_PX)

    def full_text(self) -> str:
        return self._full

    def set_full_text(self, text: str) -> None:
        self._full = text
        self._elide()

    def resizeEvent(self, event: QResizeEvent) -> None:
        super().resizeEvent(event)
        self._elide()

    def _elide(self) -> None:
        room = self.contentsRect().width() - 2 * self.margin()
        self.setText(self.fontMetrics().elidedText(self._full, Qt.TextElideMode.ElideRight, max(room, 10)))

    def sizeHint(self) -> QSize:
        return QSize(BANNER_HINT_WIDTH, self.height())

    def minimumSizeHint(self) -> QSize:
        return QSize(BANNER_HINT_WIDTH, self.height())


class AlarmBanner(QToolBar):
    """See the module docstring. ``bind(state)``; ``text()`` is what it says (plain)."""

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("AlarmBanner")
        self.setMovable(False)
        self.setFloatable(False)
        self.toggleViewAction().setVisible(False)  # not in the window's context menu: not closable
        self.setContextMenuPolicy(Qt.ContextMenuPolicy.PreventContextMenu)
        self.setStyleSheet(
            f"QToolBar#AlarmBanner {{ background: {COLOR_ALARM_BANNER};"
            f" border: none; border-bottom: 2px solid {COLOR_ERROR_DARK};"
            f" padding: 0px; spacing: 0px; }}"
        )
        layout = self.layout()
        if layout is not None:
            layout.setContentsMargins(0, 0, 0, 0)
        self.label = _BannerText(self)
        self.label.setObjectName("AlarmBannerText")
        self.label.setStyleSheet(f"QLabel {{ color: {COLOR_ALARM_BANNER_TEXT}; padding: 0px 8px; }}")
        self.addWidget(self.label)
        self._state: RobotState | None = None
        self._alarms = 0
        self._plain = ""
        self.setVisible(False)

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

    def changeEvent(self, event: QEvent) -> None:
        if event.type() == QEvent.Type.LanguageChange:
            self._render()
        super().changeEvent(event)

    def _render(self) -> None:
        if not self._alarms:
            self._plain = ""
            self.label.set_full_text("")
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
        self.label.set_full_text("   ".join([head, *lines]))
        self.label.setToolTip(self._plain)
        self.setToolTip(self.tr("Register 562 = {word}").format(word=f"0x{self._alarms:04X}"))
