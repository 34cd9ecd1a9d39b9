"""``teachpad-cli selftest`` and the register-map self-test's checks, against the simulator over
TCP: it fails on a simulator with the other word order and passes once the profile says so; a
clock off by a year, another date/time layout, a wrong robot model are reported with their fix;
nothing is ever written at the simulator; the exit codes."""

from __future__ import annotations

import dataclasses
import datetime as dt
import json
from pathlib import Path
from typing import Any

import pytest

from app.cli.exit_codes import ExitCode
from app.cli.main import main
from app.connection import ConnectionSettings
from app.link.client import RobotClient
from app.link.progress import RegisterBlocks
from app.link.register_reads import read_blocks
from app.protocol.codec import WordOrder
from app.protocol.datetime_regs import DateTimeLayout
from app.safety.register_profile import RegisterProfile, save_register_profile
from app.selftest.checks import SELFTEST_BLOCKS, CheckVerdict, check_register_map
from app.view3d.kinematics import ArmModel
from app.view3d.profile import default_profile, profile_to_dict

YEAR = 365 * 86400.0


@pytest.fixture(autouse=True)
def own_config_dir(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "config"))


def run_json(
    capsys: pytest.CaptureFixture[str], *argv: str, after: tuple[str, ...] = ()
) -> tuple[int, dict[str, Any]]:
    code = main([*argv, "selftest", "--json", *after])
    out = capsys.readouterr().out
    return code, json.loads(out)


def by_check(report: dict[str, Any]) -> dict[str, dict[str, Any]]:
    return {line["check"]: line for line in report["lines"]}


