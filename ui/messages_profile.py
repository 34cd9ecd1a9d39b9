"""A robot profile file that cannot be used (:class:`app.view3d.profile.ProfileError`, codes
``profile_*``), in the operator's language: the file, the field (a joint, a JSON key), then
why. The JSON keys (``min_deg``, ``home_deg``) stay as written in the file.

Also a settings file -- the register profile, the safety profile -- that cannot be read or is not
JSON (codes ``settings_*``, :func:`app.points.atomic.read_settings_text`), and why a file could
not be read: by its errno or its problem's code, never the OS's English (strerror)."""

from __future__ import annotations

import errno as errnos
import os
from collections.abc import Mapping
from typing import Any

from PySide6.QtCore import QCoreApplication

from app.errors import TeachPadError
from ui.joins import labelled

__all__ = ["is_profile_code", "profile_text", "register_problem_text"]

_CONTEXT = "ProfileWords"


def QT_TRANSLATE_NOOP(context: str, text: str) -> str:
    return text


_SENTENCES: dict[str, str] = {
    "profile_invalid": QT_TRANSLATE_NOOP("ProfileWords", "the robot profile cannot be used"),
    "profile_not_number": QT_TRANSLATE_NOOP("ProfileWords", "{value} is not a finite number"),
    "profile_not_six": QT_TRANSLATE_NOOP(
        "ProfileWords", "expected a list of six numbers X Y Z A B C, got {value}"
    ),
    "profile_joint_not_object": QT_TRANSLATE_NOOP("ProfileWords", "expected an object with {keys}"),
    "profile_missing": QT_TRANSLATE_NOOP("ProfileWords", "missing {keys}"),
    "profile_name_not_text": QT_TRANSLATE_NOOP("ProfileWords", "the name {value} is not text"),
    "profile_limits": QT_TRANSLATE_NOOP("ProfileWords", "min_deg {low} is not below max_deg {high}"),
    "profile_not_object": QT_TRANSLATE_NOOP("ProfileWords", "a robot profile is a JSON object"),
    "profile_format": QT_TRANSLATE_NOOP(
        "ProfileWords", "not a robot profile: its format is {value}, expected {expected}"
    ),
    "profile_version": QT_TRANSLATE_NOOP(
        "ProfileWords", "profile version {value} is not supported (this TeachPad reads version {expected})"
    ),
    "profile_joints": QT_TRANSLATE_NOOP("ProfileWords", "joints: expected a list of 1 to {most} joints"),
    "profile_home": QT_TRANSLATE_NOOP("ProfileWords", "home_deg: expected {count} numbers, one per joint"),
    "profile_too_large": QT_TRANSLATE_NOOP("ProfileWords", "too large for a robot profile (over {kb} kB)"),
    "profile_unreadable": QT_TRANSLATE_NOOP("ProfileWords", "cannot read the robot profile ({cause})"),
    "profile_not_utf8": QT_TRANSLATE_NOOP("ProfileWords", "the robot profile is not UTF-8 text"),
    "profile_not_json": QT_TRANSLATE_NOOP("ProfileWords", "not valid JSON (line {line}, column {column})"),
    # a settings file (app/points/atomic.py): {what} is the register or the safety profile
    "settings_unreadable": QT_TRANSLATE_NOOP("ProfileWords", "cannot read the {what} ({cause})"),
    "settings_not_utf8": QT_TRANSLATE_NOOP("ProfileWords", "the {what} is not UTF-8 text"),
    "settings_not_json": QT_TRANSLATE_NOOP(
        "ProfileWords", "the {what} is not valid JSON (line {line}, column {column})"
    ),
}
_WHAT = {
    "register profile": QT_TRANSLATE_NOOP("ProfileWords", "register profile"),
    "safety profile": QT_TRANSLATE_NOOP("ProfileWords", "safety profile"),
}
# a settings file's problem code (app/points/atomic.py read_limited) as a cause
_PROBLEMS = {
    "no_such_file": errnos.ENOENT,
    "permission_denied": errnos.EACCES,
    "is_a_directory": errnos.EISDIR,
}
_TOO_LARGE = QT_TRANSLATE_NOOP("ProfileWords", "the file is too large ({size} bytes, at most {limit})")
# why the file could not be read, by its errno (the OS's own English, strerror, is not the operator's)
_CAUSES: dict[int, str] = {
    errnos.ENOENT: QT_TRANSLATE_NOOP("ProfileWords", "the file does not exist"),
    errnos.EACCES: QT_TRANSLATE_NOOP("ProfileWords", "permission denied"),
    errnos.EPERM: QT_TRANSLATE_NOOP("ProfileWords", "permission denied"),
    errnos.EISDIR: QT_TRANSLATE_NOOP("ProfileWords", "it is a folder, not a file"),
    errnos.ENOTDIR: QT_TRANSLATE_NOOP("ProfileWords", "a folder on its path is a file"),
    errnos.ENAMETOOLONG: QT_TRANSLATE_NOOP("ProfileWords", "the file name is too long"),
    errnos.EIO: QT_TRANSLATE_NOOP("ProfileWords", "the disk could not be read"),
}
_OTHER_CAUSE = QT_TRANSLATE_NOOP("ProfileWords", "system error {errno}")
_JOINT = QT_TRANSLATE_NOOP("ProfileWords", "joint {n}")
_JOINT_KEY = QT_TRANSLATE_NOOP("ProfileWords", "joint {n} {key}")


