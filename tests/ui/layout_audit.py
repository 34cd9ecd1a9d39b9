"""What the layout check measures: clipped texts, overlapping siblings, motion buttons too small.

Pure functions over a shown widget tree (used by ``tests/ui/test_layout.py`` and handy from a
shell when a layout looks wrong). Each returns a list of readable problems, empty when fine.

* Clipped text: a visible QLabel / QAbstractButton / QGroupBox title whose text, measured with
  its own font (``QFontMetrics.horizontalAdvance``) plus what the style adds around it (button
  bevel, check box indicator, label margins), is wider than the widget. A word-wrapped label
  is clipped when the height it needs for its width is more than it has. A widget that elides
  on purpose carries the dynamic property ``elide=True`` and must have a tooltip instead.
* Overlap: two visible sibling widgets whose geometries intersect (Qt's own helper children,
  named ``qt_*``, popups, empty unstyled labels, which paint nothing, and widgets wholly outside
  their parent, where Qt parks the docks tabbed behind the current one, are left out).
* Motion buttons (dynamic property ``motion=True``): at least ``min_height`` px high.
"""

from __future__ import annotations

import re
from collections.abc import Iterator

from PySide6.QtCore import QSize, Qt
from PySide6.QtGui import QFontMetrics, QTextDocument
from PySide6.QtGui import Qt as GuiQt
from PySide6.QtWidgets import (
    QAbstractButton,
    QCheckBox,
    QFrame,
    QGroupBox,
    QLabel,
    QPushButton,
    QRadioButton,
    QStyle,
    QStyleOptionButton,
    QStyleOptionGroupBox,
    QStyleOptionToolButton,
    QToolButton,
    QWidget,
)

SLACK_PX = 1  # rounding of fractional advances


def visible_widgets(root: QWidget) -> Iterator[QWidget]:
    """``root`` and every descendant that is shown on screen (depth first)."""
    if not root.isVisible():
        return
    yield root
    for child in root.findChildren(QWidget, options=Qt.FindChildOption.FindDirectChildrenOnly):
        if child.isWindow():
            continue  # dialogs, menus, floating docks: checked on their own
        yield from visible_widgets(child)


def _plain(text: str) -> str:
    return re.sub(r"&(?!&)", "", text).replace("&&", "&")  # mnemonics take no room


def _label_width(label: QLabel) -> int:
    text = label.text()
    if label.textFormat() == Qt.TextFormat.RichText or (
        label.textFormat() == Qt.TextFormat.AutoText and GuiQt.mightBeRichText(text)
    ):
        doc = QTextDocument()
        doc.setDefaultFont(label.font())
        doc.setDocumentMargin(0)
        doc.setHtml(text)
        return int(doc.idealWidth() + 0.999)
    metrics = label.fontMetrics()
    return max(metrics.horizontalAdvance(line) for line in text.split("\n"))


def _label_room(label: QLabel) -> int:
    room = label.contentsRect().width() - 2 * label.margin()
    indent = label.indent()
    if indent < 0 and label.frameWidth() > 0:
        indent = label.fontMetrics().horizontalAdvance("x") // 2 - label.margin()
    side = Qt.AlignmentFlag.AlignLeft | Qt.AlignmentFlag.AlignRight
    if not label.alignment() & side:
        indent = 0  # QLabel indents only on the side it is aligned to
    return room - max(0, indent)


def _button_needs(button: QAbstractButton) -> int:
    """Text advance plus icon plus what the style puts around the contents."""
    metrics = button.fontMetrics()
    text = _plain(button.text())
    text_width = metrics.horizontalAdvance(text)
    icon = 0 if button.icon().isNull() else button.iconSize().width() + 4
    style = button.style()
    contents = QSize(text_width + icon, metrics.height())
    if isinstance(button, QToolButton):
        tool_option = QStyleOptionToolButton()
        tool_option.initFrom(button)
        tool_option.toolButtonStyle = button.toolButtonStyle()
        extra = 0
        if button.popupMode() == QToolButton.ToolButtonPopupMode.MenuButtonPopup:
            extra = style.pixelMetric(QStyle.PixelMetric.PM_MenuButtonIndicator, tool_option, button)
        size = style.sizeFromContents(QStyle.ContentsType.CT_ToolButton, tool_option, contents, button)
        return size.width() + extra
    option = QStyleOptionButton()
    option.initFrom(button)
    if isinstance(button, QCheckBox | QRadioButton):
        kind = (
            QStyle.ContentsType.CT_CheckBox
            if isinstance(button, QCheckBox)
            else QStyle.ContentsType.CT_RadioButton
        )
        option.text = text  # the style adds the label spacing only when there is a text
        return style.sizeFromContents(kind, option, contents, button).width()
    if isinstance(button, QPushButton):
        option.text = ""  # no text: the style's minimum width for texts does not apply
        if button.menu() is not None:
            contents.setWidth(
                contents.width()
                + style.pixelMetric(QStyle.PixelMetric.PM_MenuButtonIndicator, option, button)
            )
        return style.sizeFromContents(QStyle.ContentsType.CT_PushButton, option, contents, button).width()
    return text_width + icon


