"""The traffic inspector's meaning column in the operator's language.

:func:`app.protocol.frames.decode_frame` sums a frame up in English (``read status (560–583)``,
``ack teach enable (440 ← 0x80)``, ``status (560–583): mode=auto, program=running``); the stored
meaning, the filter and the export keep that text. The table shows it in the current language:
the verb, the register block, a command's action and the status fields in the protocol's words
(context "Protocol"); values, register numbers and names stay as they are. :class:`MeaningWords`
caches what it worded (the table asks for a meaning on every repaint).
"""

from __future__ import annotations

import re

from PySide6.QtCore import QCoreApplication

from ui.joins import join_clauses, join_names

__all__ = ["MeaningWords"]

_CONTEXT = "TrafficWords"
_CACHE_SIZE = 4096


def QT_TRANSLATE_NOOP(context: str, text: str) -> str:
    return text


_VERBS: tuple[tuple[re.Pattern[str], str], ...] = (
    (re.compile(r"read (?P<what>.+)"), QT_TRANSLATE_NOOP("TrafficWords", "read {what}")),
    (re.compile(r"ack write (?P<what>.+)"), QT_TRANSLATE_NOOP("TrafficWords", "write acknowledged: {what}")),
    (re.compile(r"ack (?P<what>.+)"), QT_TRANSLATE_NOOP("TrafficWords", "acknowledged: {what}")),
    (re.compile(r"malformed (?P<what>.+)"), QT_TRANSLATE_NOOP("TrafficWords", "malformed: {what}")),
    (re.compile(r"write (?P<what>.+)"), QT_TRANSLATE_NOOP("TrafficWords", "write {what}")),
    (
        re.compile(r"exception (?P<code>[0-9A-F]{2}) (?P<name>.+)"),
        QT_TRANSLATE_NOOP("TrafficWords", "exception {code}: {name}"),
    ),
)
_WHOLE = {
    "truncated frame": QT_TRANSLATE_NOOP("TrafficWords", "truncated frame"),
    "exception (code missing)": QT_TRANSLATE_NOOP("TrafficWords", "exception (code missing)"),
}
# app.protocol.naming's blocks, as written there
_BLOCKS = {
    "pose X..C": QT_TRANSLATE_NOOP("TrafficWords", "pose X..C"),
    "pose, ext axes, joints": QT_TRANSLATE_NOOP("TrafficWords", "pose, ext axes, joints"),
    "ext axes J7..J11": QT_TRANSLATE_NOOP("TrafficWords", "ext axes J7..J11"),
    "joints J1..J6": QT_TRANSLATE_NOOP("TrafficWords", "joints J1..J6"),
    "status": QT_TRANSLATE_NOOP("TrafficWords", "status"),
    "clock": QT_TRANSLATE_NOOP("TrafficWords", "clock"),
    "command status": QT_TRANSLATE_NOOP("TrafficWords", "command status"),
}
_FIELDS = {
    "mode": QT_TRANSLATE_NOOP("TrafficWords", "mode"),
    "program": QT_TRANSLATE_NOOP("TrafficWords", "program"),
    "alarms": QT_TRANSLATE_NOOP("TrafficWords", "alarms"),
    "clock": QT_TRANSLATE_NOOP("TrafficWords", "clock"),
}
_BLOCK = re.compile(r"(?P<name>[A-Za-z][A-Za-z .,0-9]*?)(?P<rest> (?:GV\d+ )?\([^)]*\))")
_ACTION = re.compile(r"(?P<action>[a-z][a-z ]*[a-z]) (?P<register>\(\d+ ← [^)]+\))")
# raw registers: "regs 107–109", "reg 1", an answer's "3 regs = 0x0001, ..." (its count first)
_REGISTERS = re.compile(r"(?:(?P<count>\d+) )?regs? (?P<rest>(?:=|\d).*)")
_REGS_COUNTED = QT_TRANSLATE_NOOP("TrafficWords", "{n} registers {rest}")
_REGS = QT_TRANSLATE_NOOP("TrafficWords", "registers {rest}")
_FIELD = re.compile(r"(?P<key>[A-Za-z0-9]+)=(?P<value>.*)")
_WORDS = re.compile(r"(?P<words>[A-Za-z][A-Za-z ]*[a-z])(?P<rest> \(.*\))?")
_INVALID = QT_TRANSLATE_NOOP("TrafficWords", "invalid")
_NONE = QT_TRANSLATE_NOOP("TrafficWords", "none")


def _tr(text: str, context: str = _CONTEXT) -> str:
    return QCoreApplication.translate(context, text)


def _protocol(text: str) -> str:
    return QCoreApplication.translate("Protocol", text)


def _subject(text: str) -> str:
    """A register block ("status (560–583)"), a command write ("teach enable (440 ← 0x80)"), or
    a block with its fields ("status (560–583): mode=auto, program=running")."""
    head, sep, fields = text.partition(": ")
    block = _BLOCK.fullmatch(head)
    action = _ACTION.fullmatch(head)
    registers = _REGISTERS.fullmatch(head)
    if registers is not None:
        count = registers["count"]
        rest = registers["rest"]
        head = _tr(_REGS_COUNTED).format(n=count, rest=rest) if count else _tr(_REGS).format(rest=rest)
    elif block is not None and block["name"] in _BLOCKS:
        head = _tr(_BLOCKS[block["name"]]) + block["rest"]
    elif action is not None:
        head = f"{_protocol(action['action'])} {action['register']}"
    if not sep:
        return head
    return head + _tr(QT_TRANSLATE_NOOP("TrafficWords", ": ")) + join_clauses(map(_field, fields.split(", ")))


def _field(text: str) -> str:
    match = _FIELD.fullmatch(text)
    if match is None or not (match["key"] in _FIELDS or match["key"] == "GV291"):
        return text
    key = _tr(_FIELDS[match["key"]]) if match["key"] in _FIELDS else match["key"]
    return f"{key}={join_names(map(_value, match['value'].split(' + ')))}"


def _value(text: str) -> str:
    """A field's value in the protocol's words ("work mode error (0x01)"), its code kept."""
    match = _WORDS.fullmatch(text)
    if match is None:
        return text
    words = match["words"]
    worded = _tr(words) if words in (_INVALID, _NONE) else _protocol(words)
    return worded + (match["rest"] or "")


def meaning_words(text: str) -> str:
    """``text`` (an English frame summary) in the current language."""
    if text in _WHOLE:
        return _tr(_WHOLE[text])
    for pattern, sentence in _VERBS:
        match = pattern.fullmatch(text)
        if match is not None:
            fields = dict(match.groupdict())
            if "what" in fields:
                fields["what"] = _subject(fields["what"])
            if "name" in fields:
                fields["name"] = _tr(fields["name"], "Messages")  # the Modbus exception's name
            return _tr(sentence).format(**fields)
    return _subject(text)


class MeaningWords:
    """:func:`meaning_words` with a cache; off (the English as stored) in English."""

    def __init__(self) -> None:
        self._cache: dict[str, str] = {}
        self.active = False

    def retranslate(self) -> None:
        self._cache.clear()
        self.active = _tr(_VERBS[0][1]) != _VERBS[0][1]

    def __call__(self, text: str) -> str:
        if not self.active:
            return text
        worded = self._cache.get(text)
        if worded is None:
            if len(self._cache) >= _CACHE_SIZE:
                self._cache.clear()
            worded = self._cache[text] = meaning_words(text)
        return worded
