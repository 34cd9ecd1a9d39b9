"""Small widgets and helpers shared by the panels: numeric readout, lamps, atomic file writes,
and the display text of connection states and command results.

Translatable strings here use the context ``Panels``; protocol texts keep theirs (``Protocol``).
"""

from __future__ import annotations

from collections.abc import Callable

from PySide6.QtCore import QCoreApplication, QEvent, QSize, Qt
from PySide6.QtGui import (
    QColor,
    QFont,
    QFontDatabase,
    QFontMetrics,
    QPainter,
    QPaintEvent,
    QPalette,
    QResizeEvent,
)
from PySide6.QtWidgets import QFrame, QHBoxLayout, QLabel, QSizePolicy, QWidget

from app.link.types import ConnectionState, LinkState
from app.models import CommandResult
from app.protocol.enums import (
    QT_TRANSLATE_NOOP,
    RUN_COMMAND_TEXT,
    TR_CONTEXT,
    UNKNOWN_STATUS_TEXT,
)
from ui.palette import (
    COLOR_BORDER,
    COLOR_ERROR,
    COLOR_INFO,
    COLOR_NEUTRAL,
    COLOR_NEUTRAL_BG,
    COLOR_OK,
    COLOR_WARN,
    COLOR_WHITE,
)
from ui.widgets.number_text import fit_number, number_room, number_text

TR = "Panels"
READOUT_MARGINS = (6, 2, 6, 2)  # a numeric readout's left, top, right, bottom margins (px)
READOUT_SPACING = 6  # px between its caption, number and unit
COMPACT_MARGINS = (3, 1, 3, 1)  # the same for a compact readout (no unit: six share a row)
COMPACT_SPACING = 4
CAPTION_MIN_POINTS = 8.0  # its caption and unit are not smaller (unless the number is)

# Lamp levels: the ``level`` dynamic property holds one of these.
LEVEL_OFF = "off"
LEVEL_OK = "ok"
LEVEL_WARN = "warn"
LEVEL_ERROR = "error"
LEVEL_INFO = "info"

#: A number shape's room (px) by (font key, integer digits, decimals): every readout of a shape
#: measures the same font at every size the monitor tries (~130 sizes before the first paint, ten
#: digits measured each), so the first measure of each is kept
_number_rooms: dict[tuple[str, int, int], int] = {}

_LAMP_STYLE: dict[str, tuple[str, str, str]] = {  # level -> (background, text, border)
    LEVEL_OFF: (COLOR_NEUTRAL_BG, COLOR_NEUTRAL, COLOR_BORDER),
    LEVEL_OK: (COLOR_OK, COLOR_WHITE, COLOR_OK),
    LEVEL_WARN: (COLOR_WARN, COLOR_WHITE, COLOR_WARN),
    LEVEL_ERROR: (COLOR_ERROR, COLOR_WHITE, COLOR_ERROR),
    LEVEL_INFO: (COLOR_INFO, COLOR_WHITE, COLOR_INFO),
}


def neutral_text(*labels: QWidget) -> None:
    """Captions, units and hints in :data:`COLOR_NEUTRAL`, in every state (as ``color:`` in a style
    sheet, but by the palette: a widget with a style sheet of its own is styled by Qt's style-sheet
    style, ~0.4 ms a label in the window's first show, ~20 ms for the ~50 captions and units)."""
    for label in labels:
        palette = label.palette()
        palette.setColor(QPalette.ColorRole.WindowText, QColor(COLOR_NEUTRAL))  # every colour group
        label.setPalette(palette)


def monospace_font(point_size: float, *, bold: bool = False) -> QFont:
    """The system fixed-pitch font (equal-width digits) at ``point_size``."""
    font = QFontDatabase.systemFont(QFontDatabase.SystemFont.FixedFont)
    font.setStyleHint(QFont.StyleHint.TypeWriter)
    font.setFixedPitch(True)
    font.setPointSizeF(point_size)
    font.setBold(bold)
    return font