def _tr(text: str) -> str:
    return QCoreApplication.translate(_CONTEXT, text)


def is_profile_code(code: str) -> bool:
    return code in _SENTENCES


def _cause(args: Mapping[str, Any]) -> str:
    """Why the file could not be read: its errno in words (an older record without one: the errno
    whose OS text it is, on this machine); an errno with no words of its own by number."""
    code = args.get("errno")
    cause = str(args.get("cause", ""))
    if not isinstance(code, int):
        code = next((c for c in _CAUSES if os.strerror(c) == cause), None)
    if code in _CAUSES:
        return _tr(_CAUSES[code])
    if isinstance(code, int):
        return _tr(_OTHER_CAUSE).format(errno=code)
    return cause


def _settings_fields(args: Mapping[str, Any], fields: dict[str, str]) -> None:
    """A settings file's kind and cause in words."""
    what = str(args.get("what", ""))
    fields["what"] = _tr(_WHAT[what]) if what in _WHAT else what
    problem = str(args.get("cause", ""))
    if problem == "file_too_large":
        fields["cause"] = _tr(_TOO_LARGE).format(size=args.get("size", "?"), limit=args.get("limit", "?"))
    elif problem in _PROBLEMS:
        fields["cause"] = _tr(_CAUSES[_PROBLEMS[problem]])
    else:
        fields["cause"] = _cause(args)


def _place(args: Mapping[str, Any]) -> str:
    joint, key = args.get("joint"), args.get("key")
    if joint is not None and key:
        return _tr(_JOINT_KEY).format(n=joint, key=key)
    if joint is not None:
        return _tr(_JOINT).format(n=joint)
    return str(key or "")


def profile_text(code: str, args: Mapping[str, Any]) -> str | None:
    """The sentence for a ``profile_*`` code and its params; None for another code."""
    sentence = _SENTENCES.get(code)
    if sentence is None:
        return None
    fields = {k: str(v) for k, v in args.items()}
    if code == "profile_unreadable":
        fields["cause"] = _cause(args)
    elif code.startswith("settings_"):
        _settings_fields(args, fields)
    try:
        text = _tr(sentence).format(**fields)
    except KeyError:
        text = _tr(_SENTENCES["profile_invalid"])
    place = _place(args)
    if place and code not in ("profile_joints", "profile_home"):  # (these name their key)
        text = labelled(place, text)
    file = args.get("file")
    return labelled(str(file), text) if file else text


_FALLBACK = QT_TRANSLATE_NOOP(
    "ProfileWords",
    "{why}; the remembered connection settings are used until an administrator saves a register profile",
)


def register_problem_text(error: TeachPadError) -> str:
    """The register profile in force could not be used (app.safety.register_profile
    read_active_profile): why, in words where its code is known, and what TeachPad does instead."""
    why = profile_text(error.code, error.params) or str(error)
    return _tr(_FALLBACK).format(why=why)
