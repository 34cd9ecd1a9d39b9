"""The on-screen numeric keypad of touch mode: tap a number field, type, OK.

:class:`KeypadDialog` has digits, sign, decimal point, backspace, clear, OK / Cancel, and
respects the field's range and decimals (OK is off while the value is outside the range). A
field with ``keypad_range()`` (:class:`~ui.keypad_range.RangedField`: an axis's offset) narrows
the range to what it allows now, and its note says why (the axis's limits, where it stands).
:func:`install_keypad` puts an opener on a QSpinBox / QDoubleSpinBox; ``ui.touch`` switches
the openers with touch mode.
"""

from __future__ import annotations

from PySide6.QtCore import QEvent, QObject, Qt, Signal, Slot
from PySide6.QtGui import QKeyEvent
from PySide6.QtWidgets import (
    QAbstractSpinBox,
    QDialog,
    QDoubleSpinBox,
    QGridLayout,
    QLabel,
    QLineEdit,
    QPushButton,
    QSpinBox,
    QVBoxLayout,
    QWidget,
)

from ui.keypad_range import RangedField

KEYPAD_KEY_SIZE = 56  # px, a key of the on-screen keypad
MINUS = "−"  # shown; "-" is what the value parser reads

NumberField = QSpinBox | QDoubleSpinBox


