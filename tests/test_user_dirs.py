"""app.user_dirs: the per-user folders without Qt are the folders QStandardPaths gives the GUI."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from PySide6.QtCore import QStandardPaths

from app import user_dirs
from app.points.autosave import default_autosave_dir

Location = QStandardPaths.StandardLocation
LINUX_ONLY = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the XDG folders")
VARIABLES = ("XDG_CONFIG_HOME", "XDG_DATA_HOME", "XDG_STATE_HOME")


def _qt(location: QStandardPaths.StandardLocation) -> Path:
    return Path(QStandardPaths.writableLocation(location))


@LINUX_ONLY
@pytest.mark.parametrize("set_by_variables", [False, True], ids=["defaults", "XDG variables"])
def test_the_folders_are_qts_generic_locations(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, set_by_variables: bool
) -> None:
    home = tmp_path / "home"
    home.mkdir()
    monkeypatch.setenv("HOME", str(home))
    for variable in VARIABLES:
        if set_by_variables:
            monkeypatch.setenv(variable, str(tmp_path / variable.lower()))
        else:
            monkeypatch.delenv(variable, raising=False)
    assert user_dirs.config_base() == _qt(Location.GenericConfigLocation)
    assert user_dirs.data_base() == _qt(Location.GenericDataLocation)
    assert user_dirs.state_base() == _qt(Location.GenericStateLocation)
    under = tmp_path if set_by_variables else home
    assert user_dirs.config_dir().is_relative_to(under)
    assert user_dirs.state_dir() == user_dirs.state_base() / "teachpad"


@LINUX_ONLY
def test_a_relative_xdg_variable_is_ignored(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    """The XDG specification: a relative path in XDG_* is invalid and ignored."""
    monkeypatch.setenv("HOME", str(tmp_path))
    monkeypatch.setenv("XDG_STATE_HOME", "relative/state")
    assert user_dirs.state_base() == tmp_path / ".local" / "state"


def test_windows_folders_come_from_the_profile_variables(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    """What a Windows build gets (the branch is plain Python: run here with the platform set)."""
    monkeypatch.setattr(sys, "platform", "win32")
    monkeypatch.setenv("APPDATA", str(tmp_path / "Roaming"))
    monkeypatch.setenv("LOCALAPPDATA", str(tmp_path / "Local"))
    assert user_dirs.config_dir() == tmp_path / "Roaming" / "teachpad"
    assert user_dirs.data_dir() == tmp_path / "Local" / "teachpad"
    assert default_autosave_dir() == tmp_path / "Local" / "teachpad" / "autosave"
    monkeypatch.delenv("LOCALAPPDATA")
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    monkeypatch.setenv("USERPROFILE", str(tmp_path / "home"))
    assert user_dirs.state_base().parts[-2:] == ("AppData", "Local")


def test_a_fresh_user_dirs_env_puts_every_folder_teachpad_reads_under_one_root(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    env = user_dirs.fresh_user_dirs_env(tmp_path)
    assert env == {
        "XDG_CONFIG_HOME": str(tmp_path / "config"),
        "XDG_DATA_HOME": str(tmp_path / "data"),
        "XDG_STATE_HOME": str(tmp_path / "state"),
        "XDG_CACHE_HOME": str(tmp_path / "cache"),
    }
    monkeypatch.setattr(sys, "platform", "linux")
    for name, value in env.items():
        monkeypatch.setenv(name, value)
    assert user_dirs.config_base() == tmp_path / "config"
    assert user_dirs.data_base() == tmp_path / "data"
    assert user_dirs.state_base() == tmp_path / "state"
