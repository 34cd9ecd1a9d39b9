"""The register profile: the protocol decisions that vary between the controllers we may meet.

A named, versioned JSON file, saved atomically; only an administrator may change the one in force
(:meth:`app.safety.session.SafetySession.set_register_profile`, audited). It is applied to the
link's :class:`~app.link.transport.ConnectionSettings` when TeachPad connects
(:meth:`RegisterProfile.apply`): the connection says *where* the controller is, the profile *how
its registers read*. ::

    {"format": "teachpad-registers", "version": 1, "name": "cell 3 (BC-2000, fw 4.2)",
     "revision": 3, "saved": "2026-11-24T05:40:00+00:00",
     "word_order": "low-first", "unit": 1, "completion": "auto", "unconfirmed_after": null,
     "poll_timeout": null, "datetime_layout": "split-words",
     "point_id_min": 0, "point_id_max": 10000}

What varies, and why (PROTOCOL.md section 7; README "Protocol decisions"):

* ``word_order`` -- the seed's low-word-first is "for example"; a controller may be set to ABCD.
* ``unit`` -- the Modbus unit (slave) id; the seed's examples use 1.
* ``completion`` -- how GV291's stale 0xFF is told from the new answer: ``sentinel`` (GV291 keeps
  what the host writes), ``observe`` (read-only or ignored writes), ``auto`` (probe once).
  ``unconfirmed_after`` (s): the observe rule's window for idempotent commands (None: default).
* ``poll_timeout`` (s) -- monitoring reads; None follows the transport (TCP 0.15 s, RTU by baud).
* ``datetime_layout`` -- GV288/289 as split words or packed 32-bit values.
* ``point_id_min`` / ``point_id_max`` -- the temp point ids the controller accepts.

Not in the profile, because the code has no choice to offer: GV291's *encoding* (float32 255.0 or
integer 0xFF in register 582 are both decoded, always) and the A B C Euler convention (fixed-axis
X-Y-Z, owned by :mod:`app.geometry`).
"""

from __future__ import annotations

import dataclasses
import datetime as dt
import json
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

from app.connection import ConnectionSettings
from app.errors import TeachPadError
from app.points.atomic import atomic_write_bytes, read_settings_text, versioned_document
from app.protocol.codec import WordOrder
from app.protocol.datetime_regs import DateTimeLayout
from app.safety.location import REGISTER_PROFILE_NAME

FORMAT = "teachpad-registers"
VERSION = 1
PROFILE_NAME = REGISTER_PROFILE_NAME  # the profile in force, in the safety folder (app.safety.location)
PROFILE_SUFFIX = ".registers.json"  # profiles kept elsewhere (Save as / Load)
_MAX_BYTES = 256 * 1024
COMPLETION_MODES: tuple[str, ...] = ("auto", "sentinel", "observe")
UNIT_RANGE = (0, 247)
POLL_TIMEOUT_RANGE = (0.02, 10.0)  # s
UNCONFIRMED_RANGE = (0.005, 5.0)  # s
POINT_ID_RANGE = (0, 65535)
_FIELDS = (
    "word_order",
    "unit",
    "completion",
    "unconfirmed_after",
    "poll_timeout",
    "datetime_layout",
    "point_id_min",
    "point_id_max",
)


class RegisterProfileError(TeachPadError):
    """A register profile that cannot be used; the message names the file and the field."""


def _short(value: object) -> str:
    text = value if isinstance(value, str) else json.dumps(value)
    text = repr(text) if isinstance(value, str) else text
    return text if len(text) <= 24 else text[:21] + "..."