class KeypadDialog(QDialog):
    """A popup numeric keypad for one number field. ``text()`` is what was typed; ``value()``
    the number (None when it is not a number or outside the field's range)."""

    def __init__(self, field: NumberField, parent: QWidget | None = None) -> None:
        super().__init__(parent or field.window())
        self.setObjectName("Keypad")
        self.setModal(True)
        self._minimum = float(field.minimum())
        self._maximum = float(field.maximum())
        offered = field.keypad_range() if isinstance(field, RangedField) else None
        self._note = ""
        if offered is not None:  # what the field allows now, within its own range
            self._minimum = max(self._minimum, offered.low)
            self._maximum = min(self._maximum, offered.high)
            self._note = offered.note
        self._decimals = field.decimals() if isinstance(field, QDoubleSpinBox) else 0
        self.display = QLineEdit(self)
        self.display.setObjectName("KeypadDisplay")
        self.display.setReadOnly(True)
        self.display.setAlignment(Qt.AlignmentFlag.AlignRight)
        font = self.display.font()
        font.setPointSizeF(font.pointSizeF() * 1.6)
        self.display.setFont(font)
        self.display.setMinimumHeight(KEYPAD_KEY_SIZE - 8)
        self.range_label = QLabel(self)
        self.range_label.setWordWrap(True)
        self.keys: dict[str, QPushButton] = {}
        grid = QGridLayout()
        grid.setSpacing(6)
        layout_keys = ("7", "8", "9", "4", "5", "6", "1", "2", "3", "sign", "0", ".")
        for i, key in enumerate(layout_keys):
            self._key(key, MINUS if key == "sign" else key, grid, i // 3, i % 3)
        self._key("back", "⌫", grid, 0, 3)
        self._key("clear", "C", grid, 1, 3)
        self.ok_button = self._key("ok", "", grid, 2, 3, rows=2)
        self.cancel_button = QPushButton(self)
        self.cancel_button.setMinimumHeight(KEYPAD_KEY_SIZE)
        self.cancel_button.clicked.connect(self.reject)
        self.ok_button.setDefault(True)
        self.keys["sign"].setEnabled(self._minimum < 0)
        self.keys["."].setEnabled(self._decimals > 0)
        layout = QVBoxLayout(self)
        layout.addWidget(self.display)
        layout.addWidget(self.range_label)
        layout.addLayout(grid)
        layout.addWidget(self.cancel_button)
        value = field.value()
        self._text = f"{value:.{self._decimals}f}".rstrip("0").rstrip(".") if self._decimals else str(value)
        self._fresh = True  # the first key replaces the old value
        self.retranslate()
        self._show()

    def _key(
        self, key: str, text: str, grid: QGridLayout, row: int, column: int, rows: int = 1
    ) -> QPushButton:
        button = QPushButton(text, self)
        button.setObjectName(f"key_{key}")
        button.setMinimumSize(KEYPAD_KEY_SIZE, KEYPAD_KEY_SIZE * rows + 6 * (rows - 1))
        button.setFocusPolicy(Qt.FocusPolicy.NoFocus)
        button.clicked.connect(lambda _=False, k=key: self.press(k))
        grid.addWidget(button, row, column, rows, 1)
        self.keys[key] = button
        return button

    def retranslate(self) -> None:
        self.setWindowTitle(self.tr("Enter a value"))
        self.ok_button.setText(self.tr("OK"))
        self.cancel_button.setText(self.tr("Cancel"))
        self.keys["back"].setToolTip(self.tr("Delete the last digit"))
        self.keys["clear"].setToolTip(self.tr("Clear"))
        low, high = (f"{v:.{self._decimals}f}" for v in (self._minimum, self._maximum))
        text = self.tr("From {low} to {high}").format(low=low, high=high)
        self.range_label.setText(f"{text}\n{self._note}" if self._note else text)

    def changeEvent(self, event: QEvent) -> None:
        if event.type() == QEvent.Type.LanguageChange:
            self.retranslate()
        super().changeEvent(event)

    # --- typing -----------------------------------------------------------------------
    def text(self) -> str:
        return self._text

    def value(self) -> float | None:
        try:
            number = float(self._text)
        except ValueError:
            return None
        return number if self._minimum <= number <= self._maximum else None

    @Slot(str)
    def press(self, key: str) -> None:
        """One key: a digit, ``.``, ``sign``, ``back``, ``clear`` or ``ok``."""
        if key == "ok":
            if self.value() is not None:
                self.accept()
            return
        text = "" if self._fresh and key not in ("sign", "back") else self._text
        self._fresh = False
        edited = self._edited(text, key)
        if edited is None:
            return
        self._text = edited
        self._show()

    def _edited(self, text: str, key: str) -> str | None:
        """``text`` after the editing ``key`` (None: the key is refused, the text stays)."""
        if key == "back":
            return text[:-1]
        if key == "clear":
            return ""
        if key == "sign":
            if self._minimum < 0:
                return text[1:] if text.startswith("-") else "-" + text
            return text
        if key == ".":
            if self._decimals > 0 and "." not in text:
                return (text or "0") + "."
            return text
        if key.isdigit():
            return self._with_digit(text, key)
        return text

    def _with_digit(self, text: str, digit: str) -> str | None:
        if "." in text and len(text.split(".", 1)[1]) >= self._decimals:
            return None  # no more decimals than the field keeps
        if text in ("0", "-0"):
            text = text[:-1]  # no leading zeros
        return text + digit

    def keyPressEvent(self, event: QKeyEvent) -> None:
        keys = {
            Qt.Key.Key_Backspace: "back",
            Qt.Key.Key_Minus: "sign",
            Qt.Key.Key_Period: ".",
            Qt.Key.Key_Comma: ".",
            Qt.Key.Key_Return: "ok",
            Qt.Key.Key_Enter: "ok",
        }
        text = event.text()
        if text.isdigit():
            self.press(text)
        elif event.key() in keys:
            self.press(keys[Qt.Key(event.key())])
        else:
            super().keyPressEvent(event)

    def _show(self) -> None:
        self.display.setText(self._text.replace("-", MINUS))
        self.ok_button.setEnabled(self.value() is not None)


class _KeypadOpener(QObject):
    """On a spin box's line edit: a tap opens the keypad; OK writes the value."""

    opened = Signal(KeypadDialog)

    def __init__(self, field: NumberField) -> None:
        super().__init__(field)
        self.setObjectName("KeypadOpener")
        self._field = field
        self.enabled = True
        field.lineEdit().installEventFilter(self)

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        if (
            self.enabled
            and event.type() == QEvent.Type.MouseButtonRelease
            and self._field.isEnabled()
            and not self._field.isReadOnly()
        ):
            self.open()
            return True
        return super().eventFilter(watched, event)

    def open(self) -> KeypadDialog:
        dialog = KeypadDialog(self._field)
        dialog.setAttribute(Qt.WidgetAttribute.WA_DeleteOnClose)
        dialog.accepted.connect(lambda: self._apply(dialog))
        dialog.open()
        self.opened.emit(dialog)
        return dialog

    def _apply(self, dialog: KeypadDialog) -> None:
        value = dialog.value()
        if value is None:
            return
        if isinstance(self._field, QSpinBox):
            self._field.setValue(round(value))
        else:
            self._field.setValue(value)
        self._field.editingFinished.emit()  # fields that apply on editing finished do so now


def install_keypad(field: NumberField, enabled: bool) -> None:
    """Tapping ``field`` opens the keypad while ``enabled`` (the opener is added once)."""
    opener = keypad_opener(field)
    if opener is None:
        if not enabled:
            return
        opener = _KeypadOpener(field)
    opener.enabled = enabled


def keypad_opener(field: QAbstractSpinBox) -> _KeypadOpener | None:
    found = field.findChild(_KeypadOpener, "KeypadOpener", Qt.FindChildOption.FindDirectChildrenOnly)
    return found if isinstance(found, _KeypadOpener) else None
