"""Where a point comes from: how it was made, when, on which controller, with which software.

Every :class:`~app.points.point.TempPoint` carries a :class:`Provenance` (``point.made``): taught
from the robot's pose, typed (added by hand or duplicated), imported from a file (which one), and
the last time it was edited. It is history for the operator (the points table's tooltip, the
project file's ``made`` key, :mod:`app.points.diff`), never data the controller holds: two
points that differ only in their provenance are equal (the field does not take part in ``==``).

A project written before provenance existed has no ``made`` key: its points read as
:data:`UNKNOWN_PROVENANCE` ("made: unknown"). The file format is in ``docs/PROJECT_FORMAT.md``.
"""

from __future__ import annotations

import datetime as dt
import enum
from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Final

from app.protocol.enums import QT_TRANSLATE_NOOP

__all__ = [
    "PROVENANCE_TEXT_MAX",
    "UNKNOWN_PROVENANCE",
    "Origin",
    "Provenance",
    "edited",
    "provenance_from_json",
    "provenance_to_json",
    "software_name",
    "stamp",
]

#: The longest text kept in one provenance field (a file name, a controller's endpoint).
PROVENANCE_TEXT_MAX: Final = 200


class Origin(enum.Enum):
    """How a point was made."""

    UNKNOWN = "unknown"  # a file written before provenance was recorded
    TAUGHT = "taught"  # from the robot's pose (teach)
    TYPED = "typed"  # added by hand (or duplicated from another point)
    IMPORTED = "imported"  # read from a file (``Provenance.file``)

    @property
    def text(self) -> str:
        return ORIGIN_TEXT[self]


ORIGIN_TEXT: dict[Origin, str] = {
    Origin.UNKNOWN: QT_TRANSLATE_NOOP("Points", "unknown"),
    Origin.TAUGHT: QT_TRANSLATE_NOOP("Points", "taught from the pose"),
    Origin.TYPED: QT_TRANSLATE_NOOP("Points", "typed"),
    Origin.IMPORTED: QT_TRANSLATE_NOOP("Points", "imported"),
}


@dataclass(frozen=True)
class Provenance:
    """How and where a point was made, and its last edit ("" where not known).

    ``time`` and ``edited`` are ISO 8601 UTC; ``controller`` is the endpoint and unit id of the
    controller the link reached then (``tcp 192.168.1.10:502 unit 1``; "" when none); ``software``
    is the program and its version (``TeachPad 1.4.0``, ``teachpad-cli 1.4.0``); ``file`` the
    name of the imported file (``Origin.IMPORTED``)."""

    origin: Origin = Origin.UNKNOWN
    time: str = ""
    controller: str = ""
    software: str = ""
    file: str = ""
    edited: str = ""
    edited_controller: str = ""

    @property
    def known(self) -> bool:
        return self.origin is not Origin.UNKNOWN


UNKNOWN_PROVENANCE: Final = Provenance()


def software_name(program: str = "TeachPad") -> str:
    """``program`` and TeachPad's installed version, e.g. ``TeachPad 1.4.0``."""
    from app.version import UNKNOWN, version  # importlib.metadata: looked up only when asked

    found = version()
    return program if found == UNKNOWN else f"{program} {found}"


def _now() -> str:
    """Now in UTC, as the project file writes times (``2026-11-29T12:00:00Z``)."""
    return dt.datetime.now(dt.UTC).replace(microsecond=0).isoformat().replace("+00:00", "Z")


def stamp(
    origin: Origin, *, controller: str = "", software: str = "", file: str = "", when: str | None = None
) -> Provenance:
    """A new point's provenance, made now (or ``when``)."""
    return Provenance(
        origin,
        when or _now(),
        controller[:PROVENANCE_TEXT_MAX],
        software[:PROVENANCE_TEXT_MAX],
        file[:PROVENANCE_TEXT_MAX],
    )


def edited(made: Provenance, *, controller: str = "", when: str | None = None) -> Provenance:
    """``made`` with its last edit set to now (or ``when``); how it was made is kept."""
    return replace(made, edited=when or _now(), edited_controller=controller[:PROVENANCE_TEXT_MAX])


# --- the project file's "made" key -------------------------------------------------------------

_KEYS: Final = ("time", "controller", "software", "file", "edited", "edited_controller")


def provenance_to_json(made: Provenance) -> dict[str, str] | None:
    """The point's ``made`` object (only the fields that are set); None for an unknown one."""
    if made == UNKNOWN_PROVENANCE:
        return None
    out = {"how": made.origin.value}
    for key in _KEYS:
        value: str = getattr(made, key)
        if value:
            out[key] = value
    return out


_CACHE_LIMIT: Final = 4096
_cache: dict[tuple[str, ...], Provenance] = {}


def provenance_from_json(raw: Mapping[str, object]) -> Provenance:
    """The provenance of a ``made`` object.

    Lenient where the history allows it: an unknown ``how`` reads as unknown (a newer TeachPad
    may know more ways), missing or non-text fields as "", over-long texts are cut. Equal objects
    give the same (shared) :class:`Provenance`: a 100,000-point import holds one."""
    how = raw.get("how")
    texts = tuple(_text(raw.get(k)) for k in _KEYS)
    key = (how if isinstance(how, str) else "", *texts)
    cached = _cache.get(key)
    if cached is None:
        origin = next((o for o in Origin if o.value == how), Origin.UNKNOWN)
        cached = Provenance(origin, *texts)
        if len(_cache) >= _CACHE_LIMIT:
            _cache.clear()
        _cache[key] = cached
    return cached


def _text(value: object) -> str:
    return value[:PROVENANCE_TEXT_MAX] if isinstance(value, str) else ""
