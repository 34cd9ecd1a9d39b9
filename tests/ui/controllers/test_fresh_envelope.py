"""A fresh install's envelope (ui/controllers/safety.py): in force at once, saved (revision 1) and
audited after the window's first paint, or FRESH_SAVE_LATEST_MS after the start with no paint, or
before any other envelope is saved -- once."""

from __future__ import annotations

from typing import Any

import pytest
from PySide6.QtWidgets import QMainWindow

from app.safety.audit_read import query
from app.safety.profile import load_profile
from app.safety.roles import Role
from app.view3d.profile import default_profile
from ui.controllers import safety as safety_module
from ui.controllers.safety import SafetyController
from ui.first_paint import AfterFirstPaint

PASSWORD = "cell-42"


def _controller(parent: QMainWindow | None = None) -> SafetyController:
    safety = SafetyController(None, parent=parent, scrypt_n=2**4)
    safety.set_idle_polling(False)
    return safety


def _actions(safety: SafetyController) -> list[str]:
    safety.session.audit.close()
    return [r.command for r in query(safety.audit_dir) if r.kind == "action"]


def test_in_force_at_once_saved_and_audited_after_the_first_paint(qtbot: Any) -> None:
    host = QMainWindow()
    qtbot.addWidget(host)
    safety = _controller(host)
    assert safety.fresh_unsaved and not safety.profile_path.exists()
    model = default_profile()
    assert safety.envelope.joint_limits == tuple((j.min_deg, j.max_deg) for j in model.joints)  # in force
    AfterFirstPaint(host, safety.save_fresh_envelope)  # as install_safety does
    host.resize(300, 200)
    host.show()
    qtbot.waitUntil(lambda: safety.profile_path.exists(), timeout=5000)
    assert not safety.fresh_unsaved
    saved = load_profile(safety.profile_path)
    assert saved.revision == 1 and saved.envelope == safety.envelope
    safety.save_fresh_envelope()  # once: a second call saves nothing
    assert load_profile(safety.profile_path).revision == 1
    assert _actions(safety) == ["create the default envelope"]


def test_saved_with_no_paint_after_the_latest_time(qtbot: Any, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(safety_module, "FRESH_SAVE_LATEST_MS", 50)
    safety = _controller()  # no window at all
    assert not safety.profile_path.exists()
    qtbot.waitUntil(lambda: safety.profile_path.exists(), timeout=5000)
    assert load_profile(safety.profile_path).revision == 1 and not safety.fresh_unsaved


def test_an_envelope_saved_first_comes_after_the_fresh_one(qtbot: Any) -> None:
    safety = _controller()
    safety.session.store.set_password(Role.ENGINEER, PASSWORD, by=Role.ADMINISTRATOR)
    safety.login(Role.ENGINEER, PASSWORD)
    assert safety.fresh_unsaved
    saved = safety.save_envelope(safety.envelope)
    assert saved.revision == 2 and load_profile(safety.profile_path).revision == 2
    assert not safety.fresh_unsaved
    actions = _actions(safety)
    assert actions.index("create the default envelope") < len(actions) - 1  # before the edit's record


def test_a_save_that_fails_is_said(qtbot: Any) -> None:
    safety = _controller()
    safety.profile_path.mkdir(parents=True)  # a folder where the file should be: the save fails
    heard: list[str] = []
    safety.message.connect(heard.append)
    safety.save_fresh_envelope()
    assert heard and "could not be saved" in heard[0] and safety.problem == heard[0]
    assert not safety.fresh_unsaved  # said once, not tried again
    safety.save_fresh_envelope()
    assert len(heard) == 1