class Lamp(QLabel):
    """A coloured indicator with a caption. ``level()`` is also the ``level`` dynamic property."""

    def __init__(self, text: str = "", parent: QWidget | None = None, *, point_size: float = 0.0) -> None:
        super().__init__(text, parent)
        self.setAlignment(Qt.AlignmentFlag.AlignCenter)
        self.setSizePolicy(QSizePolicy.Policy.Preferred, QSizePolicy.Policy.Fixed)
        self.setMinimumHeight(28)
        if point_size:
            font = self.font()
            font.setPointSizeF(point_size)
            self.setFont(font)
        self._level = ""
        self.set_level(LEVEL_OFF)

    def level(self) -> str:
        return self._level

    def set_level(self, level: str) -> None:
        if level not in _LAMP_STYLE:
            raise ValueError(f"unknown lamp level {level!r}")
        if level == self._level:
            return
        self._level = level
        self.setProperty("level", level)
        background, text, border = _LAMP_STYLE[level]
        weight = "normal" if level == LEVEL_OFF else "bold"
        self.setStyleSheet(
            f"QLabel {{ background-color: {background}; color: {text}; border: 1px solid {border};"
            f" border-radius: 5px; padding: 3px 10px; font-weight: {weight}; }}"
        )


class AlarmLamp(Lamp):
    """One alarm bit: red while set, neutral otherwise (``active`` dynamic property too)."""

    def __init__(self, text: str = "", parent: QWidget | None = None, *, point_size: float = 0.0) -> None:
        super().__init__(text, parent, point_size=point_size)
        self.setProperty("active", False)

    def is_active(self) -> bool:
        return self.level() == LEVEL_ERROR

    def set_active(self, active: bool) -> None:
        self.setProperty("active", bool(active))
        self.set_level(LEVEL_ERROR if active else LEVEL_OFF)

    def width_needed(self) -> int:
        """The width its text needs lit or not: an active lamp is bold, which is wider in most
        fonts, so a layout that keeps this much never cuts it when it lights up."""
        hint = self.sizeHint().width()
        bold = QFont(self.font())
        bold.setBold(True)
        text = self.text()
        extra = QFontMetrics(bold).horizontalAdvance(text) - self.fontMetrics().horizontalAdvance(text)
        return hint + max(0, extra)


class _Digits(QWidget):
    """A readout's number, painted on its own opaque background with a size hint that does not
    follow the text. A new value repaints this rectangle only; a QLabel's ``setText`` re-lays
    out every parent up to the window and repaints the backgrounds under it, which at the
    monitor's frame rate was a good part of the GUI thread's time (benchmarks/streaming.py).

    The number is drawn whole or not at all: when it does not fit the width the layout gave
    (a value wider than the room kept for it, a narrow window), ``######`` is drawn and the
    tooltip has the whole value (:func:`ui.widgets.number_text.fit_number`)."""

    def __init__(self, text: str, parent: QWidget) -> None:
        super().__init__(parent)
        self._text = text
        self._shown = text  # what paintEvent draws: ``_text`` or the overflow marks
        self.tip_prefix = ""  # the tooltip of an overflow: "<prefix><whole value><suffix>"
        self.tip_suffix = ""
        self.setAttribute(Qt.WidgetAttribute.WA_OpaquePaintEvent)
        self.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Preferred)

    def text(self) -> str:
        return self._text

    def shown_text(self) -> str:
        """The text drawn now: the number, or ``######`` when it does not fit."""
        return self._shown

    def setText(self, text: str) -> None:  # QLabel's name: the readout's API
        if text != self._text:
            self._text = text
            self.fit()
            self.update()

    def sizeHint(self) -> QSize:
        return QSize(self.minimumWidth(), self.fontMetrics().height())

    def minimumSizeHint(self) -> QSize:
        return self.sizeHint()

    def fit(self) -> None:
        """Decide what is drawn (the number or the overflow marks) and the tooltip that goes with it."""
        self._shown = fit_number(self._text, self.fontMetrics(), self.width())
        tip = "" if self._shown == self._text else self.tip_prefix + self._text + self.tip_suffix
        if tip != self.toolTip():
            self.setToolTip(tip)

    def resizeEvent(self, event: QResizeEvent) -> None:
        super().resizeEvent(event)
        self.fit()

    def changeEvent(self, event: QEvent) -> None:
        super().changeEvent(event)
        if event.type() == QEvent.Type.FontChange:
            self.fit()

    def paintEvent(self, event: QPaintEvent) -> None:
        painter = QPainter(self)
        palette = self.palette()  # the disabled (stale) colours while disabled
        painter.fillRect(event.rect(), palette.window())
        painter.setPen(palette.color(QPalette.ColorRole.WindowText))
        right = Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignVCenter
        painter.drawText(self.rect(), right, self._shown)


