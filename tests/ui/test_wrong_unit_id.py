"""A wrong unit id: the simulator answers another unit with Modbus exception 11 (gateway target
device failed to respond), as a TCP gateway does. It is a link problem and says to check the unit
id: the GUI's connection words in both languages, the CLI's exit 3 (issue 21, "Words that say what
happened")."""

from __future__ import annotations

from typing import Any

import pytest

from app.cli.exit_codes import ExitCode, exit_code_for
from app.errors import ModbusExceptionError
from app.link.robot_link import RobotLink
from app.link.types import LinkState
from tests.cli.test_cli_catchup import ROOMY_POLL, run_cli
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    SIGNAL_TIMEOUT_MS,
    connection_settings,
    fast_reconnect_fixture,
    is_state,
    link_fixture,
    translator_fixture,
)
from tests.ui.test_messages import assert_chinese
from ui.messages import connection_text

pytestmark = pytest.mark.timeout(60)


def test_the_gui_says_to_check_the_unit_id_in_both_languages(
    qtbot: Any, sim: Any, link: RobotLink, translator: Any
) -> None:
    with qtbot.waitSignal(
        link.connectionChanged, check_params_cb=is_state(LinkState.DOWN), timeout=SIGNAL_TIMEOUT_MS
    ):
        link.connect_to(connection_settings(sim, unit=5))
    connection = link.state.connection
    text = connection_text(connection)
    assert text == (
        "No device answered at unit id 5 (Modbus exception 11, gateway target device failed to respond): "
        "check the unit id in Connect…"
    ), text
    assert translator.set_language("zh_CN")
    chinese = connection_text(connection)
    assert_chinese(chinese)
    assert "从站地址 5" in chinese


def test_the_cli_exits_3_and_names_the_unit_id(capsys: pytest.CaptureFixture[str], sim: Any) -> None:
    code, _out, err = run_cli(capsys, "--port", str(sim.port), "--unit", "5", *ROOMY_POLL, "status")
    assert code == ExitCode.LINK, err
    assert "unit id 5" in err and "check the unit id" in err


def test_only_the_gateway_exceptions_are_a_link_problem() -> None:
    assert exit_code_for(ModbusExceptionError(3, 11, "x")) is ExitCode.LINK
    assert exit_code_for(ModbusExceptionError(3, 10, "x")) is ExitCode.LINK
    assert exit_code_for(ModbusExceptionError(3, 2, "x")) is ExitCode.FAILED
