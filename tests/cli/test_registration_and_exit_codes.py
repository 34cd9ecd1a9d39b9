"""Every command is registered where main.py says; every failure class exits with its one code.

The failures are real: the simulator refuses, answers with a Modbus exception, stays silent;
a closed port refuses the connection; a hostile peer answers malformed frames; Ctrl-C is a
real SIGINT to a real process.
"""

from __future__ import annotations

import argparse
import re
import socket
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from pymodbus.constants import ExcCodes

from app import errors
from app.cli import controller, points, run_plan, selftest, support
from app.cli.exit_codes import EPILOG, LINK_ERRORS, ExitCode, exit_code_for
from app.cli.help import walk
from app.cli.main import REGISTRARS, build_parser, main
from app.protocol.enums import Alarm
from tests.cli.ctrl_c import interrupt_cli
from tests.cli.test_cli import one_line_error
from tests.link.hostile.server import HostileServer, with_pdu

ROOT = Path(__file__).resolve().parents[2]

#: What each module's register() adds (top-level names), in the order of REGISTRARS.
COMMANDS: list[tuple[Callable[[Any], None], set[str]]] = [
    (
        controller.register,
        {
            "status",
            "watch",
            "mode",
            "step",
            "jog",
            "point",
            "move",
            "zero",
            "program",
            "stop",
            "pause",
            "resume",
            "read",
            "write",
        },
    ),
    (points.register, {"points"}),
    (run_plan.register, {"run"}),
    (selftest.register, {"selftest"}),
    (support.register, {"support-bundle", "audit", "roles"}),
]


def _top_level(parser: argparse.ArgumentParser) -> list[str]:
    (action,) = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    return list(action.choices)


# --- registration ------------------------------------------------------------------------------


def test_main_registers_every_command_module_explicitly() -> None:
    assert list(REGISTRARS) == [register for register, _ in COMMANDS]
    names = _top_level(build_parser())
    assert len(names) == len(set(names)), "a command registered twice"
    assert set(names) == set().union(*(commands for _, commands in COMMANDS))


@pytest.mark.parametrize(
    ("register", "commands"), COMMANDS, ids=[register.__module__ for register, _ in COMMANDS]
)
def test_each_module_registers_its_own_commands(register: Callable[[Any], None], commands: set[str]) -> None:
    parser = argparse.ArgumentParser()
    register(parser.add_subparsers(dest="command"))
    assert set(_top_level(parser)) == commands


def test_every_leaf_command_has_a_handler() -> None:
    leaves = [
        (path, sub)
        for path, sub in walk(build_parser())
        if path and not any(isinstance(a, argparse._SubParsersAction) for a in sub._actions)
    ]
    assert (
        len(leaves) == 26
    )  # 14 controller (point create, program run) + 5 points (diff) + run + selftest + 5 offline
    missing = [path for path, sub in leaves if not callable(sub.get_default("handler"))]
    assert missing == []


def test_no_module_is_imported_by_name() -> None:
    source = (ROOT / "app" / "cli" / "main.py").read_text(encoding="utf-8")
    assert "importlib" not in source and "PLUGIN_MODULES" not in source


# --- the table -----------------------------------------------------------------------------------


def test_the_table_keeps_its_numbers() -> None:
    assert {c.name: int(c) for c in ExitCode} == {
        "OK": 0,
        "FAILED": 1,
        "USAGE": 2,
        "LINK": 3,
        "UNKNOWN": 4,
        "INTERRUPTED": 130,
    }


def _error_classes() -> list[type[errors.TeachPadError]]:
    found, todo = [], [errors.TeachPadError]
    while todo:
        cls = todo.pop()
        found.append(cls)
        todo.extend(cls.__subclasses__())
    return [c for c in found if c.__module__ == "app.errors"]


