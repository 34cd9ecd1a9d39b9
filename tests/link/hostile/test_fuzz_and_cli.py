"""Thousands of randomly mutated answers: none becomes a value. And the CLI against a hostile peer."""

from __future__ import annotations

import json
import time

import pytest

from app.cli.main import EXIT_LINK, EXIT_OK, main
from tests.link.hostile.fuzz import run
from tests.link.hostile.server import HostileServer, silent, with_pdu

FRAMES = 2000  # per framing; about a second each


@pytest.mark.parametrize("framing", ["tcp", "rtu"])
def test_random_mutations_never_become_values(framing: str) -> None:
    figures = run(framing, FRAMES, seed=7)  # type: ignore[arg-type]
    assert figures.frames == FRAMES
    assert figures.accepted_mutated == 0 and figures.wrong_values == 0, figures
    assert figures.accepted_identical == figures.identical  # an unchanged frame is a good answer
    refused = FRAMES - figures.accepted_identical
    assert figures.malformed + figures.other_errors == refused
    assert figures.malformed > 0.95 * FRAMES  # garbage that arrived is called malformed
    assert figures.resyncs == figures.malformed  # one resync per malformed answer


def _cli(server: HostileServer, capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    framer = ["--framer", "rtu"] if server.framing == "rtu" else []
    code = main(["--host", "127.0.0.1", "--port", str(server.port), *framer, *args])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize("framing", ["tcp", "rtu"])
def test_cli_status_refuses_a_malformed_answer(framing: str, capsys: pytest.CaptureFixture[str]) -> None:
    with HostileServer(framing) as server:  # type: ignore[arg-type]
        # a roomy poll timeout: the server answers from this (maybe loaded) test process; this test
        # is about a malformed answer, not a late one
        code, out, err = _cli(server, capsys, "--poll-timeout", "1.0", "status", "--json")
        assert code == EXIT_OK, err
        link = json.loads(out)["link"]
        assert (link["requests"], link["answers"], link["malformed"]) == (2, 2, 0)
        # every read answered with function 0x04: no pose is printed, exit 3 with one line
        server.default = with_pdu(lambda a: b"\x04" + a.pdu[1:])
        code, out, err = _cli(server, capsys, "--poll-timeout", "1.0", "status", "--json")
        assert (code, out) == (EXIT_LINK, "")
        assert err.count("\n") == 1 and err.startswith(
            "teachpad-cli: error: malformed answer to the read of registers 560..583 (GV280..GV291) "
            f"from 127.0.0.1:{server.port}: controller answered function 0x04 to a read of holding "
            "registers (0x03)"
        )


def test_cli_status_reports_a_silent_controller_within_the_poll_timeout(
    capsys: pytest.CaptureFixture[str],
) -> None:
    with HostileServer("tcp") as server:
        server.default = silent
        t0 = time.monotonic()
        code, out, err = _cli(server, capsys, "status")
        elapsed = time.monotonic() - t0
    assert (code, out) == (EXIT_LINK, "")
    assert err == f"teachpad-cli: error: controller did not answer within 0.15 s (127.0.0.1:{server.port})\n"
    # the poll timeout, not the 1 s command timeout (0.35 s was once not enough for the whole CLI
    # run, connect and error included, on a loaded machine)
    assert elapsed < 0.15 + 0.6