@dataclass(frozen=True)
class RegisterProfile:
    """See the module docstring. The defaults are the vendor document's and TeachPad's own."""

    name: str = "default"
    word_order: WordOrder = WordOrder.LOW_FIRST
    unit: int = 1
    completion: Literal["auto", "sentinel", "observe"] = "auto"
    unconfirmed_after: float | None = None
    poll_timeout: float | None = None
    datetime_layout: DateTimeLayout = DateTimeLayout.SPLIT_WORDS
    point_id_min: int = 0
    point_id_max: int = 10000
    revision: int = 0
    saved: str = ""  # ISO time of the last save

    def __post_init__(self) -> None:
        _check(self, "the register profile")

    @classmethod
    def from_connection(cls, settings: ConnectionSettings, name: str = "default") -> RegisterProfile:
        """The profile a :class:`ConnectionSettings` implies (before any profile was saved)."""
        return cls(name, **{f: getattr(settings, f) for f in _FIELDS})

    def apply(self, settings: ConnectionSettings) -> ConnectionSettings:
        """``settings`` with this profile's protocol decisions (where to connect is unchanged)."""
        return dataclasses.replace(settings, **{f: getattr(self, f) for f in _FIELDS})

    def protocol_dict(self) -> dict[str, Any]:
        """The protocol fields in their JSON form (what an audit record or a diff shows)."""
        out: dict[str, Any] = {}
        for f in _FIELDS:
            value = getattr(self, f)
            out[f] = value.value if isinstance(value, WordOrder | DateTimeLayout) else value
        return out

    def changes(self, other: RegisterProfile) -> dict[str, list[Any]]:
        """``{field: [mine, other's]}`` for every field that differs (the name too)."""
        mine, theirs = self.protocol_dict(), other.protocol_dict()
        out = {f: [mine[f], theirs[f]] for f in _FIELDS if mine[f] != theirs[f]}
        if self.name != other.name:
            out["name"] = [self.name, other.name]
        return out

    def summary(self) -> str:
        """One line for messages: ``'cell 3' rev 2: low-first, unit 1, completion auto``."""
        return (
            f"{self.name!r} rev {self.revision}: {self.word_order.value}, unit {self.unit}, "
            f"completion {self.completion}"
        )


def _check(p: RegisterProfile, where: str) -> None:
    _check_kinds(p, where)
    _check_whole_numbers(p, where)
    _check_timeouts(p, where)
    if isinstance(p.revision, bool) or not isinstance(p.revision, int) or p.revision < 0:
        raise _bad(where, "revision", "must be a whole number >= 0")


def _bad(where: str, name: str, text: str) -> RegisterProfileError:
    return RegisterProfileError(f"{where}: {name} {text}")


def _check_kinds(p: RegisterProfile, where: str) -> None:
    """The name is text; the word order, clock layout and completion are ones TeachPad knows."""
    if not isinstance(p.name, str) or not p.name.strip() or len(p.name) > 80:
        raise _bad(where, "name", "must be text of 1 to 80 characters")
    if not isinstance(p.word_order, WordOrder):
        raise _bad(where, "word_order", "must be low-first or high-first")
    if not isinstance(p.datetime_layout, DateTimeLayout):
        raise _bad(where, "datetime_layout", "must be split-words or packed32")
    if p.completion not in COMPLETION_MODES:
        raise _bad(
            where, "completion", f"must be one of {', '.join(COMPLETION_MODES)}, got {_short(p.completion)}"
        )


def _check_whole_numbers(p: RegisterProfile, where: str) -> None:
    """The unit and the point id range: whole numbers in their ranges, the range not reversed."""
    for name, lo, hi in (
        ("unit", *UNIT_RANGE),
        ("point_id_min", *POINT_ID_RANGE),
        ("point_id_max", *POINT_ID_RANGE),
    ):
        value = getattr(p, name)
        if isinstance(value, bool) or not isinstance(value, int) or not lo <= value <= hi:
            raise _bad(where, name, f"must be a whole number {lo}..{hi}, got {_short(value)}")
    if p.point_id_min > p.point_id_max:
        raise _bad(where, "point_id_min", f"({p.point_id_min}) is above point_id_max ({p.point_id_max})")


def _check_timeouts(p: RegisterProfile, where: str) -> None:
    """The timeouts: empty (automatic) or a number of seconds in their range."""
    for name, lo_f, hi_f in (
        ("poll_timeout", *POLL_TIMEOUT_RANGE),
        ("unconfirmed_after", *UNCONFIRMED_RANGE),
    ):
        value = getattr(p, name)
        if value is None:
            continue
        if (
            isinstance(value, bool)
            or not isinstance(value, int | float)
            or not math.isfinite(value)
            or not lo_f <= value <= hi_f
        ):
            raise _bad(where, name, f"must be empty (automatic) or {lo_f:g}..{hi_f:g} s, got {_short(value)}")


