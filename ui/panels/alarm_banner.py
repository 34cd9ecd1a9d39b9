"""The alarm banner: window-wide, red, above everything while any alarm bit (register 562) is set.

It names every set alarm in the operator's language with what to do about it, and says when the
motion controls are held. It is a toolbar that cannot be moved, floated or hidden by hand: it
shows exactly while the controller reports an alarm (the last known word when the link is stale,
marked as such) and hides itself when every bit is clear.
"""

from __future__ import annotations

import html

from PySide6.QtCore import QCoreApplication, QEvent, QSize, Qt, Slot
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
from ui.palette import COLOR_ALARM_BANNER, COLOR_ALARM_BANNER_TEXT, COLOR_ERROR_DARK

__all__ = ["AlarmBanner", "alarm_name"]

BANNER_HINT_WIDTH = 200  # px: the text's size hint in the toolbar (it stretches to the window)


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
    """A label that asks a toolbar for little width and takes what is there (Expanding): a
    toolbar moves a widget whose size hint does not fit into its overflow menu."""

    def sizeHint(self) -> QSize:
        return QSize(BANNER_HINT_WIDTH, super().sizeHint().height())

    def minimumSizeHint(self) -> QSize:
        return QSize(BANNER_HINT_WIDTH, super().minimumSizeHint().height())


class AlarmBanner(QToolBar):
    """See the module docstring. ``bind(state)``; ``text()`` is what it says (plain)."""

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("AlarmBanner")
        self.setMovable(False)
        self.setFloatable(False)
        self.toggleViewAction().setVisible(False)  # not in the window's context menu: not closable
        self.setContextMenuPolicy(Qt.ContextMenuPolicy.PreventContextMenu)
        self.setStyleSheet(f"QToolBar#AlarmBanner {{ background: {COLOR_ALARM_BANNER};"
                           f" border: 2px solid {COLOR_ERROR_DARK}; padding: 2px; spacing: 0px; }}")
        self.label = _BannerText(self)
        self.label.setObjectName("AlarmBannerText")
        # one line per alarm, no wrapping: a wrapping label in a toolbar asks for its height at a
        # narrow width and the banner grows to several times its text
        self.label.setWordWrap(False)
        self.label.setTextFormat(Qt.TextFormat.RichText)
        self.label.setStyleSheet(f"QLabel {{ color: {COLOR_ALARM_BANNER_TEXT}; padding: 2px 8px; }}")
        self.label.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Preferred)
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
            self.label.setText("")
            return
        bits = alarm_bits(self._alarms)
        names = ", ".join(alarm_name(b) for b in bits)
        title = self.tr("ALARM: {names}").format(names=names)
        if self._state is not None and not self._state.fresh:
            title += " " + self.tr("(last known: the link is not live)")
        held = ""
        if blocks_motion(self._alarms):
            held = self.tr("Motion controls are held until the alarm is reset. STOP stays available.")
        lines = [f"{alarm_name(b)}: {alarm_advice(b)}" for b in bits]
        self._plain = "\n".join([f"{title} — {held}" if held else title, *lines])
        head = f"<span style='font-size:16px'><b>{html.escape(title)}</b></span>"
        if held:
            head += f" &nbsp;—&nbsp; <b>{html.escape(held)}</b>"
        body = "<br>".join(html.escape(line) for line in lines)
        self.label.setText(f"{head}<br>{body}")
        self.label.setToolTip(self._plain)
        self.setToolTip(self.tr("Register 562 = {word}").format(word=f"0x{self._alarms:04X}"))

