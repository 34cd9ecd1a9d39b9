"""``teachpad-cli watch --gv/--reg``: the values the simulator holds, JSON lines, exit codes."""

from __future__ import annotations

import json
import socket
from typing import Any

import pytest

from app.cli.exit_codes import ExitCode
from app.cli.main import main
from app.connection import ConnectionSettings
from app.link.client import RobotClient
from app.protocol.codec import WordOrder

pytestmark = pytest.mark.timeout(60)

ROOMY_POLL = ("--poll-timeout", "1.0")  # the simulator answers from this (maybe loaded) process


def run(port: int, capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(["--port", str(port), *argv])
    out, err = capsys.readouterr()
    return code, out, err


def _hold(sim: Any, order: WordOrder) -> None:
    with RobotClient(ConnectionSettings(host="127.0.0.1", port=sim.port, word_order=order)) as client:
        client.write_gv(10, [12.5, -3.25])
        client.write_registers(40, [(-1234) & 0xFFFF, 0b101])


@pytest.mark.parametrize("order", ["low-first", "high-first"])
def test_text_lines(sim_factory: Any, capsys: pytest.CaptureFixture[str], order: str) -> None:
    sim = sim_factory(word_order=WordOrder.parse(order))
    _hold(sim, WordOrder.parse(order))
    watched = ("--gv", "10", "--gv", "11", "--reg", "40", "--reg", "41:bits", "--reg", "560")
    code, out, err = run(
        sim.port, capsys, *ROOMY_POLL, "--word-order", order, "watch", *watched, "--count", "2"
    )
    assert code == ExitCode.OK, err
    lines = out.splitlines()
    assert len(lines) == 2
    mode = int(sim.state().mode)  # register 560: the controller mode
    assert lines[0].split(" ", 1)[1] == (
        f"GV10=12.5 GV11=-3.25 reg40=-1234 reg41.bits=0b0000000000000101 reg560={mode}"
    )


def test_json_lines_with_names(sim: Any, capsys: pytest.CaptureFixture[str]) -> None:
    _hold(sim, WordOrder.LOW_FIRST)
    code, out, err = run(
        sim.port,
        capsys,
        *ROOMY_POLL,
        "watch",
        "--json",
        "--count",
        "1",
        "--gv",
        "10=tool length",
        "--reg",
        "40",
    )
    assert code == ExitCode.OK, err
    doc = json.loads(out.splitlines()[0])
    assert doc["stale"] is False
    first, second = doc["values"]
    assert first == {
        "key": "GV10",
        "name": "tool length",
        "source": "gv",
        "number": 10,
        "type": "float32",
        "value": 12.5,
        "raw": [0, 0x4148],
    }
    assert second["value"] == -1234 and second["type"] == "int16"


def test_a_register_the_controller_lacks_reads_error_and_the_others_go_on(
    sim: Any, capsys: pytest.CaptureFixture[str]
) -> None:
    _hold(sim, WordOrder.LOW_FIRST)
    code, out, err = run(
        sim.port, capsys, *ROOMY_POLL, "watch", "--count", "1", "--gv", "10", "--reg", "60000"
    )
    assert code == ExitCode.OK, err
    assert out.split(" ", 1)[1].strip() == "GV10=12.5 reg60000=error"


@pytest.mark.parametrize(
    ("argv", "words"),
    [
        (("--gv", "40000"), "GV 40000 is out of range (0..32767)"),
        (("--reg", "70000"), "register 70000 is out of range"),
        (("--gv", "10:double"), "unknown type 'double': use float32, int16 or bits"),
        (("--gv", "ten"), "GV 'ten' is not a number"),
        (("--reg", "65535:float32"), "register 65535 is out of range (0..65534)"),
    ],
)
def test_bad_arguments_exit_2_before_anything_is_sent(
    sim: Any, capsys: pytest.CaptureFixture[str], argv: tuple[str, ...], words: str
) -> None:
    code, out, err = run(sim.port, capsys, "watch", "--count", "1", *argv)
    assert code == ExitCode.USAGE
    assert words in err and "Traceback" not in err
    assert out == "" and sim.requests_count == 0


def test_no_controller_exits_3(capsys: pytest.CaptureFixture[str]) -> None:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]  # closed again: nothing listens there
    code, _, err = run(port, capsys, "--timeout", "0.5", "watch", "--count", "1", "--gv", "10")
    assert code == ExitCode.LINK
    assert err.startswith("teachpad-cli: error:")
