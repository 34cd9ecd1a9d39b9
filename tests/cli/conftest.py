"""The CLI tests' safety state: each test has its own config directory (the role store and the
GUI's envelope file the CLI reads, app/cli/guard.py), so no test sees another's."""

from __future__ import annotations

from pathlib import Path

import pytest

from app.safety.envelope import Envelope
from app.safety.profile import SafetyProfile, save_profile
from app.safety.roles import default_config_dir


@pytest.fixture(autouse=True)
def own_config_dir(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "config"))
    for name in ("TEACHPAD_ROLE", "TEACHPAD_PASSWORD", "TEACHPAD_ADMIN_PASSWORD"):
        monkeypatch.delenv(name, raising=False)
    return default_config_dir()


def save_envelope(envelope: Envelope) -> Path:
    """Save ``envelope`` where the GUI keeps the one in force (the CLI reads it from there)."""
    path = default_config_dir() / "envelope.safety.json"  # the GUI's (app/cli/guard.py ENVELOPE_FILE)
    path.parent.mkdir(parents=True, exist_ok=True)
    save_profile(path, SafetyProfile("test", envelope))
    return path


@pytest.fixture
def open_envelope(own_config_dir: Path) -> Path:
    """An envelope without Cartesian limits: a move to a point the CLI has no copy of (no
    --project) can go (with the fresh install's keep-in box it is refused, unchecked)."""
    return save_envelope(Envelope())
