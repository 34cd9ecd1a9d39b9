"""The CLI is a screen too: help with units and examples, quiet pipes, honest program starts,
Chinese names aligned by display width."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from app.cli.exit_codes import ExitCode
from app.cli.help import EXAMPLES, help_defects, walk
from app.cli.main import build_parser, main
from app.cli.points import display_width, fit_width

ROOT = Path(__file__).resolve().parents[2]
SAMPLES = ROOT / "resources" / "samples"


def test_every_option_has_help_and_every_command_an_example() -> None:
    parser = build_parser()
    assert help_defects(parser) == []
    paths = {path for path, _ in walk(parser)}
    assert set(EXAMPLES) <= paths, f"examples of commands that do not exist: {set(EXAMPLES) - paths}"


def test_the_walk_finds_an_option_without_help() -> None:
    parser = build_parser()
    leaf = dict(walk(parser))["stop"]
    leaf.add_argument("--bad")
    assert help_defects(parser) == ["stop: --bad has no help"]


def test_a_command_help_shows_units_and_its_example(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["move", "--help"]) == ExitCode.OK
    out = capsys.readouterr().out
    assert "mm/s" in out and "example: teachpad-cli move 12 --via 11 --speed 80" in out


def test_status_into_a_closed_pipe_ends_quietly(sim: Any) -> None:
    """`teachpad-cli status | head -1`: the reader is gone before we write."""
    proc = subprocess.Popen(
        # a roomy poll timeout: the simulator answers from this (maybe loaded) test process
        [sys.executable, "-m", "app.cli.main", "--port", str(sim.port), "--poll-timeout", "1.0", "status"],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    assert proc.stdout is not None
    proc.stdout.close()  # like head after its first line
    _, err = proc.communicate(timeout=30)
    assert err.decode() == ""
    assert proc.returncode == ExitCode.OK


@pytest.mark.skipif(shutil.which("head") is None or shutil.which("bash") is None, reason="needs a shell")
def test_status_piped_into_head_prints_one_line_and_no_traceback(sim: Any) -> None:
    # a roomy poll timeout: the simulator answers from this (maybe loaded) test process
    cli = f"{sys.executable} -m app.cli.main --port {sim.port} --poll-timeout 1.0"
    cmd = f"set -o pipefail; {cli} watch --rate 50 | head -1"
    done = subprocess.run(["bash", "-c", cmd], cwd=ROOT, capture_output=True, text=True, timeout=60)
    assert done.stderr == ""
    assert len(done.stdout.splitlines()) == 1
    assert done.returncode == ExitCode.OK


def test_program_run_of_an_unknown_program_is_an_error(sim: Any, capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["--port", str(sim.port), "program", "run", "99"])
    out, err = capsys.readouterr()
    assert code == ExitCode.FAILED and out == ""
    assert err.startswith("teachpad-cli: error: run program 99 refused: the program did not start")
    assert len(err.strip().splitlines()) == 1
    assert not sim.state().moving


def test_fit_width_counts_wide_characters_twice() -> None:
    assert display_width("取料点") == 6 and display_width("P1") == 2
    assert fit_width("取料点", 8) == "取料点  "
    assert display_width(fit_width("很长很长很长很长很长很长的名字", 20)) == 20
    assert fit_width("很长很长很长很长很长很长的名字", 20).rstrip().endswith("…")


def test_points_list_aligns_chinese_names(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    demo = tmp_path / "demo.teachpad.json"
    shutil.copy(SAMPLES / "demo.teachpad.json", demo)
    assert main(["points", "list", str(demo)]) == ExitCode.OK
    out = capsys.readouterr().out
    pose = re.compile(r"(\s+-?\d+\.\d{3}){6}")
    ends = {display_width(line[: m.end()]) for line in out.splitlines() if (m := pose.search(line))}
    assert "取料点" in out
    assert len(ends) == 1, out  # every pose column ends at the same terminal column


def test_an_axis_error_names_the_frames(sim: Any, capsys: pytest.CaptureFixture[str]) -> None:
    main(["--port", str(sim.port), "jog", "--axis", "J3", "--dir", "+", "--ratio", "5"])
    err = capsys.readouterr().err
    assert "in the base, user and tool frames" in err and "the this" not in err
