"""Per-user folders of TeachPad without Qt (the core and the CLI do not import Qt): the folders
``QStandardPaths`` gives the GUI, computed the same way, one place for every platform.

* config: Linux ``$XDG_CONFIG_HOME`` or ``~/.config``; Windows ``%APPDATA%``; macOS
  ``~/Library/Application Support``;
* data: Linux ``$XDG_DATA_HOME`` or ``~/.local/share``; Windows ``%LOCALAPPDATA%``; macOS the same
  as config;
* state: Linux ``$XDG_STATE_HOME`` or ``~/.local/state``; Windows ``%LOCALAPPDATA%``; macOS the same
  as config;

each with ``teachpad`` under it. On Linux these are ``QStandardPaths.writableLocation`` of
``GenericConfigLocation``, ``GenericDataLocation`` and ``GenericStateLocation``
(tests/test_user_dirs.py compares them); a relative ``XDG_*`` value is ignored, as the XDG
specification and Qt do. On Windows data and state are Qt's ``GenericDataLocation``
(``%LOCALAPPDATA%``, this computer only); config is the roaming profile (``%APPDATA%``, Qt's
``AppDataLocation`` without the application's folder) so that a user's settings follow them
to another PC of the plant's domain -- the folder the role store has always used there.
``QSettings`` (the GUI's window settings) is the registry on Windows
(``HKEY_CURRENT_USER\\Software\\Bochuang\\TeachPad``) and ``~/.config/Bochuang/TeachPad.conf``
on Linux: Qt's own choice, not changed here.

The safety state's folders (roles, envelope, audit: ``app.safety``) and the autosaves
(``app.points.autosave``) are these; whoever moves one says so in the README.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path
from typing import Final

APP_DIR: Final = "teachpad"


#: The XDG variables whose folders a TeachPad process writes to (CACHE: Qt's and the font cache)
XDG_KINDS: Final = ("CONFIG", "DATA", "STATE", "CACHE")


def fresh_user_dirs_env(root: str | os.PathLike[str]) -> dict[str, str]:
    """``XDG_*_HOME`` for every folder of :data:`XDG_KINDS` under ``root`` (``root/config``, ...): a
    process started with them is a fresh install of its own (tests, benchmarks; Linux)."""
    return {f"XDG_{kind}_HOME": str(Path(root) / kind.lower()) for kind in XDG_KINDS}


def _xdg(variable: str, *fallback: str) -> Path:
    value = os.environ.get(variable, "")
    if value and os.path.isabs(value):
        return Path(value)
    return Path.home().joinpath(*fallback)


def _windows(variable: str, *fallback: str) -> Path:
    return Path(os.environ.get(variable) or Path.home().joinpath("AppData", *fallback))


def config_base() -> Path:
    """The per-user configuration root (without TeachPad's folder)."""
    if sys.platform == "win32":
        return _windows("APPDATA", "Roaming")
    if sys.platform == "darwin":
        return Path.home() / "Library" / "Application Support"
    return _xdg("XDG_CONFIG_HOME", ".config")


def data_base() -> Path:
    """The per-user data root (without TeachPad's folder)."""
    if sys.platform == "win32":
        return _windows("LOCALAPPDATA", "Local")
    if sys.platform == "darwin":
        return Path.home() / "Library" / "Application Support"
    return _xdg("XDG_DATA_HOME", ".local", "share")


def state_base() -> Path:
    """The per-user state root: what may be lost without harm (autosaves), never roamed."""
    if sys.platform == "win32":
        return _windows("LOCALAPPDATA", "Local")
    if sys.platform == "darwin":
        return Path.home() / "Library" / "Application Support"
    return _xdg("XDG_STATE_HOME", ".local", "state")


def config_dir() -> Path:
    return config_base() / APP_DIR


def data_dir() -> Path:
    return data_base() / APP_DIR


def state_dir() -> Path:
    return state_base() / APP_DIR