def clipped_texts(root: QWidget) -> list[str]:
    problems: list[str] = []
    for widget in visible_widgets(root):
        problem = _clipped(widget)
        if problem is not None:
            problems.append(problem)
    return problems


def _clipped(widget: QWidget) -> str | None:
    """What of ``widget``'s text does not fit, by the kind of widget; None when it fits."""
    if widget.property("elide"):
        return _elided_without_tooltip(widget)
    if isinstance(widget, QLabel):
        return _clipped_label(widget)
    if isinstance(widget, QAbstractButton):
        return _clipped_button(widget)
    if isinstance(widget, QGroupBox) and widget.title():
        return _clipped_title(widget)
    return None


def _elided_without_tooltip(widget: QWidget) -> str | None:
    """A widget that elides on purpose must say its whole text in a tooltip."""
    shown = widget.text() if isinstance(widget, QLabel | QAbstractButton) else ""
    if shown and not widget.toolTip():
        return f"{describe(widget)} elides on purpose but has no tooltip"
    return None


def _clipped_label(widget: QLabel) -> str | None:
    if not widget.text() or (widget.pixmap() is not None and not widget.pixmap().isNull()):
        return None
    if widget.wordWrap():
        needed = widget.heightForWidth(widget.width())
        if needed > widget.height() + SLACK_PX:
            return f"{describe(widget)} needs {needed} px of height, has {widget.height()}"
        return None
    needed, room = _label_width(widget), _label_room(widget)
    if needed > room + SLACK_PX:
        return f"{describe(widget)} needs {needed} px, has {room}"
    return None


def _clipped_button(widget: QAbstractButton) -> str | None:
    if not widget.text():
        return None
    needed = _button_needs(widget)
    if needed > widget.width() + SLACK_PX:
        return f"{describe(widget)} needs {needed} px, has {widget.width()}"
    return None


def _clipped_title(widget: QGroupBox) -> str | None:
    option = QStyleOptionGroupBox()
    option.initFrom(widget)
    option.text = widget.title()
    option.subControls = QStyle.SubControl.SC_GroupBoxLabel
    if widget.isCheckable():
        option.subControls |= QStyle.SubControl.SC_GroupBoxCheckBox
    metrics = QFontMetrics(widget.font())
    needed = metrics.horizontalAdvance(_plain(widget.title())) + 2 * metrics.horizontalAdvance(" ")
    if widget.isCheckable():
        needed += widget.style().pixelMetric(QStyle.PixelMetric.PM_IndicatorWidth, option, widget) + 6
    if needed > widget.width() + SLACK_PX:
        return f"{describe(widget)} (title) needs {needed} px, has {widget.width()}"
    return None


def paints_nothing(widget: QWidget) -> bool:
    """An empty label without frame or style (a unit that is not shown, say) covers nothing."""
    style = widget.styleSheet()
    return (
        isinstance(widget, QLabel)
        and not widget.text()
        and widget.frameShape() == QFrame.Shape.NoFrame
        and "background" not in style
        and "border" not in style
        and (widget.pixmap() is None or widget.pixmap().isNull())
    )


def overlapping_siblings(root: QWidget) -> list[str]:
    problems: list[str] = []
    for parent in visible_widgets(root):
        children = [
            c
            for c in parent.findChildren(QWidget, options=Qt.FindChildOption.FindDirectChildrenOnly)
            if c.isVisible()
            and not c.isWindow()
            and not c.objectName().startswith("qt_")
            and not c.property("overlay")  # laid over the others on purpose (the alarm banner)
            and c.width() > 0
            and c.height() > 0
            and not paints_nothing(c)
            and c.geometry().intersects(parent.rect())
        ]
        for i, first in enumerate(children):
            for second in children[i + 1 :]:
                if first.geometry().intersects(second.geometry()):
                    shared = first.geometry().intersected(second.geometry())
                    problems.append(
                        f"{describe(first)} and {describe(second)} overlap by "
                        f"{shared.width()}×{shared.height()} px in {describe(parent)}"
                    )
    return problems


def small_motion_buttons(root: QWidget, min_height: int) -> list[str]:
    return [
        f"{describe(w)} is {w.height()} px high, motion buttons need {min_height}"
        for w in visible_widgets(root)
        if w.property("motion") and w.height() < min_height
    ]


def describe(widget: QWidget) -> str:
    name = widget.objectName()
    text = ""
    if isinstance(widget, QLabel | QAbstractButton):
        text = widget.text()
    elif isinstance(widget, QGroupBox):
        text = widget.title()
    owner = widget.parentWidget()
    while owner is not None and not owner.objectName():
        owner = owner.parentWidget()
    where = f" in {owner.objectName()}" if owner is not None else ""
    label = f"{type(widget).__name__}"
    if name:
        label += f"#{name}"
    if text:
        label += f" {text[:30]!r}"
    return label + where
