"""The CLI for script writers (issue 21): the help names the file type the program writes and the
point id range it accepts (and the link agrees), ``audit`` columns align whatever the role's
length, the audit CSV opens right in Excel (UTF-8 with a BOM)."""

from __future__ import annotations

import csv
import json
from pathlib import Path
from typing import Any

import pytest

from app.cli.exit_codes import ExitCode
from app.cli.main import main
from app.points.project import PROJECT_SUFFIX
from app.protocol import registers
from app.safety.audit import AuditLog, FsyncPolicy
from app.safety.audit_read import Result

SCAN = 0.02


@pytest.fixture
def csim(sim_factory: Any) -> Any:
    return sim_factory(command_latency=SCAN)


def help_text(capsys: pytest.CaptureFixture[str], *argv: str) -> str:
    assert main([*argv, "--help"]) == ExitCode.OK
    return " ".join(capsys.readouterr().out.split())


@pytest.mark.parametrize(
    "command",
    [("points", "list"), ("points", "upload"), ("points", "export"), ("points", "import"), ("run",)],
)
def test_the_help_names_the_file_type_the_program_writes(
    command: tuple[str, ...], capsys: pytest.CaptureFixture[str]
) -> None:
    text = help_text(capsys, *command)
    assert ".tpproj" not in text
    assert PROJECT_SUFFIX in text


def test_support_bundle_example_names_the_real_file_type(capsys: pytest.CaptureFixture[str]) -> None:
    text = help_text(capsys, "support-bundle")
    assert ".tpproj" not in text and f"cell{PROJECT_SUFFIX}" in text


def test_point_help_and_validation_agree(csim: Any, capsys: pytest.CaptureFixture[str]) -> None:
    """PROTOCOL.md: 0 <= id <= 10000 by default. The help says so, id 0 is created at the
    simulator, 10001 is refused before anything is sent."""
    lo, hi = registers.TEMP_POINT_ID_MIN, registers.TEMP_POINT_ID_MAX
    for command in (("point", "create"), ("move",)):
        text = help_text(capsys, *command)
        assert f"{lo}..{hi}" in text and "1..10000" not in text
    code = main(
        ["--port", str(csim.port), "point", "create", str(lo), "--xyzabc", "400", "0", "300", "180", "0", "0"]
    )
    _out, err = capsys.readouterr()
    assert code == ExitCode.OK, err
    assert lo in csim.state().points
    code = main(
        [
            "--port",
            str(csim.port),
            "point",
            "create",
            str(hi + 1),
            "--xyzabc",
            "400",
            "0",
            "300",
            "180",
            "0",
            "0",
        ]
    )
    _out, err = capsys.readouterr()
    assert code == ExitCode.USAGE and "Traceback" not in err
    assert hi + 1 not in csim.state().points


def _trail(directory: Path) -> None:
    cli = AuditLog(directory, role="administrator (cli)", fsync=FsyncPolicy.ALWAYS)
    cli.record("command", "stop", detail="by the script")
    cli.close()
    gui = AuditLog(directory, role="operator", fsync=FsyncPolicy.ALWAYS)
    gui.record_refused("jog X+", "outside the work space")
    gui.record("command", "pause", result=Result.OK)
    gui.close()


def test_audit_columns_align_with_the_cli_role(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    _trail(tmp_path)
    assert main(["audit", "--audit-dir", str(tmp_path)]) == ExitCode.OK
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == 3
    commands = [line.index(word) for line, word in zip(lines, ("stop", "jog X+", "pause"), strict=True)]
    results = [line.index(word) for line, word in zip(lines, ("ok", "refused", "ok"), strict=True)]
    assert len(set(commands)) == 1, lines
    assert len(set(results)) == 1, lines


def test_audit_csv_has_a_bom(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    trail = tmp_path / "audit"
    _trail(trail)
    out_file = tmp_path / "audit.csv"
    assert main(["audit", "--audit-dir", str(trail), "--csv", str(out_file)]) == ExitCode.OK
    data = out_file.read_bytes()
    assert data.startswith(b"\xef\xbb\xbf")
    rows = list(csv.reader(data.decode("utf-8-sig").splitlines()))
    assert rows[0][0] == "host_time" and len(rows) == 4


def test_watch_json_lines(csim: Any, capsys: pytest.CaptureFixture[str]) -> None:
    code = main(
        [
            "--port",
            str(csim.port),
            "--poll-timeout",
            "1.0",
            "watch",
            "--json",
            "--rate",
            "100",
            "--count",
            "3",
        ]
    )
    out, err = capsys.readouterr()
    assert code == ExitCode.OK and err == ""
    samples = [json.loads(line) for line in out.splitlines()]
    assert len(samples) == 3
    assert all(s["stale"] is False and s["mode"]["name"] == "auto" for s in samples)
    assert samples[0]["pose"]["x"] == pytest.approx(csim.state().pose[0], abs=1e-3)
    assert samples[0]["t"] <= samples[1]["t"] <= samples[2]["t"]


def test_watch_goes_on_after_a_missed_poll(csim: Any, capsys: pytest.CaptureFixture[str]) -> None:
    """Every third answer comes after the poll timeout: those samples read "stale", the watch
    goes on and ends normally."""
    csim.set_slow_answers(0.8, every=3)
    argv = ["--port", str(csim.port), "--poll-timeout", "0.4"]
    code = main([*argv, "watch", "--json", "--rate", "50", "--count", "8", "--down-after", "30"])
    out, err = capsys.readouterr()
    assert code == ExitCode.OK, err
    samples = [json.loads(line) for line in out.splitlines()]
    assert len(samples) == 8
    stale = [i for i, s in enumerate(samples) if s["stale"]]
    assert stale and "did not answer" in samples[stale[0]]["error"]
    assert any(not s["stale"] for s in samples[stale[0] + 1 :])  # answered again after a miss
    code = main([*argv, "watch", "--rate", "50", "--count", "8", "--down-after", "30"])
    out, err = capsys.readouterr()
    assert code == ExitCode.OK, err
    assert any(" stale: " in line for line in out.splitlines())


def test_watch_exits_3_when_the_link_is_down(csim: Any, capsys: pytest.CaptureFixture[str]) -> None:
    argv = ["--port", str(csim.port), "--poll-timeout", "0.2"]
    csim.set_silent(True)
    code = main([*argv, "watch", "--rate", "20", "--down-after", "0.6"])
    out, err = capsys.readouterr()
    assert code == ExitCode.LINK
    assert out and all(" stale: " in line for line in out.splitlines())
    assert "link is down" in err and len(err.strip().splitlines()) == 1 and "Traceback" not in err
