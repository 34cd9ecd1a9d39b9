"""Qt's own words that its shipped ``qtbase_zh_CN.qm`` leaves in English.

:class:`~ui.i18n.Translator` loads Qt's translations (``qtbase_<code>.qm`` from
``QLibraryInfo.TranslationsPath``; the bundle keeps them, packaging/teachpad.spec) beside ours.
Qt's Chinese file still has the file dialog's "Look in:" and "Files of type:" only without their
accelerators, so the dialog showed "&Look in:" and "Files of &type:" in English. Marked here in
Qt's own context, lupdate collects them into our .ts; our translator is installed after Qt's and
answers first.
"""

from __future__ import annotations

from PySide6.QtCore import QT_TRANSLATE_NOOP

QT_OWN_WORDS = (
    QT_TRANSLATE_NOOP("QFileDialog", "&Look in:"),
    QT_TRANSLATE_NOOP("QFileDialog", "Files of &type:"),
)
