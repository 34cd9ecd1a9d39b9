"""Translator loading and the runtime language switch.

English is the source language (no translator). Other languages load
``ui/i18n/teachpad_<code>.qm`` plus Qt's own ``qtbase_<code>.qm`` (standard dialog buttons).
Installing or removing a translator makes Qt send ``QEvent.LanguageChange`` to every widget;
each panel re-translates its texts in ``changeEvent``.
"""

from __future__ import annotations

from pathlib import Path

from PySide6.QtCore import QCoreApplication, QLibraryInfo, QTranslator

from app.protocol.enums import TR_CONTEXT

I18N_DIR = Path(__file__).resolve().parent / "i18n"
SOURCE_LANGUAGE = "en"

# Language code -> its name written in that language (menus show it untranslated).
LANGUAGE_NAMES: dict[str, str] = {
    "en": "English",
    "zh_CN": "简体中文",
}


def qm_path(code: str) -> Path:
    return I18N_DIR / f"teachpad_{code}.qm"


def protocol_text(text: str) -> str:
    """An ``app.protocol.enums`` description (marked QT_TRANSLATE_NOOP) in the current language."""
    return QCoreApplication.translate(TR_CONTEXT, text)


class Translator:
    """Owns the installed translators of one application; ``set_language`` switches at runtime."""

    def __init__(self) -> None:
        self._installed: list[QTranslator] = []
        self._language = SOURCE_LANGUAGE

    @property
    def language(self) -> str:
        return self._language

    def set_language(self, code: str) -> bool:
        """Switch to ``code``; returns False (and stays in English) when its file is missing."""
        if code not in LANGUAGE_NAMES:
            code = SOURCE_LANGUAGE
        if code == self._language and (code == SOURCE_LANGUAGE or self._installed):
            return True
        self._remove()
        self._language = SOURCE_LANGUAGE
        if code == SOURCE_LANGUAGE:
            return True
        ours = QTranslator()
        if not ours.load(str(qm_path(code))):
            return False
        qt_base = QTranslator()
        qt_dir = QLibraryInfo.path(QLibraryInfo.LibraryPath.TranslationsPath)
        if qt_base.load(f"qtbase_{code}", qt_dir):
            QCoreApplication.installTranslator(qt_base)
            self._installed.append(qt_base)
        QCoreApplication.installTranslator(ours)
        self._installed.append(ours)
        self._language = code
        return True

    def uninstall(self) -> None:
        """Remove our translators (the application goes back to English)."""
        self._remove()
        self._language = SOURCE_LANGUAGE

    def _remove(self) -> None:
        for translator in self._installed:
            QCoreApplication.removeTranslator(translator)
        self._installed.clear()
