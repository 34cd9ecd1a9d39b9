"""Fixed widths that fit a text in every shipped language, so nothing moves when a text changes.

``both_languages(context, source)`` gives the English source and its Chinese translation (read
from the shipped .qm with a private, never installed, translator); ``fit_width`` the pixel width
of the widest of them in a widget's font, plus room for padding.

At start-up the languages not shown wait for the window's first paint (``ui/main.py``): measuring
a Chinese text loads the CJK fallback fonts, one per size and weight (~15 ms before an English
window's first paint). Between :func:`defer_other_languages` and :func:`measure_other_languages`
``both_languages`` gives the source and the language shown only, and each fit made with
:func:`fit_in_every_language` runs again when the others are measured (nothing moves then unless
a text of another language is the widest). Without that call (tests, tools) every language is
measured at once.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable

from PySide6.QtCore import QTranslator
from PySide6.QtGui import QFontMetrics
from PySide6.QtWidgets import QWidget

from ui.i18n import LANGUAGE_NAMES, SOURCE_LANGUAGE, qm_path

_translators: dict[str, QTranslator] = {}
# While the other languages wait (defer_other_languages): the language shown, and the fits to run
# again when they are measured. None: every language is measured at once.
_shown: str | None = None
_waiting_fits: list[Callable[[], object]] = []


def _translator(code: str) -> QTranslator | None:
    if code not in _translators:
        translator = QTranslator()
        if not translator.load(str(qm_path(code))):
            return None
        _translators[code] = translator
    return _translators[code]


def defer_other_languages(shown: str) -> None:
    """Until :func:`measure_other_languages`, measure the source and the language ``shown`` only."""
    global _shown
    _shown = shown
    _waiting_fits.clear()


def measure_other_languages(*, refit: bool = True) -> None:
    """Measure every language from now on, and run again the fits that waited for them (unless
    ``refit`` is False: their widgets are gone, a window closed before its first paint)."""
    global _shown
    _shown = None
    fits = list(_waiting_fits)
    _waiting_fits.clear()
    for fit in fits if refit else ():
        fit()


def fit_in_every_language(fit: Callable[[], object]) -> None:
    """Run ``fit`` (it sets widths from :func:`both_languages`) now, and again once every language
    is measured if some wait (:func:`defer_other_languages`)."""
    fit()
    if _shown is not None:
        _waiting_fits.append(fit)


def both_languages(context: str, source: str) -> list[str]:
    """``source`` and its translation in every shipped language (missing ones left out); only in
    the language shown while the others wait (:func:`defer_other_languages`)."""
    texts = [source]
    for code in LANGUAGE_NAMES:
        if code == SOURCE_LANGUAGE or (_shown is not None and code != _shown):
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
