"""Robot model profiles: loading, errors, FK against the simulator, IK and reach."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from app.errors import ProfileError
from app.sim import kinematics as sim_kin
from app.view3d.kinematics import ArmModel, ArmTracker, Reach
from app.view3d.profile import default_profile, load_profile, profile_to_dict


@pytest.fixture(name="model")
def model_fixture() -> ArmModel:
    return ArmModel(default_profile())


def test_default_profile_fk_equals_the_simulator(model: ArmModel) -> None:
    rng = np.random.default_rng(7)
    limits = np.array(sim_kin.JOINT_LIMITS)
    for _ in range(50):
        q = rng.uniform(limits[:, 0], limits[:, 1])
        assert np.allclose(model.forward(q), sim_kin.forward(q), atol=1e-9)
    assert np.allclose(model.profile.limits, limits)


def test_link_polyline_starts_at_base_and_ends_at_flange(model: ArmModel) -> None:
    q = np.array(sim_kin.HOME_JOINTS)
    links = model.link_points(q)
    assert np.allclose(links[0], 0.0)
    assert np.allclose(links[-1], sim_kin.forward(q)[:3, 3])
    assert np.allclose(model.link_points(np.zeros(6))[-1], (525.0, 0.0, 890.0))


def test_ik_reaches_fk_poses_and_reports_unreachable(model: ArmModel) -> None:
    q = np.array([10.0, 30.0, 15.0, 5.0, 40.0, -20.0])
    result = model.inverse(model.forward(q), model.home)
    assert result.reach is Reach.OK and result.joints is not None
    assert np.allclose(model.forward(result.joints)[:3, 3], model.forward(q)[:3, 3], atol=0.05)
    far = model.inverse_pose((3000.0, 0.0, 400.0, 180.0, 0.0, 180.0))
    assert far.reach is Reach.UNREACHABLE and far.joints is None


def test_ik_past_a_joint_limit_is_reported(tmp_path: Path) -> None:
    data = profile_to_dict(default_profile())
    data["joints"][0]["min_deg"], data["joints"][0]["max_deg"] = -10.0, 10.0  # J1 nearly locked
    path = tmp_path / "narrow.json"
    path.write_text(json.dumps(data), encoding="utf-8")
    model = ArmModel(load_profile(path))
    target = ArmModel(default_profile()).forward([60.0, 20.0, 20.0, 0.0, 50.0, 0.0])
    assert model.inverse(target, [60.0, 20.0, 20.0, 0.0, 50.0, 0.0]).reach is Reach.JOINT_LIMIT


def test_tracker_marks_estimates(model: ArmModel) -> None:
    tracker = ArmTracker(model)
    q = [5.0, 25.0, 10.0, 0.0, 45.0, 0.0]
    tracker.from_joints(q)
    assert not tracker.estimated
    pose = sim_kin.forward_pose(q)
    joints = tracker.from_pose(pose)
    assert tracker.estimated and tracker.reach is Reach.OK
    assert np.allclose(model.forward(joints)[:3, 3], pose[:3], atol=0.05)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("{", "not valid JSON (line 1"),
        ('{"format": "x", "version": 1}', "not a robot profile"),
        ('{"format": "teachpad-robot-profile", "version": 9}', "version 9 is not supported"),
        ('{"format": "teachpad-robot-profile", "version": 1, "joints": []}', "joints: expected a list"),
        ('{"format": "teachpad-robot-profile", "version": 1, "joints": [{"d": 1}]}', "joint 1: missing a"),
        (
            '{"format": "teachpad-robot-profile", "version": 1, "joints": [{"d": "abc", "a": 0,'
            ' "alpha_deg": 0, "min_deg": -1, "max_deg": 1}]}',
            "joint 1 d: 'abc' is not a finite number",
        ),
        (
            '{"format": "teachpad-robot-profile", "version": 1, "joints": [{"d": 0, "a": 0, "alpha_deg": 0,'
            ' "min_deg": 5, "max_deg": 1}]}',
            "min_deg 5 is not below max_deg 1",
        ),
        (
            '{"format": "teachpad-robot-profile", "version": 1, "joints": [{"d": 0, "a": 0, "alpha_deg": 0,'
            ' "min_deg": -1, "max_deg": 1}], "base": [1, 2]}',
            "base: expected a list of six numbers",
        ),
    ],
)
def test_profile_file_errors_say_what_is_wrong(tmp_path: Path, text: str, message: str) -> None:
    path = tmp_path / "arm.json"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(ProfileError) as info:
        load_profile(path)
    assert str(info.value).startswith(str(path))
    assert message in str(info.value)


def test_missing_profile_file_and_long_values_are_quoted_short(tmp_path: Path) -> None:
    with pytest.raises(ProfileError, match="cannot read the robot profile"):
        load_profile(tmp_path / "nope.json")
    data = profile_to_dict(default_profile())
    data["name"] = 5
    data["joints"][0]["d"] = "x" * 500
    path = tmp_path / "long.json"
    path.write_text(json.dumps(data), encoding="utf-8")
    with pytest.raises(ProfileError) as info:
        load_profile(path)
    assert len(str(info.value)) < len(str(path)) + 120


def test_profile_round_trips(tmp_path: Path) -> None:
    path = tmp_path / "copy.json"
    path.write_text(json.dumps(profile_to_dict(default_profile())), encoding="utf-8")
    assert load_profile(path) == default_profile()