# --- JSON -------------------------------------------------------------------------------------


def profile_to_json(profile: RegisterProfile) -> str:
    doc: dict[str, Any] = {
        "format": FORMAT,
        "version": VERSION,
        "name": profile.name,
        "revision": profile.revision,
        "saved": profile.saved,
    }
    doc.update(profile.protocol_dict())
    return json.dumps(doc, indent=2, ensure_ascii=False) + "\n"


def profile_from_json(text: str, source: str = "the register profile") -> RegisterProfile:
    doc = versioned_document(
        text, source, fmt=FORMAT, version=VERSION, what="register profile", error=RegisterProfileError
    )
    unknown = sorted(set(doc) - {"format", "version", "name", "revision", "saved", *_FIELDS})
    if unknown:
        raise RegisterProfileError(f"{source}: unknown field {_short(unknown[0])}")
    defaults = RegisterProfile()
    values: dict[str, Any] = {f: doc.get(f, getattr(defaults, f)) for f in ("name", "revision", *_FIELDS)}
    saved = doc.get("saved", "")
    if not isinstance(saved, str):
        raise RegisterProfileError(f"{source}: 'saved' must be text")
    values["saved"] = saved
    for name, kind in (("word_order", WordOrder), ("datetime_layout", DateTimeLayout)):
        raw = values[name]
        if not isinstance(raw, kind):
            try:
                values[name] = kind(raw)
            except ValueError:
                choices = ", ".join(member.value for member in kind)
                raise RegisterProfileError(
                    f"{source}: {name} must be one of {choices}, got {_short(raw)}"
                ) from None
    for name in ("poll_timeout", "unconfirmed_after"):  # JSON has one number type
        if isinstance(values[name], int) and not isinstance(values[name], bool):
            values[name] = float(values[name])
    try:
        return RegisterProfile(**values)
    except RegisterProfileError as exc:  # name the file rather than "the register profile"
        raise RegisterProfileError(str(exc).replace("the register profile", source, 1)) from None


def load_register_profile(path: str | os.PathLike[str]) -> RegisterProfile:
    """Read a profile; :class:`RegisterProfileError` says what is wrong with it, in words."""
    p = Path(path)
    text = read_settings_text(p, _MAX_BYTES, "register profile", RegisterProfileError)
    return profile_from_json(text, f"register profile {p.name}")


def save_register_profile(
    path: str | os.PathLike[str], profile: RegisterProfile, now: dt.datetime | None = None
) -> RegisterProfile:
    """Write atomically with the next revision; returns the profile as saved."""
    stamp = (now or dt.datetime.now(dt.UTC)).isoformat(timespec="seconds")
    saved = dataclasses.replace(profile, revision=profile.revision + 1, saved=stamp)
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    atomic_write_bytes(path, profile_to_json(saved).encode("utf-8"))
    return saved


def export_register_profile(path: str | os.PathLike[str], profile: RegisterProfile) -> None:
    """Write a copy elsewhere (Save as), unchanged: its revision is the one in force."""
    atomic_write_bytes(path, profile_to_json(profile).encode("utf-8"))


def active_profile(path: Path, fallback: RegisterProfile) -> tuple[RegisterProfile, str]:
    """The profile in force at ``path`` and a problem ("" when none). No file: ``fallback`` (the
    remembered connection's decisions). A damaged file: ``fallback`` and the reason, so the
    window can say it instead of connecting with values nobody chose silently."""
    profile, problem = read_active_profile(path, fallback)
    if problem is None:
        return profile, ""
    return profile, f"{problem}; {FALLBACK_NOTE}"


#: What a damaged profile in force means (said after the problem)
FALLBACK_NOTE = "the remembered connection settings are used until an administrator saves a register profile"


def read_active_profile(
    path: Path, fallback: RegisterProfile
) -> tuple[RegisterProfile, RegisterProfileError | None]:
    """As :func:`active_profile`, the problem as the error itself (the GUI words it by its code)."""
    if not path.exists():
        return fallback, None
    try:
        return load_register_profile(path), None
    except RegisterProfileError as exc:
        return fallback, exc
