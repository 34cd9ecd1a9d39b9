"""A host-name typo: the GUI's link reaches a failed state with words (not "connecting" for ever),
and the connection dialog refuses the typo before it is accepted (issue 19 section 4)."""

from __future__ import annotations

from typing import Any

import pytest
from PySide6.QtWidgets import QDialogButtonBox

from app.connection import ConnectionSettings
from app.link.robot_link import RobotLink
from app.link.types import LinkState
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    SIGNAL_TIMEOUT_MS,
    fast_reconnect_fixture,
    is_state,
    link_fixture,
)
from ui.dialogs.connection_dialog import ConnectionDialog
from ui.messages import reason_text

pytestmark = pytest.mark.timeout(60)


@pytest.mark.parametrize("host", ["cell3..local", "a" * 64 + ".local"])
def test_the_link_says_the_host_is_not_valid(qtbot: Any, link: RobotLink, host: str) -> None:
    with qtbot.waitSignal(
        link.connectionChanged, check_params_cb=is_state(LinkState.DOWN), timeout=SIGNAL_TIMEOUT_MS
    ) as blocker:
        link.connect_to(ConnectionSettings(host=host, port=5020, timeout=0.5))
    state = blocker.args[0]
    assert "is not valid" in state.message
    assert state.reason is not None and state.reason.code == "host_invalid"
    assert "is not valid" in (reason_text(state.reason) or "")


def test_the_dialog_refuses_a_host_typo(qtbot: Any) -> None:
    dialog = ConnectionDialog(ConnectionSettings())
    qtbot.addWidget(dialog)
    dialog.show()
    dialog.host_edit.setText("cell3..local")
    ok = dialog.buttons.button(QDialogButtonBox.StandardButton.Ok)
    ok.click()
    assert dialog.isVisible() and dialog.result() == 0  # not accepted
    assert dialog.host_note.isVisible()
    assert "Not a valid host name or IP address" in dialog.host_note.text()
    assert "two dots in a row" in dialog.host_note.text()
    qtbot.keyClicks(dialog.host_edit, "x")  # typing again hides the words
    assert not dialog.host_note.isVisible()
    dialog.host_edit.setText("cell3.local")
    ok.click()
    assert dialog.result() == 1 and dialog.settings().host == "cell3.local"