def test_other_word_order_fails_and_passes_once_the_profile_is_set(
    sim_factory: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    sim = sim_factory(word_order=WordOrder.HIGH_FIRST)
    code, report = run_json(capsys, "--port", str(sim.port))
    assert code == ExitCode.FAILED
    assert not report["passed"]
    lines = by_check(report)
    assert lines["pose"]["verdict"] == "mismatch"
    assert lines["model"]["verdict"] == "mismatch"
    assert lines["pose"]["setting"] == {"word_order": "high-first"}
    assert report["settings_to_change"] == {"word_order": "high-first"}
    # the other checks do not depend on the word order: they match
    for check in ("mode", "program state", "alarms", "clock", "command status"):
        assert lines[check]["verdict"] == "match", lines[check]

    profile = tmp_path / "cell.registers.json"
    save_register_profile(profile, RegisterProfile("cell", word_order=WordOrder.HIGH_FIRST))
    code, report = run_json(capsys, "--port", str(sim.port), "--register-profile", str(profile))
    assert code == ExitCode.OK, report
    assert report["passed"]
    assert {line["verdict"] for line in report["lines"]} == {"match"}
    assert sim.writes == []  # write-free: not one write reached the controller


def test_text_output_says_each_line_and_the_fix(sim_factory: Any, capsys: pytest.CaptureFixture[str]) -> None:
    sim = sim_factory(word_order=WordOrder.HIGH_FIRST)
    assert main(["--port", str(sim.port), "selftest"]) == ExitCode.FAILED
    out = capsys.readouterr().out.splitlines()
    assert any(line.startswith("mismatch") and 'word_order to "high-first"' in line for line in out)
    assert any(line.startswith("match") and "clock" in line for line in out)
    assert out[-1].startswith("the register map does not match")


def test_a_clock_off_by_a_year_is_reported(sim_factory: Any, capsys: pytest.CaptureFixture[str]) -> None:
    sim = sim_factory(clock_offset=-YEAR)
    code, report = run_json(capsys, "--port", str(sim.port))
    assert code == ExitCode.FAILED
    clock = by_check(report)["clock"]
    assert clock["verdict"] == "mismatch"
    assert clock["code"] == "clock-off"
    assert "365 days behind" in clock["text"]
    assert clock["setting"] is None and "controller's clock" in clock["fix"]
    assert sim.writes == []


def test_the_other_clock_layout_is_the_fix(sim_factory: Any, capsys: pytest.CaptureFixture[str]) -> None:
    sim = sim_factory(datetime_layout=DateTimeLayout.PACKED32)
    code, report = run_json(capsys, "--port", str(sim.port))
    assert code == ExitCode.FAILED
    clock = by_check(report)["clock"]
    assert clock["verdict"] == "mismatch" and clock["setting"] == {"datetime_layout": "packed32"}


def test_a_robot_model_of_another_arm_is_reported(
    sim: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    data = profile_to_dict(default_profile())
    data["name"] = "longer forearm"
    data["joints"][3]["d"] += 200.0
    path = tmp_path / "long.json"
    path.write_text(json.dumps(data), encoding="utf-8")
    code, report = run_json(capsys, "--port", str(sim.port), after=("--robot-profile", str(path)))
    assert code == ExitCode.FAILED
    model = by_check(report)["model"]
    assert model["code"] == "model-disagrees" and "longer forearm" in model["text"]


def test_exit_codes_link_and_usage(sim: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["--port", str(sim.port), "selftest"]) == ExitCode.OK
    assert main(["--port", str(sim.port), "selftest", "--robot-profile", str(tmp_path / "none.json")]) == (
        ExitCode.USAGE
    )
    sim.stop()
    assert main(["--port", str(sim.port), "--timeout", "0.5", "selftest"]) == ExitCode.LINK
    err = capsys.readouterr().err
    assert "Traceback" not in err


def test_a_refused_block_is_not_checked_and_does_not_fail(sim: Any, make_client: Any) -> None:
    """A controller that refuses table 2 (exception 2): its lines are "not checked", the rest is
    still checked, and the run passes."""
    from pymodbus.constants import ExcCodes

    sim.set_exception(ExcCodes.ILLEGAL_ADDRESS, addresses=range(576, 580))
    client: RobotClient = make_client(sim)
    read = read_blocks(client, SELFTEST_BLOCKS)
    assert read.refused == {560: 2}
    report = check_register_map(
        read, WordOrder.LOW_FIRST, DateTimeLayout.SPLIT_WORDS, ArmModel(default_profile())
    )
    verdicts = {line.check: line.verdict for line in report.lines}
    assert verdicts["status"] is CheckVerdict.UNCHECKED
    assert verdicts["pose"] is CheckVerdict.MATCH
    assert report.passed


def test_units_and_abc_conventions_are_named() -> None:
    """The same registers, the pose reported in metres or with Z-Y-Z angles: the model check
    names what the controller reports (not a profile setting)."""
    import math

    from app.geometry import matrix_to_abc, rot_y, rot_z
    from app.protocol import registers
    from app.protocol.codec import encode_floats

    model = ArmModel(default_profile())
    joints = [10.0, -20.0, 30.0, 5.0, 40.0, -15.0]
    flange = model.forward(joints)
    x, y, z = (float(v) for v in flange[:3, 3])

    def read_of(pose: list[float]) -> RegisterBlocks:
        values = dict(enumerate([0] * 1024))
        for i, v in enumerate(encode_floats(pose, WordOrder.LOW_FIRST)):
            values[registers.gv_reg(registers.GV_POSE) + i] = v
        for i, v in enumerate(encode_floats(joints, WordOrder.LOW_FIRST)):
            values[registers.gv_reg(registers.GV_JOINTS) + i] = v
        now = dt.datetime.now()
        return RegisterBlocks(SELFTEST_BLOCKS, values, {}, now.timestamp())

    a, b, c = matrix_to_abc(flange[:3, :3])
    metres = check_register_map(
        read_of([x / 1000, y / 1000, z / 1000, a, b, c]),
        WordOrder.LOW_FIRST,
        DateTimeLayout.SPLIT_WORDS,
        model,
    )
    line = next(line for line in metres.lines if line.check == "model")
    assert line.code == "model-units" and "metres" in line.text
    # Z-Y-Z Euler angles of the same rotation
    r = flange[:3, :3]
    beta = math.degrees(math.acos(max(-1.0, min(1.0, float(r[2, 2])))))
    alpha = math.degrees(math.atan2(float(r[1, 2]), float(r[0, 2])))
    gamma = math.degrees(math.atan2(float(r[2, 1]), -float(r[2, 0])))
    assert float(abs(rot_z(alpha) @ rot_y(beta) @ rot_z(gamma) - r).max()) < 1e-9
    zyz = check_register_map(
        read_of([x, y, z, alpha, beta, gamma]), WordOrder.LOW_FIRST, DateTimeLayout.SPLIT_WORDS, model
    )
    line = next(line for line in zyz.lines if line.check == "model")
    assert line.code == "model-units" and "Z-Y-Z" in line.text
    assert line.setting is None


def test_the_settings_a_report_points_at_apply_to_a_profile(sim_factory: Any, make_client: Any) -> None:
    """Setting what the report points at makes the next self-test pass (the GUI's "apply")."""
    sim = sim_factory(word_order=WordOrder.HIGH_FIRST, datetime_layout=DateTimeLayout.PACKED32)
    client: RobotClient = make_client(port=sim.port)
    model = ArmModel(default_profile())
    profile = RegisterProfile()
    report = check_register_map(
        read_blocks(client, SELFTEST_BLOCKS), profile.word_order, profile.datetime_layout, model
    )
    assert report.settings_to_change == {"word_order": "high-first", "datetime_layout": "packed32"}
    fixed = dataclasses.replace(
        profile, word_order=WordOrder.HIGH_FIRST, datetime_layout=DateTimeLayout.PACKED32
    )
    settings = fixed.apply(ConnectionSettings(port=sim.port))
    again = check_register_map(
        read_blocks(client, SELFTEST_BLOCKS), settings.word_order, settings.datetime_layout, model
    )
    assert again.passed, [line.line for line in again.lines]
    assert sim.writes == []
