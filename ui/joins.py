"""The separators that join words into one sentence, in the operator's language.

A list of names (alarms), a list of clauses ("3 errors, 4 points need upload"), a label and what
it labels ("E-stop: ..."): English writes ", ", "; " and ": "; Chinese writes the full-width
"、", "，", "；" and "：" with no space. Code that builds a sentence from parts joins them here
rather than with an English separator in the source.
"""

from __future__ import annotations

from collections.abc import Iterable

from PySide6.QtCore import QCoreApplication

__all__ = ["join_clauses", "join_names", "join_sentences", "labelled"]


def join_names(names: Iterable[str]) -> str:
    """Names in a row (alarms, points, segments): "a, b" / "a、b"."""
    return QCoreApplication.translate("JoinNames", ", ").join(names)


def join_clauses(clauses: Iterable[str]) -> str:
    """Clauses of one sentence: "3 errors, 4 points need upload" / "3 个错误，4 个点需要上传"."""
    return QCoreApplication.translate("Joins", ", ").join(clauses)


def join_sentences(parts: Iterable[str]) -> str:
    """Parts that stand apart in one line: "a; b" / "a；b"."""
    return QCoreApplication.translate("Joins", "; ").join(parts)


def labelled(label: str, text: str) -> str:
    """A label and what it says: "E-stop: ..." / "急停：..."."""
    return QCoreApplication.translate("Joins", "{label}: {text}").format(label=label, text=text)
