"""Fixed widths that fit a text in every shipped language, so nothing moves when a text changes.

``both_languages(context, source)`` gives the English source and its Chinese translation (read
from the shipped .qm with a private, never installed, translator); ``fit_width`` the pixel width
of the widest of them in a widget's font, plus room for padding.
"""

from __future__ import annotations

from collections.abc import Iterable

from PySide6.QtCore import QTranslator
from PySide6.QtGui import QFontMetrics
from PySide6.QtWidgets import QWidget

from ui.i18n import LANGUAGE_NAMES, SOURCE_LANGUAGE, qm_path

_translators: dict[str, QTranslator] = {}


def _translator(code: str) -> QTranslator | None:
    if code not in _translators:
        translator = QTranslator()
        if not translator.load(str(qm_path(code))):
            return None
        _translators[code] = translator
    return _translators[code]


def both_languages(context: str, source: str) -> list[str]:
    """``source`` and its translation in every shipped language (missing ones left out)."""
    texts = [source]
    for code in LANGUAGE_NAMES:
        if code == SOURCE_LANGUAGE:
            continue
        translator = _translator(code)
        text = translator.translate(context, source) if translator is not None else ""
        if text:
            texts.append(text)
    return texts


def fit_width(widget: QWidget, texts: Iterable[str], padding: int = 0) -> int:
    """Pixels for the widest of ``texts`` in ``widget``'s font (every line), plus ``padding``."""
    metrics = QFontMetrics(widget.font())
    widest = max((metrics.horizontalAdvance(line) for text in texts for line in text.split("\n")), default=0)
    return widest + padding