# What width_for adds to the sum of its measured parts: each is an advance rounded down (a label
# lays its text out with fractional advances and may need a pixel more), and a font whose
# metrics differ from the developers' must not tip a readout into overlapping its unit.
READOUT_SLACK_PX = 4


class NumericReadout(QFrame):
    """A large fixed-decimal number with its caption and unit, e.g. ``X  -123.456 mm``.

    ``set_value`` only touches the number when the shown text changes, so calling it at the
    paint rate with an unchanged value costs nothing; a change repaints the number alone.
    The number keeps room for ``integer_digits`` digits, a sign, the point and the decimals in
    its font (the widest digit of the font in use: :func:`~ui.widgets.number_text.number_room`);
    a value that does not fit the room it gets shows ``######``, the whole value in the tooltip
    (``text()`` is the value's text, ``shown_text()`` what is drawn).
    """

    PLACEHOLDER = "—"

    def __init__(
        self,
        caption: str,
        unit: str,
        *,
        decimals: int = 3,
        point_size: float = 22.0,
        integer_digits: int = 4,
        unit_room: str = "mm ",
        compact: bool = False,
        parent: QWidget | None = None,
    ) -> None:
        super().__init__(parent)
        self.setFrameShape(QFrame.Shape.StyledPanel)
        self.setObjectName("NumericReadout")
        self.setAutoFillBackground(True)  # a tile of its own: the number's repaint stops here
        self._decimals = decimals
        self._value: float | None = None

        self._integer_digits = integer_digits
        self._unit_room = unit_room  # the unit column is this wide, so numbers line up
        self._margins = COMPACT_MARGINS if compact else READOUT_MARGINS
        self._spacing = COMPACT_SPACING if compact else READOUT_SPACING
        self._point_size = 0.0

        self._caption = QLabel(caption, self)
        self._number = _Digits(self.PLACEHOLDER, self)
        self._unit = QLabel(unit, self)
        neutral_text(self._caption, self._unit)
        self._unit.setVisible(not compact)  # compact: the unit is in the box's title
        self._tip()
        self.set_point_size(point_size)

        layout = QHBoxLayout(self)
        layout.setContentsMargins(*self._margins)
        layout.setSpacing(self._spacing)
        layout.addWidget(self._caption)
        layout.addWidget(self._number, 1)
        layout.addWidget(self._unit)
        self.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Fixed)

    def point_size(self) -> float:
        return self._point_size

    @staticmethod
    def _caption_font(base: QFont, point_size: float) -> QFont:
        font = QFont(base)
        font.setPointSizeF(max(min(CAPTION_MIN_POINTS, point_size), point_size * 0.6))
        font.setBold(True)
        return font

    @staticmethod
    def _unit_font(base: QFont, point_size: float) -> QFont:
        font = QFont(base)
        font.setPointSizeF(max(min(CAPTION_MIN_POINTS, point_size), point_size * 0.55))
        return font

    def _number_room(self, font: QFont) -> int:
        key = (font.key(), self._integer_digits, self._decimals)
        room = _number_rooms.get(key)
        if room is None:
            room = _number_rooms[key] = number_room(QFontMetrics(font), self._integer_digits, self._decimals)
        return room

    def width_for(self, point_size: float) -> int:
        """The least width (px) this readout needs at ``point_size`` to show its widest number
        whole, with its caption and unit: the panel picks the largest size that fits."""
        caption = QFontMetrics(self._caption_font(self.font(), point_size)).horizontalAdvance(self.caption())
        number = self._number_room(monospace_font(point_size, bold=True))
        left, _top, right, _bottom = self._margins
        width = caption + number + left + right + self._spacing + 2 * self.frameWidth()
        if self._unit.isVisibleTo(self):
            metrics = QFontMetrics(self._unit_font(self.font(), point_size))
            unit = max(metrics.horizontalAdvance(self._unit_room), metrics.horizontalAdvance(self.unit()))
            width += unit + self._spacing
        return width + READOUT_SLACK_PX

    def set_point_size(self, point_size: float) -> None:
        """Size of the number; caption and unit follow. Keeps room for the widest expected value
        (measured in the font in use) so the layout does not jump while the robot moves."""
        if point_size == self._point_size:
            return
        self._point_size = point_size
        self._caption.setFont(self._caption_font(self.font(), point_size))
        number_font = monospace_font(point_size, bold=True)
        self._number.setFont(number_font)
        self._number.setMinimumWidth(self._number_room(number_font))
        unit_font = self._unit_font(self.font(), point_size)
        self._unit.setFont(unit_font)
        self._unit.setMinimumWidth(QFontMetrics(unit_font).horizontalAdvance(self._unit_room))

    @property
    def value(self) -> float | None:
        return self._value

    def text(self) -> str:
        """The value's text, whole (without caption and unit)."""
        return self._number.text()

    def shown_text(self) -> str:
        """What the readout draws now: the value's text, or ``######`` when it does not fit."""
        return self._number.shown_text()

    def caption(self) -> str:
        return self._caption.text()

    def unit(self) -> str:
        return self._unit.text()

    def set_unit(self, unit: str) -> None:
        self._unit.setText(unit)
        self._tip()

    def _tip(self) -> None:
        self._number.tip_prefix = f"{self.caption()} = "
        self._number.tip_suffix = f" {self.unit()}" if self.unit() else ""
        self._number.fit()

    def set_value(self, value: float | None) -> None:
        self._value = value
        nan = value != value
        text = self.PLACEHOLDER if value is None or nan else number_text(value, self._decimals)
        if text != self._number.text():
            self._number.setText(text)


