"""A robot profile's safety envelope on disk: JSON, versioned, saved atomically.

::

    {"format": "teachpad-safety", "version": 1, "robot": "cell 3", "revision": 4,
     "saved": "2026-11-24T03:10:00+00:00",
     "envelope": {"joint_limits": [[-170, 170], ...],
                  "keep_in": {"name": "work space", "lo": [x, y, z], "hi": [x, y, z]},
                  "keep_out": [{"name": "fixture A", "lo": [...], "hi": [...]}],
                  "max_jog_ratio": 50, "max_speed": 500,
                  "reduced_jog_ratio": 10, "reduced_speed": 250}}

``version`` is the file format (a newer one is refused, not guessed at); ``revision`` counts
saves, so an audit record or a support bundle can say which envelope was in force. The
envelope alone (:func:`envelope_to_dict` / :func:`envelope_from_dict`) can be embedded in a
larger robot profile.

A fresh install has no file yet: :func:`fresh_profile` derives its envelope from the robot model
(:func:`default_envelope`): the model's joint limits, and a keep-in box from its reach -- X and Y
within the reach around the base, Z from the plane the robot stands on (the base's own height)
up to the reach above it: the TCP never goes below the surface the arm is mounted on. Both on,
so a new user starts with the limits checked; an engineer tightens them to the cell.
"""

from __future__ import annotations

import datetime as dt
import json
import math
import os
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from app.errors import InvalidInput, ProfileError
from app.points.atomic import atomic_write_bytes, read_settings_text, versioned_document
from app.safety.box import Box
from app.safety.envelope import Envelope

if TYPE_CHECKING:  # the robot model is read only for a fresh install
    from app.view3d.profile import RobotProfile

FORMAT = "teachpad-safety"
VERSION = 1
PROFILE_SUFFIX = ".safety.json"
_MAX_BYTES = 1024 * 1024


@dataclass(frozen=True)
class SafetyProfile:
    robot: str = ""
    envelope: Envelope = field(default_factory=Envelope)
    revision: int = 0
    saved: str = ""  # ISO time of the last save


#: The keep-in box of a fresh install, rounded out to this many mm.
FRESH_BOX_ROUNDING = 10.0
#: The name of a fresh install's keep-in box.
FRESH_BOX_NAME = "robot reach"


def default_envelope(robot: RobotProfile) -> Envelope:
    """A fresh install's envelope from the robot model ``robot`` (see the module docstring); the
    speed caps are the :class:`Envelope` defaults. A base mounted tilted (A or B not 0) gets the
    reach all round in Z too: there is no floor below it to keep to."""
    limits = tuple((j.min_deg, j.max_deg) for j in robot.joints[:6])
    reach = math.ceil(robot.reach / FRESH_BOX_ROUNDING) * FRESH_BOX_ROUNDING
    x, y, z, a, b, _c = robot.base
    upright = abs(a) < 1e-9 and abs(b) < 1e-9
    lo = (x - reach, y - reach, z if upright else z - reach)
    hi = (x + reach, y + reach, z + reach)
    return Envelope(joint_limits=limits, keep_in=Box(FRESH_BOX_NAME, lo, hi))


def fresh_profile(robot: RobotProfile) -> SafetyProfile:
    """The safety profile of a fresh install (no file yet): :func:`default_envelope`, revision 0."""
    return SafetyProfile(robot.name, default_envelope(robot))


def _box_to_dict(box: Box) -> dict[str, Any]:
    return {"name": box.name, "lo": list(box.lo), "hi": list(box.hi)}


def envelope_to_dict(env: Envelope) -> dict[str, Any]:
    return {
        "joint_limits": [list(pair) for pair in env.joint_limits],
        "keep_in": None if env.keep_in is None else _box_to_dict(env.keep_in),
        "keep_out": [_box_to_dict(b) for b in env.keep_out],
        "max_jog_ratio": env.max_jog_ratio,
        "max_speed": env.max_speed,
        "reduced_jog_ratio": env.reduced_jog_ratio,
        "reduced_speed": env.reduced_speed,
    }


