"""The cell file: the controllers of one cell, as a named, versioned JSON file written atomically.

::

    {"format": "teachpad-cell", "version": 1, "name": "cell 3",
     "controllers": [
       {"name": "R1", "host": "10.0.3.11", "port": 502, "unit": 1,
        "register_profile": "r1.registers.json", "robot_profile": "bc6.json"},
       {"name": "R2", "rtu": "/dev/ttyUSB0", "baud": 115200, "unit": 2,
        "external_axes": 2, "plant_writes": ["program/run", "program/stop", "speed_ratio"]}
     ]}

Each controller is reached over Modbus TCP (``host``, ``port``: default 502) or RTU on a serial
line (``rtu``: the device, ``baud``: default 115200), never both; ``unit`` (default: the register
profile's, else 1). ``register_profile`` (a ``.registers.json`` as the GUI saves it:
:mod:`app.safety.register_profile`) says how its registers read; ``robot_profile`` (a
``teachpad-robot-profile``: :mod:`app.view3d.profile`) its arm. Profile paths are relative to the
cell file's folder. Both are read when the cell is loaded, so a bad one is found before anything
connects. ``external_axes`` (0..5, default 0): how many of the external axes E1..E5 the robot has
(the gateway publishes those). ``plant_writes`` (default none): the writes a plant may make to this
robot through ``teachpad-gateway``'s DCMD, each named (:data:`app.safety.roles.PLANT_WRITES`), each
an administrator's decision; a list without them (or no list) is a robot the plant only watches.

A problem is one line naming the file, the controller and the field (``cell.json: controller
'R2': port must be a whole number 1..65535, got 70000``): :class:`CellFileError`.
"""

from __future__ import annotations

import dataclasses
import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from app.connection import ConnectionSettings
from app.errors import ProfileError, TeachPadError
from app.points.atomic import atomic_write_bytes, read_settings_text, versioned_document
from app.safety.register_profile import RegisterProfile, RegisterProfileError, load_register_profile
from app.safety.roles import PLANT_WRITES
from app.view3d.profile import RobotProfile, load_profile

__all__ = ["FORMAT", "VERSION", "Cell", "CellController", "CellFileError", "load_cell", "save_cell"]

FORMAT = "teachpad-cell"
VERSION = 1
MAX_BYTES = 1024 * 1024
MAX_CONTROLLERS = 256
MAX_NAME = 80
DEFAULT_TCP_PORT = 502
DEFAULT_BAUD = 115200
BAUD_RANGE = (1200, 4_000_000)
UNIT_RANGE = (0, 247)
_TOP_FIELDS = frozenset({"format", "version", "name", "controllers"})
_FIELDS = frozenset(
    {
        "name",
        "host",
        "port",
        "rtu",
        "baud",
        "unit",
        "register_profile",
        "robot_profile",
        "external_axes",
        "plant_writes",
    }
)
MAX_EXTERNAL_AXES = 5


class CellFileError(TeachPadError):
    """A cell file that cannot be used; the message is one line naming the controller and the field."""


@dataclass(frozen=True)
class CellController:
    """One controller of the cell: where it is, and the profiles it uses (as read, resolved)."""

    name: str
    host: str | None = None
    port: int = DEFAULT_TCP_PORT
    rtu: str | None = None
    baud: int = DEFAULT_BAUD
    unit: int | None = None  # None: the register profile's, else 1
    register_profile: str | None = None  # the path as written in the file
    robot_profile: str | None = None
    registers: RegisterProfile | None = None  # the register profile read (None: none named)
    robot: RobotProfile | None = None
    external_axes: int = 0  # E1..E<n> are present
    plant_writes: tuple[str, ...] = ()  # what the plant may write (app.safety.roles.PLANT_WRITES)

    def settings(self, *, monitor_only: bool = True) -> ConnectionSettings:
        """How TeachPad reaches it: the register profile's decisions, then the cell's unit."""
        where = ConnectionSettings(
            host=self.host or "127.0.0.1",
            port=self.port,
            serial_port=self.rtu,
            baudrate=self.baud,
            monitor_only=monitor_only,
        )
        settings = where if self.registers is None else self.registers.apply(where)
        if self.unit is not None:
            settings = dataclasses.replace(settings, unit=self.unit)
        return settings

    def as_json(self) -> dict[str, Any]:
        out: dict[str, Any] = {"name": self.name}
        if self.rtu is not None:
            out.update(rtu=self.rtu, baud=self.baud)
        else:
            out.update(host=self.host, port=self.port)
        optional = {"unit": self.unit, "register_profile": self.register_profile}
        optional["robot_profile"] = self.robot_profile
        out.update({key: value for key, value in optional.items() if value is not None})
        if self.external_axes:
            out["external_axes"] = self.external_axes
        if self.plant_writes:
            out["plant_writes"] = list(self.plant_writes)
        return out


@dataclass(frozen=True)
class Cell:
    name: str
    controllers: tuple[CellController, ...]


def _quote(value: object) -> str:
    text = json.dumps(value, ensure_ascii=False)
    return text if len(text) <= 40 else text[:37] + "..."


def _whole(raw: dict[str, Any], key: str, default: int | None, bounds: tuple[int, int]) -> int | None:
    value = raw.get(key, default)
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int) or not bounds[0] <= value <= bounds[1]:
        raise ValueError(f"{key} must be a whole number {bounds[0]}..{bounds[1]}, got {_quote(value)}")
    return value


def _text(raw: dict[str, Any], key: str) -> str | None:
    value = raw.get(key)
    if value is None:
        return None
    if not isinstance(value, str) or not value.strip() or len(value) > 4096:
        raise ValueError(f"{key} must be non-empty text, got {_quote(value)}")
    return value


