"""Remembered settings: language, touch mode, connection, poll rate, last project, window geometry
(a QSettings wrapper).

``AppSettings()`` uses the user's settings store (organisation ``Bochuang``, application
``TeachPad``); tests and portable installs pass an explicit INI file
(``AppSettings.from_file(path)``) so they never touch the user's. The safety state (roles,
envelope, register profile, audit trail) is never kept here: :mod:`app.safety.location`.
"""

from __future__ import annotations

import dataclasses
import os
from pathlib import Path
from typing import Any

from PySide6.QtCore import QByteArray, QSettings

from app import timing
from app.connection import ConnectionSettings
from app.protocol.codec import WordOrder
from app.safety import register_profile as regprofile
from app.safety.location import safety_location

ORGANIZATION = "Bochuang"
APPLICATION = "TeachPad"
LANGUAGES = ("en", "zh_CN")
DEFAULT_LANGUAGE = "en"

_CONNECTION_KEYS: dict[str, type] = {
    "host": str,
    "port": int,
    "unit": int,
    "serial_port": str,
    "baudrate": int,
    "parity": str,
    "stopbits": int,
    "bytesize": int,
    "framer": str,
    "timeout": float,
    "retries": int,
    "monitor_only": bool,
}


def _to_bool(value: Any) -> bool:
    if isinstance(value, str):  # INI files store booleans as "true"/"false"
        return value.strip().lower() in ("1", "true", "yes", "on")
    return bool(value)


class AppSettings:
    """Typed access to the few values TeachPad remembers between runs."""

    def __init__(self, store: QSettings | None = None) -> None:
        self._store = store if store is not None else QSettings(ORGANIZATION, APPLICATION)

    @classmethod
    def from_file(cls, path: str | os.PathLike[str]) -> AppSettings:
        return cls(QSettings(os.fspath(path), QSettings.Format.IniFormat))

    @property
    def store(self) -> QSettings:
        return self._store

    def sync(self) -> None:
        self._store.sync()

    # --- language ---------------------------------------------------------------------
    @property
    def language(self) -> str:
        value = str(self._store.value("ui/language", DEFAULT_LANGUAGE))
        return value if value in LANGUAGES else DEFAULT_LANGUAGE

    @language.setter
    def language(self, code: str) -> None:
        self._store.setValue("ui/language", code if code in LANGUAGES else DEFAULT_LANGUAGE)

    # --- touch mode -------------------------------------------------------------------
    @property
    def touch_mode(self) -> bool:
        """Bigger motion buttons and an on-screen keypad for number fields."""
        return _to_bool(self._store.value("ui/touch_mode", False))

    @touch_mode.setter
    def touch_mode(self, on: bool) -> None:
        self._store.setValue("ui/touch_mode", bool(on))

    # --- poll rate --------------------------------------------------------------------
    @property
    def poll_hz(self) -> float:
        try:
            value = float(self._store.value("link/poll_hz", timing.POLL_HZ_DEFAULT))  # type: ignore[arg-type]
        except (TypeError, ValueError):
            return float(timing.POLL_HZ_DEFAULT)
        return value if 1.0 <= value <= 500.0 else float(timing.POLL_HZ_DEFAULT)

    @poll_hz.setter
    def poll_hz(self, hz: float) -> None:
        self._store.setValue("link/poll_hz", float(hz))

    # --- connection -------------------------------------------------------------------
    def connection(self) -> ConnectionSettings:
        """The last connection settings (defaults for what was never saved), with the register
        profile in force applied (see the register profile block below)."""
        return self.register_profile()[0].apply(self._remembered_connection())

    def _remembered_connection(self) -> ConnectionSettings:
        defaults = ConnectionSettings()
        values: dict[str, Any] = {}
        for key, kind in _CONNECTION_KEYS.items():
            raw = self._store.value(f"connection/{key}")
            if raw is None or raw == "":
                continue
            try:
                values[key] = _to_bool(raw) if kind is bool else kind(raw)
            except (TypeError, ValueError):
                continue
        if "serial_port" in values and not values["serial_port"]:
            values["serial_port"] = None
        order = self._store.value("connection/word_order")
        if order is not None:
            try:
                values["word_order"] = WordOrder[str(order)]
            except KeyError:
                pass
        return dataclasses.replace(defaults, **values)

    def has_saved_connection(self) -> bool:
        """A connection was saved (``connection()`` is then the last one, not the defaults)."""
        return self._store.contains("connection/host") or self._store.contains("connection/serial_port")

    def save_connection(self, settings: ConnectionSettings) -> None:
        for key in _CONNECTION_KEYS:
            value = getattr(settings, key)
            self._store.setValue(f"connection/{key}", "" if value is None else value)
        self._store.setValue("connection/word_order", settings.word_order.name)

    # --- register profile (issue 12, guard rails: the safety block) -------------------------
    # The protocol decisions that vary between controllers (word order, unit id, completion rule,
    # poll timeout, date/time layout, point ids) live in a register profile file, not in these
    # keys: only an administrator changes it (Safety -> Register profile...). ``connection()``
    # returns the remembered connection with the profile in force applied.
    def register_profile_path(self) -> Path:
        """The profile in force: with the role store and the envelope
        (:func:`~app.safety.location.safety_location`), never beside the settings file."""
        return safety_location().register_profile

    def register_profile(self) -> tuple[regprofile.RegisterProfile, str]:
        """(the profile in force, a problem reading it or ""). No file yet: the profile the
        remembered connection implies (so nothing changes until an administrator saves one)."""
        try:
            fallback = regprofile.RegisterProfile.from_connection(self._remembered_connection())
        except regprofile.RegisterProfileError:  # a remembered value out of range
            fallback = regprofile.RegisterProfile()
        profile, problem = regprofile.read_active_profile(self.register_profile_path(), fallback)
        if problem is None:
            return profile, ""
        from ui.messages_profile import register_problem_text  # words: read when there is a problem

        return profile, register_problem_text(problem)

    # --- project ----------------------------------------------------------------------
    @property
    def last_project(self) -> str:
        """The project file opened or saved last ("" when none)."""
        return str(self._store.value("project/last", "") or "")

    @last_project.setter
    def last_project(self, path: str) -> None:
        self._store.setValue("project/last", str(path))

    # --- window -----------------------------------------------------------------------
    def window_geometry(self) -> QByteArray | None:
        value = self._store.value("window/geometry")
        return value if isinstance(value, QByteArray) and not value.isEmpty() else None

    def window_state(self) -> QByteArray | None:
        value = self._store.value("window/state")
        return value if isinstance(value, QByteArray) and not value.isEmpty() else None

    def save_window(self, geometry: QByteArray, state: QByteArray) -> None:
        self._store.setValue("window/geometry", geometry)
        self._store.setValue("window/state", state)

    # --- 3D view: the robot model profile (view3d-reach) -------------------------------
    @property
    def robot_profile_path(self) -> str:
        """The robot model profile file loaded last ("" for the default profile)."""
        return str(self._store.value("view3d/robot_profile", "") or "")

    @robot_profile_path.setter
    def robot_profile_path(self, path: str) -> None:
        self._store.setValue("view3d/robot_profile", str(path))
