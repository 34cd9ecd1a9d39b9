"""teachpad-cli catches up with the GUI: reach in ``run``, ``--register-profile``, unknown writes in
``audit``. Against the simulator over TCP; what was (not) sent is read from its write log."""

from __future__ import annotations

import dataclasses
import json
import shutil
from pathlib import Path
from typing import Any

import pytest

from app.cli.exit_codes import ExitCode
from app.cli.main import build_parser, main, settings_from_args
from app.protocol.codec import WordOrder
from app.protocol.datetime_regs import DateTimeLayout
from app.safety.audit import AuditLog
from app.safety.audit_read import Result
from app.safety.register_profile import RegisterProfile, profile_to_json
from app.view3d.profile import default_profile, profile_to_dict

ROOT = Path(__file__).resolve().parents[2]
DEMO = ROOT / "resources" / "samples" / "demo.teachpad.json"
FAR_X = 3000.0  # mm: beyond the simulator arm's 900 mm reach
# `status` reads with the poll timeout (0.15 s): roomy here, as tests/cli/test_cli.py says why
ROOMY_POLL = ("--poll-timeout", "1.0")


def run_cli(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    assert "Traceback" not in err
    return code, out, err


def project_with_far_point(tmp_path: Path) -> Path:
    """The demo project with point 2 ('取料点 pick', used by 'pick and place') out of reach."""
    doc = json.loads(DEMO.read_text(encoding="utf-8"))
    far = next(p for p in doc["points"] if p["id"] == 2)
    far["x"] = FAR_X
    path = tmp_path / "far.teachpad.json"
    path.write_text(json.dumps(doc, ensure_ascii=False), encoding="utf-8")
    return path


def write_register_profile(path: Path, profile: RegisterProfile, **edit: Any) -> Path:
    doc = json.loads(profile_to_json(profile))
    doc.update(edit)
    path.write_text(json.dumps(doc), encoding="utf-8")
    return path


# --- reach in run ------------------------------------------------------------------------------


def test_an_unreachable_point_refuses_the_run_before_anything_is_sent(
    sim: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    project = project_with_far_point(tmp_path)
    code, _out, err = run_cli(
        capsys, "--port", str(sim.port), "run", str(project), "--plan", "pick and place"
    )
    assert code == ExitCode.FAILED
    assert "P2 '取料点 pick' is out of the robot model's reach" in err
    assert "not running it" in err
    assert sim.writes == []  # no point created, no move: the pose was only read


def test_run_check_checks_reach_too(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    project = project_with_far_point(tmp_path)
    code, _out, err = run_cli(capsys, "run", str(project), "--plan", "pick and place", "--check")
    assert code == ExitCode.FAILED and "P2 '取料点 pick'" in err
    code, _out, err = run_cli(capsys, "run", str(project), "--plan", "circle", "--check")
    assert code == ExitCode.OK and err == ""  # the other plan does not use the far point


def test_the_robot_profile_decides_reach(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The demo plan fits the default (simulator) arm; a long arm reaches the far point, a short
    arm reaches none of the demo's points."""
    project = project_with_far_point(tmp_path)
    base = profile_to_dict(default_profile())

    def arm(name: str, scale: float) -> Path:
        doc = json.loads(json.dumps(base))
        doc["name"] = name
        for joint in doc["joints"]:
            joint["d"] *= scale
            joint["a"] *= scale
        path = tmp_path / f"{name}.json"
        path.write_text(json.dumps(doc), encoding="utf-8")
        return path

    demo = tmp_path / "demo.teachpad.json"
    shutil.copy(DEMO, demo)
    assert run_cli(capsys, "run", str(demo), "--plan", "circle", "--check")[0] == ExitCode.OK
    short = arm("short", 0.3)
    code, _out, err = run_cli(
        capsys, "run", str(demo), "--plan", "circle", "--check", "--robot-profile", str(short)
    )
    assert code == ExitCode.FAILED and "out of the robot model's reach" in err
    long_arm = arm("long", 4.0)
    code, _out, err = run_cli(
        capsys, "run", str(project), "--plan", "pick and place", "--check", "--robot-profile", str(long_arm)
    )
    assert "P2 '取料点 pick'" not in err


def test_a_bad_robot_profile_is_a_usage_error_naming_the_file(
    sim: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = tmp_path / "broken-arm.json"
    bad.write_text('{"format": "teachpad-robot-profile", "version": 1, "joints": "many"}', encoding="utf-8")
    code, _out, err = run_cli(
        capsys, "--port", str(sim.port), "run", str(DEMO), "--plan", "circle", "--robot-profile", str(bad)
    )
    assert code == ExitCode.USAGE
    assert "broken-arm.json" in err and "joints" in err and len(err.strip().splitlines()) == 1
    assert sim.writes == []


def test_plan_errors_other_than_reach_stay_usage(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    project = project_with_far_point(tmp_path)
    code, _out, err = run_cli(
        capsys, "run", str(project), "--plan", "pick and place", "--check", "--max-speed", "60"
    )  # too slow for the plan's segments, and far
    assert code == ExitCode.USAGE and "out of the robot model's reach" in err


# --- the register profile ----------------------------------------------------------------------


def test_a_register_profile_sets_word_order_and_unit(
    sim_factory: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    sim = sim_factory(word_order=WordOrder.HIGH_FIRST, unit=7)
    profile = write_register_profile(
        tmp_path / "cell.registers.json", RegisterProfile("cell 7", word_order=WordOrder.HIGH_FIRST, unit=7)
    )
    code, out, err = run_cli(
        capsys, "--port", str(sim.port), "--register-profile", str(profile), *ROOMY_POLL, "status", "--json"
    )
    assert code == ExitCode.OK, err
    pose = json.loads(out)["pose"]
    expected = sim.state().pose
    assert [pose[k] for k in "xyz"] == pytest.approx(list(expected[:3]), abs=1e-3)


def test_explicit_flags_override_the_profile(
    sim_factory: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    sim = sim_factory(word_order=WordOrder.HIGH_FIRST, unit=7)
    wrong = write_register_profile(
        tmp_path / "other.registers.json",
        RegisterProfile("other cell", word_order=WordOrder.LOW_FIRST, unit=3),
    )
    code, out, err = run_cli(
        capsys,
        "--port",
        str(sim.port),
        "--register-profile",
        str(wrong),
        "--unit",
        "7",
        "--word-order",
        "high-first",
        *ROOMY_POLL,
        "status",
        "--json",
    )
    assert code == ExitCode.OK, err
    assert json.loads(out)["pose"]["x"] == pytest.approx(sim.state().pose[0], abs=1e-3)
    # the profile alone (low-first) reads the same registers as other numbers
    code, out, err = run_cli(
        capsys,
        "--port",
        str(sim.port),
        "--register-profile",
        str(wrong),
        "--unit",
        "7",
        *ROOMY_POLL,
        "status",
        "--json",
    )
    assert code != ExitCode.OK or json.loads(out)["pose"]["x"] != pytest.approx(sim.state().pose[0], abs=1e-3)


def test_settings_take_every_profile_field_and_the_flags_win(tmp_path: Path) -> None:
    profile = RegisterProfile(
        "cell 3",
        word_order=WordOrder.HIGH_FIRST,
        unit=5,
        completion="observe",
        unconfirmed_after=0.5,
        poll_timeout=0.3,
        datetime_layout=DateTimeLayout.PACKED32,
        point_id_min=10,
        point_id_max=99,
    )
    path = write_register_profile(tmp_path / "cell.registers.json", profile)
    parser = build_parser()
    args = parser.parse_args(
        ["--host", "10.0.0.9", "--timeout", "0.7", "--register-profile", str(path), "status"]
    )
    settings = settings_from_args(args)
    assert (settings.host, settings.timeout) == ("10.0.0.9", 0.7)  # where: the link options
    assert RegisterProfile.from_connection(settings, "cell 3") == profile  # how: the profile
    args = parser.parse_args(
        [
            "--register-profile",
            str(path),
            "--unit",
            "9",
            "--word-order",
            "low-first",
            "--completion",
            "sentinel",
            "--poll-timeout",
            "0.2",
            "status",
        ]
    )
    settings = settings_from_args(args)
    assert (settings.unit, settings.word_order, settings.completion, settings.poll_timeout) == (
        9,
        WordOrder.LOW_FIRST,
        "sentinel",
        0.2,
    )
    assert settings.datetime_layout is DateTimeLayout.PACKED32 and settings.point_id_max == 99
    no_profile = settings_from_args(parser.parse_args(["status"]))
    assert dataclasses.astuple(no_profile) == dataclasses.astuple(
        settings_from_args(parser.parse_args(["--unit", "1", "--word-order", "low-first", "status"]))
    )


@pytest.mark.parametrize(
    ("edit", "field"),
    [
        ({"unit": 300}, "unit"),
        ({"word_order": "middle"}, "word_order"),
        ({"completion": "guess"}, "completion"),
        ({"poll_timeout": "soon"}, "poll_timeout"),
    ],
)
def test_a_malformed_register_profile_is_usage_naming_file_and_field(
    sim: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str], edit: dict[str, Any], field: str
) -> None:
    path = write_register_profile(tmp_path / "bad.registers.json", RegisterProfile(), **edit)
    code, out, err = run_cli(capsys, "--port", str(sim.port), "--register-profile", str(path), "zero", "all")
    assert code == ExitCode.USAGE and out == ""
    line = err.strip()
    assert line.startswith("teachpad-cli: error: ") and len(line.splitlines()) == 1
    assert "bad.registers.json" in line and field in line
    assert sim.writes == []


def test_a_missing_register_profile_is_usage(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, _out, err = run_cli(capsys, "--register-profile", str(tmp_path / "nope.registers.json"), "status")
    assert code == ExitCode.USAGE and "nope.registers.json" in err and "does not exist" in err


def test_the_profiles_point_ids_apply_to_project_files(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The demo uses ids 1..8; a controller that accepts 100..200 makes it unusable (USAGE)."""
    path = write_register_profile(
        tmp_path / "ids.registers.json", RegisterProfile("ids", point_id_min=100, point_id_max=200)
    )
    assert run_cli(capsys, "points", "list", str(DEMO))[0] == ExitCode.OK
    code, _out, err = run_cli(capsys, "--register-profile", str(path), "points", "list", str(DEMO))
    assert code == ExitCode.USAGE and "100" in err


def test_help_says_the_flags_override_the_profile(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["--help"]) == ExitCode.OK
    out = " ".join(capsys.readouterr().out.split())
    assert "--register-profile FILE" in out and "override the profile's field" in out


# --- audit: unknown writes ---------------------------------------------------------------------


def _trail_with_an_unknown_write(directory: Path) -> None:
    log = AuditLog(directory, role="operator")
    with log.writing(441, [1], single=True):
        pass  # answered
    log.record_write(200, [4, 5], pending=True)  # sent; the process died before the answer
    log.record_refused("jog", "outside the envelope")
    log.close()


def test_audit_counts_and_filters_unknown_writes(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    trail = tmp_path / "audit"
    _trail_with_an_unknown_write(trail)
    code, out, err = run_cli(capsys, "audit", "--audit-dir", str(trail))
    assert code == ExitCode.OK and len(out.strip().splitlines()) == 3
    assert "1 write(s) with result unknown" in err and "--result unknown" in err
    code, out, err = run_cli(capsys, "audit", "--audit-dir", str(trail), "--result", "unknown")
    lines = out.strip().splitlines()
    assert code == ExitCode.OK and len(lines) == 1 and " unknown " in lines[0]
    assert "stopped before the answer" in lines[0] and err == ""
    csv_path = tmp_path / "unknown.csv"
    code, out, _err = run_cli(
        capsys, "audit", "--audit-dir", str(trail), "--result", "unknown", "--csv", str(csv_path)
    )
    assert code == ExitCode.OK and "wrote 1 records" in out and "(1 unknown)" in out
    assert Result.UNKNOWN in csv_path.read_text(encoding="utf-8")


def test_audit_without_unknown_writes_says_nothing_about_them(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    log = AuditLog(tmp_path, role="operator")
    with log.writing(441, [1], single=True):
        pass
    log.close()
    code, out, err = run_cli(capsys, "audit", "--audit-dir", str(tmp_path))
    assert code == ExitCode.OK and " ok " in out and err == ""
