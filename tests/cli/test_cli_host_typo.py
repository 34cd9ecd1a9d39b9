"""A host-name typo is a link error in one line (exit 3), never a traceback (issue 19 section 4).

``cell3..local`` (an empty label) and a 64-character label make Python's resolver raise
``UnicodeError`` (its IDNA codec), which ``TcpStream.open`` used to let through."""

from __future__ import annotations

import pytest

from app.cli.exit_codes import ExitCode
from app.cli.main import main
from app.link.hostname import host_problem
from tests.cli.test_cli import one_line_error

LONG_LABEL = "a" * 64 + ".local"


@pytest.mark.parametrize(
    ("host", "words"),
    [
        ("cell3..local", "the host name 'cell3..local' is not valid: it has an empty part"),
        (LONG_LABEL, "a part between two dots is longer than 63 characters"),
        (".cell3", "it has an empty part"),
        ("cell 3", "it contains a space"),
        ("192.168.1.300", "it looks like an IP address but is not one"),
        ("cell3-.local", "starts or ends with a hyphen"),
    ],
)
def test_a_host_typo_is_a_link_error_in_one_line(
    capsys: pytest.CaptureFixture[str], host: str, words: str
) -> None:
    code = main(["--host", host, "--port", "5020", "--timeout", "0.3", "status"])
    err = capsys.readouterr().err
    assert code == ExitCode.LINK
    line = one_line_error(err)
    assert words in line, line


@pytest.mark.parametrize(
    "host",
    [
        "127.0.0.1",
        "::1",
        "[::1]",
        "cell3.local",
        "cell3.local.",
        "a" * 63 + ".local",
        "münchen.example",
        "plc_7",
    ],
)
def test_valid_hosts_pass(host: str) -> None:
    assert host_problem(host) is None


@pytest.mark.parametrize(
    ("host", "problem"),
    [
        ("", "empty"),
        ("cell3..local", "empty_label"),
        (LONG_LABEL, "long_label"),
        ("a." * 127 + "ab", "too_long"),
        ("cell/3", "bad_character"),
        ("cell3-.local", "bad_hyphen"),
        ("10.0.1", "bad_ip"),
    ],
)
def test_invalid_hosts_say_why(host: str, problem: str) -> None:
    assert host_problem(host) == problem