# --- connection state -------------------------------------------------------------------
_STATE_TEXT: dict[LinkState, tuple[str, str]] = {  # link state -> (text, lamp level)
    LinkState.CONNECTED: (QT_TRANSLATE_NOOP("Panels", "connected"), LEVEL_OK),
    LinkState.CONNECTING: (QT_TRANSLATE_NOOP("Panels", "connecting"), LEVEL_WARN),
    LinkState.NOT_ANSWERING: (QT_TRANSLATE_NOOP("Panels", "not answering"), LEVEL_WARN),
    LinkState.DOWN: (QT_TRANSLATE_NOOP("Panels", "link down"), LEVEL_ERROR),
    LinkState.DISCONNECTED: (QT_TRANSLATE_NOOP("Panels", "disconnected"), LEVEL_OFF),
}


def connection_display(connection: ConnectionState) -> tuple[str, str]:
    """(translated text, lamp level) of a link state."""
    text, level = _STATE_TEXT[connection.state]
    return QCoreApplication.translate(TR, text), level


# --- command results --------------------------------------------------------------------
def command_name(result: CommandResult) -> str:
    """Translated name of the command a result belongs to."""
    if result.command is not None and result.command in RUN_COMMAND_TEXT:
        return QCoreApplication.translate(TR_CONTEXT, RUN_COMMAND_TEXT[result.command])
    return QCoreApplication.translate("Panels", "command")


def command_status_text(result: CommandResult) -> str:
    """Translated GV291 meaning, decoded with the table of the result's command kind."""
    status = result.status
    if status is None:
        if result.ok:
            return QCoreApplication.translate("Panels", "done")
        return QCoreApplication.translate("Panels", "failed")
    if status.text == UNKNOWN_STATUS_TEXT.format(code=status.code):
        return QCoreApplication.translate(TR_CONTEXT, UNKNOWN_STATUS_TEXT).format(code=status.code)
    return QCoreApplication.translate(TR_CONTEXT, status.text)


def export_with_dialog(
    parent: QWidget, title: str, default_name: str, filters: str, export: Callable[[str], object]
) -> None:
    """Ask for a file name, run ``export(path)``; a failed write is shown, never raised."""
    from PySide6.QtWidgets import QFileDialog, QMessageBox  # dialogs: imported when one is shown

    path, _ = QFileDialog.getSaveFileName(parent, title, default_name, filters)
    if not path:
        return
    try:
        export(path)
    except OSError as exc:
        QMessageBox.warning(
            parent,
            title,
            QCoreApplication.translate("Export", "Could not write {path}: {error}").format(
                path=path, error=exc
            ),
        )