def _number(value: object, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise ProfileError(f"{where}: expected a number, got {_short(value)}")
    return float(value)


def _short(value: object) -> str:
    text = json.dumps(value) if not isinstance(value, str) else repr(value)
    return text if len(text) <= 24 else text[:21] + "..."


def _triple(value: object, where: str) -> tuple[float, float, float]:
    if not isinstance(value, list) or len(value) != 3:
        raise ProfileError(f"{where}: expected three numbers [x, y, z], got {_short(value)}")
    return (_number(value[0], where), _number(value[1], where), _number(value[2], where))


def _box_from(value: object, where: str) -> Box:
    if not isinstance(value, dict):
        raise ProfileError(f"{where}: expected an object with name, lo and hi")
    name = value.get("name", "")
    if not isinstance(name, str) or not name.strip():
        raise ProfileError(f"{where}: a zone needs a name")
    try:
        lo, hi = _triple(value.get("lo"), f"{where}.lo"), _triple(value.get("hi"), f"{where}.hi")
        return Box(name.strip(), lo, hi)
    except InvalidInput as exc:
        raise ProfileError(f"{where}: {exc}") from None


def envelope_from_dict(data: object, where: str = "envelope") -> Envelope:
    """Build an envelope from its JSON form; :class:`ProfileError` names the bad field."""
    if not isinstance(data, dict):
        raise ProfileError(f"{where}: expected an object")
    known = {
        "joint_limits",
        "keep_in",
        "keep_out",
        "max_jog_ratio",
        "max_speed",
        "reduced_jog_ratio",
        "reduced_speed",
    }
    unknown = sorted(set(data) - known)
    if unknown:
        raise ProfileError(f"{where}: unknown field {_short(unknown[0])}")
    joints_raw = data.get("joint_limits", [])
    if not isinstance(joints_raw, list):
        raise ProfileError(f"{where}.joint_limits: expected a list of [low, high] pairs")
    joints: list[tuple[float, float]] = []
    for i, pair in enumerate(joints_raw):
        w = f"{where}.joint_limits[J{i + 1}]"
        if not isinstance(pair, list) or len(pair) != 2:
            raise ProfileError(f"{w}: expected [low, high]")
        joints.append((_number(pair[0], w), _number(pair[1], w)))
    keep_in_raw = data.get("keep_in")
    keep_in = None if keep_in_raw is None else _box_from(keep_in_raw, f"{where}.keep_in")
    keep_out_raw = data.get("keep_out", [])
    if not isinstance(keep_out_raw, list):
        raise ProfileError(f"{where}.keep_out: expected a list of zones")
    keep_out = tuple(_box_from(b, f"{where}.keep_out[{i + 1}]") for i, b in enumerate(keep_out_raw))
    defaults = Envelope()
    numbers = {
        name: _number(data.get(name, getattr(defaults, name)), f"{where}.{name}")
        for name in ("max_jog_ratio", "max_speed", "reduced_jog_ratio", "reduced_speed")
    }
    try:
        return Envelope(tuple(joints), keep_in, keep_out, **numbers)
    except InvalidInput as exc:
        raise ProfileError(f"{where}: {exc}") from None


def profile_to_json(profile: SafetyProfile) -> str:
    doc = {
        "format": FORMAT,
        "version": VERSION,
        "robot": profile.robot,
        "revision": profile.revision,
        "saved": profile.saved,
        "envelope": envelope_to_dict(profile.envelope),
    }
    return json.dumps(doc, indent=2, ensure_ascii=False) + "\n"


def profile_from_json(text: str, source: str = "the safety profile") -> SafetyProfile:
    doc = versioned_document(
        text, source, fmt=FORMAT, version=VERSION, what="safety profile", error=ProfileError
    )
    robot, revision, saved = doc.get("robot", ""), doc.get("revision", 0), doc.get("saved", "")
    if not isinstance(robot, str) or not isinstance(saved, str):
        raise ProfileError(f"{source}: 'robot' and 'saved' must be text")
    if not isinstance(revision, int) or isinstance(revision, bool) or revision < 0:
        raise ProfileError(f"{source}: 'revision' must be a whole number >= 0")
    try:
        envelope = envelope_from_dict(doc.get("envelope"))
    except ProfileError as exc:
        raise ProfileError(f"{source}: {exc}") from None
    return SafetyProfile(robot, envelope, revision, saved)


def load_profile(path: str | os.PathLike[str]) -> SafetyProfile:
    """Read a profile; :class:`ProfileError` says what is wrong with it, in words."""
    p = Path(path)
    text = read_settings_text(p, _MAX_BYTES, "safety profile", ProfileError)
    return profile_from_json(text, f"safety profile {p.name}")


def save_profile(
    path: str | os.PathLike[str], profile: SafetyProfile, now: dt.datetime | None = None
) -> SafetyProfile:
    """Write atomically with the next revision; returns the profile as saved."""
    stamp = (now or dt.datetime.now(dt.UTC)).isoformat(timespec="seconds")
    saved = replace(profile, revision=profile.revision + 1, saved=stamp)
    atomic_write_bytes(path, profile_to_json(saved).encode("utf-8"))
    return saved