def _where(raw: dict[str, Any]) -> dict[str, Any]:
    """``host``/``port`` or ``rtu``/``baud``, exactly one of the two."""
    host, rtu = _text(raw, "host"), _text(raw, "rtu")
    if (host is None) == (rtu is None):
        raise ValueError(
            "needs either host (Modbus TCP) or rtu (a serial device), not both"
            if host
            else "host is missing (or rtu, for a serial line)"
        )
    if host is not None:
        if "baud" in raw:
            raise ValueError("baud is for a serial line (rtu), not for host")
        return {"host": host, "port": _whole(raw, "port", DEFAULT_TCP_PORT, (1, 65535))}
    if "port" in raw:
        raise ValueError("port is for Modbus TCP (host), not for rtu; the serial device is rtu")
    return {"rtu": rtu, "baud": _whole(raw, "baud", DEFAULT_BAUD, BAUD_RANGE)}


def _profiles(raw: dict[str, Any], base: Path) -> dict[str, Any]:
    out: dict[str, Any] = {}
    registers = _text(raw, "register_profile")
    if registers is not None:
        try:
            out["registers"] = load_register_profile(base / registers)
        except RegisterProfileError as exc:
            raise ValueError(f"register_profile: {exc}") from None
    robot = _text(raw, "robot_profile")
    if robot is not None:
        try:
            out["robot"] = load_profile(base / robot)
        except ProfileError as exc:
            raise ValueError(f"robot_profile: {exc}") from None
    return {"register_profile": registers, "robot_profile": robot, **out}


def _plant_writes(raw: dict[str, Any]) -> tuple[str, ...]:
    value = raw.get("plant_writes", [])
    if not isinstance(value, list):
        raise ValueError(
            f"plant_writes must be a list of names ({', '.join(PLANT_WRITES)}), got {_quote(value)}"
        )
    for item in value:
        if item not in PLANT_WRITES:
            raise ValueError(
                f"plant_writes: {_quote(item)} is not a write the plant may make ({', '.join(PLANT_WRITES)})"
            )
    if len(set(value)) != len(value):
        raise ValueError("plant_writes names a write twice")
    return tuple(value)


def _controller(raw: object, index: int, base: Path) -> CellController:
    label = f"controller {index + 1}"
    try:
        if not isinstance(raw, dict):
            raise ValueError("must be an object with name, host/port or rtu/baud, unit")
        name = raw.get("name")
        if isinstance(name, str) and name.strip():
            label = f"controller {name!r}"
        if not isinstance(name, str) or not name.strip() or len(name) > MAX_NAME or "/" in name:
            raise ValueError(
                f"name must be text of 1 to {MAX_NAME} characters without '/', got {_quote(name)}"
            )
        unknown = sorted(set(raw) - _FIELDS)
        if unknown:
            raise ValueError(f"unknown field {_quote(unknown[0])}")
        return CellController(
            name=name,
            unit=_whole(raw, "unit", None, UNIT_RANGE),
            external_axes=_whole(raw, "external_axes", 0, (0, MAX_EXTERNAL_AXES)) or 0,
            plant_writes=_plant_writes(raw),
            **_where(raw),
            **_profiles(raw, base),
        )
    except ValueError as exc:
        raise CellFileError(f"{label}: {exc}") from None


def cell_from_json(text: str, source: str, base: Path) -> Cell:
    """The cell in ``text`` (``source`` names it in errors; ``base``: the folder profile paths are in)."""
    doc = versioned_document(text, source, fmt=FORMAT, version=VERSION, what="cell file", error=CellFileError)
    unknown = sorted(set(doc) - _TOP_FIELDS)
    if unknown:
        raise CellFileError(f"{source}: unknown field {_quote(unknown[0])}")
    name = doc.get("name")
    if not isinstance(name, str) or not name.strip() or len(name) > MAX_NAME:
        raise CellFileError(f"{source}: name must be text of 1 to {MAX_NAME} characters, got {_quote(name)}")
    raw = doc.get("controllers")
    if not isinstance(raw, list) or not 1 <= len(raw) <= MAX_CONTROLLERS:
        raise CellFileError(f"{source}: controllers must be a list of 1 to {MAX_CONTROLLERS} controllers")
    controllers: list[CellController] = []
    for index, item in enumerate(raw):
        try:
            controller = _controller(item, index, base)
        except CellFileError as exc:
            raise CellFileError(f"{source}: {exc}") from None
        if any(c.name == controller.name for c in controllers):
            raise CellFileError(f"{source}: controller {controller.name!r}: name is used twice")
        controllers.append(controller)
    return Cell(name, tuple(controllers))


def load_cell(path: str | os.PathLike[str]) -> Cell:
    """Read a cell file; :class:`CellFileError` (one line) says what is wrong with it."""
    p = Path(path)
    text = read_settings_text(p, MAX_BYTES, f"cell file {p.name}", CellFileError)
    return cell_from_json(text, f"cell file {p.name}", p.parent)


def cell_to_json(cell: Cell) -> str:
    doc = {
        "format": FORMAT,
        "version": VERSION,
        "name": cell.name,
        "controllers": [c.as_json() for c in cell.controllers],
    }
    return json.dumps(doc, indent=2, ensure_ascii=False) + "\n"


def save_cell(path: str | os.PathLike[str], cell: Cell) -> None:
    """Write atomically (:func:`app.points.atomic.atomic_write_bytes`)."""
    atomic_write_bytes(path, cell_to_json(cell).encode("utf-8"))