def test_every_typed_error_maps_to_one_code() -> None:
    expected = {
        errors.InvalidInput: ExitCode.USAGE,
        errors.ProfileError: ExitCode.USAGE,  # a robot or safety profile that cannot be used
        errors.LinkError: ExitCode.LINK,
        errors.ResponseTimeout: ExitCode.LINK,
        errors.MalformedResponse: ExitCode.LINK,
        errors.CommandTimeout: ExitCode.UNKNOWN,  # taken, not finished in time: what it did is unknown
        errors.OutcomeUnknown: ExitCode.UNKNOWN,
    }
    classes = _error_classes()
    assert set(LINK_ERRORS) <= set(classes) and len(classes) >= 10
    for cls in classes:
        error = cls.__new__(cls)  # the mapping looks at the class only
        assert exit_code_for(error) is expected.get(cls, ExitCode.FAILED), cls.__name__
    assert exit_code_for(KeyboardInterrupt()) is ExitCode.INTERRUPTED
    assert exit_code_for(PermissionError(13, "Permission denied")) is ExitCode.FAILED


def _documented_codes(text: str) -> dict[int, str]:
    return {
        int(code): meaning.strip()
        for code, meaning in re.findall(r"^\s*\|?\s*`?(\d+)`?\s*\|?\s+(.+)$", text, re.M)
    }


def test_the_table_is_in_help_and_in_the_readme(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["--help"]) == ExitCode.OK
    out = capsys.readouterr().out
    assert out.rstrip().endswith(EPILOG.rstrip())
    for code in ExitCode:
        assert re.search(rf"^\s+{int(code)}  {re.escape(code.meaning)}$", out, re.M), code
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    section = readme[readme.index("### Exit codes") :]
    section = section[: section.index("\n#")]
    rows = dict(re.findall(r"^\| `(\d+)` \| (\w+) \|", section, re.M))
    assert {int(k): v for k, v in rows.items()} == {int(c): c.name for c in ExitCode}


# --- each failure class against real peers -------------------------------------------------------


