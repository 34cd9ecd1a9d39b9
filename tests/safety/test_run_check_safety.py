"""``run --check --safety PROFILE``: a plan leaving the envelope cannot run (CLI, no controller)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from app.cli import points as cli_points
from app.safety.box import Box
from app.safety.envelope import Envelope
from app.safety.profile import SafetyProfile, save_profile
from tests.cli.test_cli_points import SAMPLES, Cli


@pytest.fixture
def demo(tmp_path: Path) -> Path:
    path = tmp_path / "demo.teachpad.json"
    shutil.copy(SAMPLES / "demo.teachpad.json", path)
    return path


def _profile(tmp_path: Path, envelope: Envelope) -> Path:
    path = tmp_path / "cell.safety.json"
    save_profile(path, SafetyProfile("sim", envelope))
    return path


def test_a_plan_outside_the_keep_in_box_is_refused(
    demo: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    tiny = _profile(tmp_path, Envelope(keep_in=Box("cell", (9000.0,) * 3, (9001.0,) * 3)))
    cli = Cli()
    code = cli("run", str(demo), "--plan", "circle", "--check", "--safety", str(tiny))
    assert code == cli_points.EXIT_FAILED  # refused by the envelope, as a step out of it is (issue 19 §5)
    err = capsys.readouterr().err
    assert "outside the allowed work space" in err and "not running it" in err
    assert "(outside the safety envelope)" in err
    assert cli.clients_made == 0


def test_a_roomy_envelope_passes(demo: Path, tmp_path: Path) -> None:
    roomy = _profile(tmp_path, Envelope(keep_in=Box("cell", (-9000.0,) * 3, (9000.0,) * 3)))
    code = Cli()("run", str(demo), "--plan", "circle", "--check", "--safety", str(roomy))
    assert code == cli_points.EXIT_OK


def test_a_bad_profile_is_a_usage_error(
    demo: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = tmp_path / "bad.safety.json"
    bad.write_text("{", encoding="utf-8")
    code = Cli()("run", str(demo), "--plan", "circle", "--check", "--safety", str(bad))
    assert code == cli_points.EXIT_USAGE
    assert "safety profile" in capsys.readouterr().err
