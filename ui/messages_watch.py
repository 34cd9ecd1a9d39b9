"""The watch list's reasons in words (codes of app/watchlist/entry.py and app/link/watch_list.py),
merged into :mod:`ui.messages`' table (``reason_text`` / ``error_text`` word them)."""

from __future__ import annotations

__all__ = ["WATCH_TEMPLATES"]


def QT_TRANSLATE_NOOP(context: str, text: str) -> str:  # the name lupdate looks for
    return text


WATCH_TEMPLATES: dict[str, str] = {
    "watch_bad_type": QT_TRANSLATE_NOOP(
        "Messages", "Unknown type \u201c{type}\u201d: use float32, int16 or bits."
    ),
    "watch_bad_source": QT_TRANSLATE_NOOP("Messages", "Unknown source \u201c{source}\u201d: use gv or reg."),
    "watch_bad_number": QT_TRANSLATE_NOOP("Messages", "\u201c{text}\u201d is not a GV or register number."),
    "watch_gv_out_of_range": QT_TRANSLATE_NOOP("Messages", "GV{value} is out of range (GV0..GV{max})."),
    "watch_register_out_of_range": QT_TRANSLATE_NOOP(
        "Messages", "Register {value} is out of range (0..{max} for this type)."
    ),
    "watch_bad_name": QT_TRANSLATE_NOOP(
        "Messages", "A watched value's name is one line of at most {max} characters."
    ),
    "watch_not_a_number": QT_TRANSLATE_NOOP("Messages", "{name}: \u201c{text}\u201d is not a number."),
    "watch_not_finite": QT_TRANSLATE_NOOP("Messages", "{name}: the value must be a finite number (not NaN)."),
    "watch_value_out_of_range": QT_TRANSLATE_NOOP(
        "Messages", "{name}: {value} is out of range ({min}..{max})."
    ),
    "watch_write_control": QT_TRANSLATE_NOOP(
        "Messages", "{what}: registers 440..445 are the controller's commands; use the motion controls."
    ),
    "watch_written": QT_TRANSLATE_NOOP("Messages", "{what} = {value}: written."),
}
