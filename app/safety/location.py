"""Where the safety state lives: the role store, the envelope, the register profile, the audit trail.

One answer for the GUI and the CLI, and never beside a settings file: ``teachpad --settings FILE``
takes any path, and a safety state that followed it would start fresh wherever a user points it
(no administrator password, so anyone is administrator; revision 0 of the envelope with no keep-in
box; an audit trail nobody reads). The settings file keeps only what is the operator's to choose.

* **Machine-wide** when an administrator has created the folder (TeachPad never creates it):
  ``/var/lib/teachpad`` (Linux and other POSIX), ``%ProgramData%\\TeachPad`` (Windows),
  ``/Library/Application Support/TeachPad`` (macOS). Every account of the PC then shares one role
  store, one envelope and one audit trail; the administrator decides who may write there (the
  operators' accounts need write access for the audit and for role or envelope changes made in
  TeachPad; without it a change is refused with the reason, and a write to the controller is
  refused when its audit record cannot be written).
* **Per-user** otherwise, as before: the role store, the envelope and the register profile in the
  user's config folder (``$XDG_CONFIG_HOME/teachpad``, ``%APPDATA%\\teachpad``), the audit trail in
  the data folder (``$XDG_DATA_HOME/teachpad/audit``, ``%LOCALAPPDATA%\\teachpad\\audit``). These are
  the account's own files: whoever holds the account can edit or delete them whatever TeachPad
  does (and point ``XDG_*`` elsewhere), so a PC whose operators share an account, or must not
  lower their own rails, gets the machine-wide folder.

Nothing here is read from TeachPad's own settings or options.
"""

from __future__ import annotations

import enum
import os
import sys
from dataclasses import dataclass
from pathlib import Path

from app import user_dirs

__all__ = [
    "AUDIT_FOLDER",
    "ENVELOPE_NAME",
    "REGISTER_PROFILE_NAME",
    "ROLES_NAME",
    "SafetyLocation",
    "Scope",
    "machine_dir",
    "safety_location",
    "user_config_dir",
    "user_data_dir",
]

ROLES_NAME = "roles.json"
ENVELOPE_NAME = "envelope.safety.json"
REGISTER_PROFILE_NAME = "register.profile.json"
AUDIT_FOLDER = "audit"


class Scope(enum.Enum):
    MACHINE = "machine-wide"
    USER = "per-user"


def machine_dir() -> Path:
    """The machine-wide folder (used when it exists; an administrator creates it)."""
    if sys.platform == "win32":
        return Path(os.environ.get("PROGRAMDATA") or r"C:\ProgramData") / "TeachPad"
    if sys.platform == "darwin":
        return Path("/Library/Application Support/TeachPad")
    return Path("/var/lib/teachpad")


def user_config_dir() -> Path:
    """The user's config folder of TeachPad (the per-user role store, envelope, register profile)."""
    return user_dirs.config_dir()


def user_data_dir() -> Path:
    """The user's data folder of TeachPad (the per-user audit trail)."""
    return user_dirs.data_dir()


@dataclass(frozen=True)
class SafetyLocation:
    """The files of the safety state, and whether they are the machine's or the user's."""

    scope: Scope
    config_dir: Path  # the role store, the envelope, the register profile
    audit_dir: Path

    @property
    def roles(self) -> Path:
        return self.config_dir / ROLES_NAME

    @property
    def envelope(self) -> Path:
        return self.config_dir / ENVELOPE_NAME

    @property
    def register_profile(self) -> Path:
        return self.config_dir / REGISTER_PROFILE_NAME

    def describe(self) -> str:
        """One line for a person (About, the support bundle, logs)."""
        if self.scope is Scope.MACHINE:
            return f"{self.scope.value}: {self.config_dir}"
        return f"{self.scope.value}: {self.config_dir} (audit: {self.audit_dir})"


def safety_location() -> SafetyLocation:
    """The machine-wide folder when it exists, else the user's folders (see the module docstring)."""
    machine = machine_dir()
    if machine.is_dir():
        return SafetyLocation(Scope.MACHINE, machine, machine / AUDIT_FOLDER)
    return SafetyLocation(Scope.USER, user_config_dir(), user_data_dir() / AUDIT_FOLDER)
