"""The safety controller's seams are typed: the views that draw the envelope (the 3D view's
canvas, the planner's 2D preview) are :class:`EnvelopeView`s, the planner is an
:class:`EnvelopeChecker` (envelope and reduced-speed mode); mypy checks the assignments below,
the test checks what each receives when the envelope or the mode changes."""

from __future__ import annotations

from typing import Any

import pytest

from app.safety.box import Box
from app.safety.envelope import Envelope
from app.safety.roles import Role
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    app_settings_fixture,
    fast_reconnect_fixture,
    link_fixture,
    project_dialogs_fixture,
    translator_fixture,
    window_fixture,
)
from ui.controllers.safety import EditGated, EnvelopeChecker, EnvelopeView
from ui.main_window import MainWindow

pytestmark = [pytest.mark.timeout(60), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]

PASSWORD = "cell-42"


def test_views_draw_the_envelope_and_the_planner_checks_with_the_mode(qtbot: Any, window: MainWindow) -> None:
    safety = window.safety_menu.safety
    safety.session.store.scrypt_n = 2**4
    safety.session.store.set_password(Role.ENGINEER, PASSWORD, by=Role.ADMINISTRATOR)
    canvas: EnvelopeView = window.view3d.panel.canvas  # built now: attached on first build
    preview: EnvelopeView = window.planner_panel.preview
    planner: EnvelopeChecker = window.planner_panel
    gated: list[EditGated] = [window.points_panel, window.planner_panel]
    assert canvas is not preview and planner is window.planner_panel and len(gated) == 2
    assert not window.planner_panel.checks.reduced_speed

    safety.login(Role.ENGINEER, PASSWORD)
    with qtbot.waitSignal(safety.envelopeChanged, timeout=2000):
        safety.save_envelope(Envelope(keep_out=(Box("fixture", (0.0, 0.0, 0.0), (10.0, 10.0, 10.0)),)))
    assert len(window.view3d.panel.canvas.keep_out_edges) == 24
    top = window.planner_panel.preview.projections["top"].keep_out
    assert top is not None and len(top.xData) == 24
    checks = window.planner_panel.checks
    assert checks.envelope == safety.envelope and not checks.reduced_speed

    with qtbot.waitSignal(safety.reducedChanged, timeout=2000):
        assert safety.set_reduced(True)
    assert window.planner_panel.checks.reduced_speed  # the checks use the reduced caps now
    assert len(window.view3d.panel.canvas.keep_out_edges) == 24  # still drawn