def _run(capsys: pytest.CaptureFixture[str], port: int, *argv: str) -> tuple[int, str, str]:
    code = main(["--port", str(port), *argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_ok(sim: Any, capsys: pytest.CaptureFixture[str]) -> None:
    # a roomy poll timeout: the simulator answers from this test process, which a loaded machine
    # can hold past the product's 0.15 s (then rightly "did not answer", exit 3)
    code, out, err = _run(capsys, sim.port, "--poll-timeout", "1.0", "status")
    assert (code, err) == (ExitCode.OK, "") and "mode      auto" in out


@pytest.mark.usefixtures("open_envelope")  # a move without --project: no keep-in box
def test_refused_by_the_controller_is_failed(sim: Any, capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = _run(capsys, sim.port, "move", "77")  # no temp point 77 on the controller
    assert code == ExitCode.FAILED
    assert "bad end point" in one_line_error(err)
    assert sim.writes_to(440)[-1].values == (0x42,)  # the command went out; the controller said no
    assert not sim.state().moving


def test_an_alarm_is_failed(sim: Any, capsys: pytest.CaptureFixture[str]) -> None:
    sim.set_alarm(Alarm.ESTOP, True)
    code, _, err = _run(capsys, sim.port, "step", "--frame", "base", "X=5")
    assert code == ExitCode.FAILED
    one_line_error(err)
    assert not sim.state().moving


def test_a_modbus_exception_is_failed(sim: Any, capsys: pytest.CaptureFixture[str]) -> None:
    sim.set_exception(ExcCodes.ILLEGAL_ADDRESS, range(442, 443))
    code, _, err = _run(capsys, sim.port, "pause")
    assert code == ExitCode.FAILED
    assert "illegal data address" in one_line_error(err)


def test_monitor_only_is_failed_and_sends_nothing(sim: Any, capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = _run(capsys, sim.port, "--monitor-only", "write", "200", "1.5")
    assert code == ExitCode.FAILED and "monitor-only" in one_line_error(err)
    assert sim.writes == []


def test_a_file_that_cannot_be_written_is_failed_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out_file = tmp_path / "no such folder" / "audit.csv"
    code = main(["audit", "--audit-dir", str(tmp_path), "--csv", str(out_file)])
    err = capsys.readouterr().err
    assert code == ExitCode.FAILED
    assert one_line_error(err) == f"teachpad-cli: error: {out_file}: No such file or directory"


@pytest.mark.parametrize(
    "argv",
    [
        ["nonsense"],  # argparse
        ["move", "5", "--via", "5"],  # a value the client refuses before sending
        ["read", "10", "99"],  # more GVs than one request
    ],
)
def test_usage_is_2_and_sends_nothing(sim: Any, capsys: pytest.CaptureFixture[str], argv: list[str]) -> None:
    code, _, err = _run(capsys, sim.port, *argv)
    assert code == ExitCode.USAGE and err
    assert sim.writes == []


def test_a_bad_input_file_is_usage(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "bad.teachpad.json"
    bad.write_text("{", encoding="utf-8")
    assert main(["points", "list", str(bad)]) == ExitCode.USAGE
    assert "Traceback" not in capsys.readouterr().err


def test_a_refused_connection_is_link(capsys: pytest.CaptureFixture[str]) -> None:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        free = s.getsockname()[1]  # bound, never listening: the connection is refused
        code, _, err = _run(capsys, free, "--timeout", "0.3", "status")
    assert code == ExitCode.LINK and "connection refused" in one_line_error(err)


def test_no_answer_is_link(sim: Any, capsys: pytest.CaptureFixture[str]) -> None:
    sim.set_silent(True)
    code, _, err = _run(capsys, sim.port, "--timeout", "0.2", "read", "291")
    assert code == ExitCode.LINK and "did not answer within 0.2 s" in one_line_error(err)


def test_a_malformed_answer_is_link(capsys: pytest.CaptureFixture[str]) -> None:
    with HostileServer("tcp") as server:
        server.default = with_pdu(lambda a: b"\x04" + a.pdu[1:])  # the wrong function code
        code, out, err = _run(capsys, server.port, "read", "291")
    assert (code, out) == (ExitCode.LINK, "")
    assert "malformed answer" in one_line_error(err)


def test_a_link_lost_in_a_points_upload_is_link_too(
    sim: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``points`` reports its own errors; the code comes from the same table."""
    demo = tmp_path / "demo.teachpad.json"
    demo.write_bytes((ROOT / "resources" / "samples" / "demo.teachpad.json").read_bytes())
    with HostileServer("tcp") as server:
        server.default = with_pdu(lambda a: b"\x04" + a.pdu[1:])
        code, _, err = _run(capsys, server.port, "points", "upload", str(demo))
    assert code == ExitCode.LINK and "malformed answer" in err


def test_ctrl_c_is_interrupted(sim_factory: Any) -> None:
    sim = sim_factory(command_latency=0.02)
    code, err = interrupt_cli(sim, ["step", "--frame", "joint", "J1=90", "--speed", "1"], lambda s: s.moving)
    assert code == ExitCode.INTERRUPTED
    assert err.splitlines()[-1] == "teachpad-cli: error: interrupted"
    assert sim.wait_for(lambda s: not s.moving, 2.0)  # and the motion was stopped


def test_the_console_script_ends_a_ctrl_c_during_its_imports_in_one_line(capsys: Any) -> None:
    """Ctrl-C while ``teachpad-cli`` is still importing (a few hundred ms): exit 130, one line on
    stderr, no traceback; otherwise the script is :func:`app.cli.main.main` itself."""
    import tomllib

    from app.cli import entry

    def interrupted_import() -> Any:
        raise KeyboardInterrupt

    assert entry.main(interrupted_import) == ExitCode.INTERRUPTED == entry.INTERRUPTED
    err = capsys.readouterr().err
    assert err == "teachpad-cli: interrupted (before any request was sent)\n"
    assert entry.main(lambda: lambda: 7) == 7
    assert entry._load() is main
    scripts = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["scripts"]
    assert scripts["teachpad-cli"] == "app.cli.entry:main"


def test_the_installed_console_script_runs() -> None:
    """The ``teachpad-cli`` the install made (beside this Python) starts through :mod:`app.cli.entry`."""
    import subprocess
    import sys

    script = Path(sys.executable).parent / "teachpad-cli"
    if not script.exists():
        pytest.skip("teachpad-cli is not installed beside this Python")
    assert "app.cli.entry" in script.read_text()
    proc = subprocess.run([str(script), "--help"], capture_output=True, text=True, timeout=60, check=False)
    assert proc.returncode == 0 and "exit codes" in proc.stdout, proc.stderr
