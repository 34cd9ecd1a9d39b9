"""Robot model profiles: the arm's geometry as data (DH parameters, joint limits, base, flange).

A profile is a JSON file (``"format": "teachpad-robot-profile"``, ``"version": 1``) with one
entry per joint — standard (distal) Denavit-Hartenberg ``offset_deg``, ``d``, ``a``,
``alpha_deg`` (mm, degrees; joint ``i`` rotates ``theta_i = q_i + offset_i`` about
``z_{i-1}``) and its limits ``min_deg``/``max_deg`` — plus ``home_deg`` (the IK's first seed),
``base`` (the robot base in the world, X Y Z A B C) and ``flange`` (the flange in the last DH
frame, X Y Z A B C). A B C follow :mod:`app.geometry`. The simulator's arm is
:func:`default_profile`. Kinematics of a profile are in :mod:`app.view3d.kinematics`.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Final

from app.errors import InvalidInput, ProfileError
from app.geometry import pose_to_transform

if TYPE_CHECKING:
    import numpy as np
    from numpy.typing import NDArray
else:  # numpy is imported by its first use, not with this module (app/lazy_numpy.py)
    from app.lazy_numpy import np
from app.lazy_numpy import Matrix

PROFILE_FORMAT: Final = "teachpad-robot-profile"
PROFILE_VERSION: Final = 1
DEFAULT_PROFILE_FILE: Final = "sim_arm.json"
MAX_JOINTS: Final = 12
MAX_FILE_BYTES: Final = 1_000_000
_QUOTE_CHARS: Final = 40  # a bad value is quoted up to this many characters


@dataclass(frozen=True)
class JointSpec:
    """One revolute joint: its DH row and limits (degrees, mm)."""

    name: str
    offset_deg: float
    d: float
    a: float
    alpha_deg: float
    min_deg: float
    max_deg: float


@dataclass(frozen=True)
class RobotProfile:
    """An arm: joints base -> flange, the home joints, base and flange offsets (X Y Z A B C)."""

    name: str
    joints: tuple[JointSpec, ...]
    home_deg: tuple[float, ...]
    base: tuple[float, float, float, float, float, float] = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    flange: tuple[float, float, float, float, float, float] = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)

    @property
    def dof(self) -> int:
        return len(self.joints)

    @property
    def limits(self) -> NDArray[np.float64]:
        """(dof, 2) min, max in degrees."""
        return np.array([(j.min_deg, j.max_deg) for j in self.joints], dtype=np.float64)

    @property
    def base_transform(self) -> Matrix:
        return pose_to_transform(*self.base)

    @property
    def flange_transform(self) -> Matrix:
        return pose_to_transform(*self.flange)

    @property
    def reach(self) -> float:
        """An upper bound (mm) of how far the flange gets from the base origin."""
        total = sum(math.hypot(j.a, j.d) for j in self.joints)
        return total + math.sqrt(sum(v * v for v in self.flange[:3]))


def _quote(value: object) -> str:
    text = repr(value)
    return text if len(text) <= _QUOTE_CHARS else text[: _QUOTE_CHARS - 1] + "…"


def _place(where: str, joint: int | None = None) -> dict[str, object]:
    """The params naming a field: its key (``d``, ``home_deg[2]``) and its joint (1-based)."""
    return {"key": where} if joint is None else {"joint": joint, "key": where}


def _number(where: str, value: object, joint: int | None = None) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(float(value)):
        label = where if joint is None else f"joint {joint} {where}"
        raise ProfileError(
            f"{label}: {_quote(value)} is not a finite number",
            code="profile_not_number",
            params={**_place(where, joint), "value": _quote(value)},
        )
    return float(value)


def _six(where: str, value: object) -> tuple[float, float, float, float, float, float]:
    if not isinstance(value, list) or len(value) != 6:
        raise ProfileError(
            f"{where}: expected a list of six numbers X Y Z A B C, got {_quote(value)}",
            code="profile_not_six",
            params={**_place(where), "value": _quote(value)},
        )
    x, y, z, a, b, c = (_number(f"{where}[{i}]", v) for i, v in enumerate(value))
    return (x, y, z, a, b, c)


def _joint(index: int, raw: object) -> JointSpec:
    joint = index + 1
    where = f"joint {joint}"
    keys = ("offset_deg", "d", "a", "alpha_deg", "min_deg", "max_deg")
    if not isinstance(raw, dict):
        raise ProfileError(
            f"{where}: expected an object with {', '.join(keys)}",
            code="profile_joint_not_object",
            params={"joint": joint, "keys": ", ".join(keys)},
        )
    missing = [k for k in keys[1:] if k not in raw]
    if missing:
        raise ProfileError(
            f"{where}: missing {', '.join(missing)}",
            code="profile_missing",
            params={"joint": joint, "keys": ", ".join(missing)},
        )
    name = raw.get("name", f"J{joint}")
    if not isinstance(name, str):
        raise ProfileError(
            f"{where}: name {_quote(name)} is not text",
            code="profile_name_not_text",
            params={"joint": joint, "value": _quote(name)},
        )
    values = {k: _number(k, raw.get(k, 0.0), joint) for k in keys}
    if values["min_deg"] >= values["max_deg"]:
        low, high = f"{values['min_deg']:g}", f"{values['max_deg']:g}"
        raise ProfileError(
            f"{where}: min_deg {low} is not below max_deg {high}",
            code="profile_limits",
            params={"joint": joint, "low": low, "high": high},
        )
    return JointSpec(name=name[:20], **values)


def profile_from_dict(data: object) -> RobotProfile:
    """A profile from parsed JSON; :class:`ProfileError` says what is wrong."""
    if not isinstance(data, dict):
        raise ProfileError("a robot profile is a JSON object", code="profile_not_object")
    if data.get("format") != PROFILE_FORMAT:
        raise ProfileError(
            f"not a robot profile: format is {_quote(data.get('format'))}, expected '{PROFILE_FORMAT}'",
            code="profile_format",
            params={"value": _quote(data.get("format")), "expected": PROFILE_FORMAT},
        )
    version = data.get("version")
    if version != PROFILE_VERSION:
        raise ProfileError(
            f"profile version {_quote(version)} is not supported (this TeachPad reads "
            f"version {PROFILE_VERSION})",
            code="profile_version",
            params={"value": _quote(version), "expected": PROFILE_VERSION},
        )
    joints_raw = data.get("joints")
    if not isinstance(joints_raw, list) or not 1 <= len(joints_raw) <= MAX_JOINTS:
        raise ProfileError(
            f"joints: expected a list of 1 to {MAX_JOINTS} joints",
            code="profile_joints",
            params={"most": MAX_JOINTS},
        )
    joints = tuple(_joint(i, raw) for i, raw in enumerate(joints_raw))
    home_raw: Any = data.get("home_deg", [0.0] * len(joints))
    if not isinstance(home_raw, list) or len(home_raw) != len(joints):
        raise ProfileError(
            f"home_deg: expected {len(joints)} numbers, one per joint",
            code="profile_home",
            params={"count": len(joints)},
        )
    home = tuple(_number(f"home_deg[{i}]", v) for i, v in enumerate(home_raw))
    name = data.get("name", "robot")
    if not isinstance(name, str):
        raise ProfileError(
            f"name {_quote(name)} is not text", code="profile_name_not_text", params={"value": _quote(name)}
        )
    base = _six("base", data.get("base", [0.0] * 6))
    flange = _six("flange", data.get("flange", [0.0] * 6))
    return RobotProfile(name=name[:100], joints=joints, home_deg=home, base=base, flange=flange)


def load_profile(path: str | os.PathLike[str]) -> RobotProfile:
    """Read a profile file; :class:`ProfileError` names the file and the problem."""
    label = os.fspath(path)
    try:
        if os.path.getsize(path) > MAX_FILE_BYTES:
            raise ProfileError(
                f"{label}: too large for a robot profile (over {MAX_FILE_BYTES // 1000} kB)",
                code="profile_too_large",
                params={"file": label, "kb": MAX_FILE_BYTES // 1000},
            )
        with open(path, encoding="utf-8") as handle:
            text = handle.read()
    except OSError as exc:
        raise ProfileError(
            f"{label}: cannot read the robot profile ({exc.strerror or exc})",
            code="profile_unreadable",
            # errno beside the OS's English: the GUI words the common cases (ui/messages_profile.py)
            params={"file": label, "cause": exc.strerror or str(exc), "errno": exc.errno},
        ) from exc
    except UnicodeDecodeError as exc:
        raise ProfileError(
            f"{label}: the robot profile is not UTF-8 text", code="profile_not_utf8", params={"file": label}
        ) from exc
    return parse_profile(text, label)


def parse_profile(text: str, label: str = "profile") -> RobotProfile:
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        where = f"line {exc.lineno}, column {exc.colno}"
        raise ProfileError(
            f"{label}: not valid JSON ({where}: {exc.msg})",
            code="profile_not_json",
            params={"file": label, "line": exc.lineno, "column": exc.colno},
        ) from exc
    try:
        return profile_from_dict(data)
    except ProfileError as exc:
        raise ProfileError(f"{label}: {exc}", code=exc.code, params={**exc.params, "file": label}) from exc


def profile_to_dict(profile: RobotProfile) -> dict[str, Any]:
    return {
        "format": PROFILE_FORMAT,
        "version": PROFILE_VERSION,
        "name": profile.name,
        "joints": [
            {
                "name": j.name,
                "offset_deg": j.offset_deg,
                "d": j.d,
                "a": j.a,
                "alpha_deg": j.alpha_deg,
                "min_deg": j.min_deg,
                "max_deg": j.max_deg,
            }
            for j in profile.joints
        ],
        "home_deg": list(profile.home_deg),
        "base": list(profile.base),
        "flange": list(profile.flange),
    }


def default_profile() -> RobotProfile:
    """The simulator's arm (shipped with the package)."""
    # Beside this module, as the package ships it (and the bundle: packaging/teachpad.spec): not
    # through importlib.resources, whose import costs a fresh install's first start ~10 ms
    text = (Path(__file__).with_name("profiles") / DEFAULT_PROFILE_FILE).read_text("utf-8")
    return parse_profile(text, DEFAULT_PROFILE_FILE)


def joints_array(q_deg: Sequence[float] | NDArray[np.float64], dof: int) -> NDArray[np.float64]:
    arr = np.asarray(q_deg, dtype=np.float64).reshape(-1)
    if arr.size < dof:
        raise InvalidInput(f"{dof} joint angles are needed, got {arr.size}")
    return np.asarray(arr[:dof], dtype=np.float64)
