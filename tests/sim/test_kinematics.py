"""DH model, forward and inverse kinematics of the simulated arm."""

from __future__ import annotations

import numpy as np
import pytest

from app.geometry import abc_to_matrix
from app.sim import kinematics as kin


def test_zero_pose_matches_the_documented_dh_table() -> None:
    x, y, z, _a, b, _c = kin.forward_pose([0.0] * 6)
    assert (x, y, z) == pytest.approx((525.0, 0.0, 890.0), abs=1e-9)
    assert b == pytest.approx(-90.0)  # flange along +X


def test_home_is_in_front_tool_down_and_not_singular() -> None:
    x, y, z, a, b, _c = kin.forward_pose(kin.HOME_JOINTS)
    assert x > 300 and abs(y) < 1e-6 and 200 < z < 800
    assert abs(abs(a) - 180.0) < 1e-6 and b == pytest.approx(0.0, abs=1e-6)
    sv = np.linalg.svd(kin.jacobian(kin.HOME_JOINTS), compute_uv=False)
    assert sv.min() > 0.1
    assert kin.within_limits(kin.HOME_JOINTS)


@pytest.mark.parametrize(
    "q", [(10, 30, 10, 20, 40, 30), (-45, 0, 45, -30, 60, 90), (90, 40, -20, 10, 70, -120)]
)
def test_ik_round_trip_from_home(q: tuple[float, ...]) -> None:
    target = kin.forward(q)
    solved = kin.inverse(target, kin.HOME_JOINTS)
    assert solved is not None
    back = kin.forward(solved)
    assert np.linalg.norm(back[:3, 3] - target[:3, 3]) < 1e-2
    assert np.allclose(back[:3, :3], target[:3, :3], atol=1e-5)


def test_ik_pose_round_trip_uses_the_abc_convention() -> None:
    pose = kin.forward_pose((5, 25, 15, 10, 45, -20))
    t = kin.pose6_to_transform(pose)
    assert np.allclose(t[:3, :3], abc_to_matrix(*pose[3:]))
    solved = kin.inverse_pose(pose, kin.HOME_JOINTS)
    assert solved is not None
    assert kin.forward_pose(solved) == pytest.approx(pose, abs=1e-3)


def test_ik_fails_out_of_reach() -> None:
    far = kin.pose6_to_transform((2000.0, 0.0, 500.0, 180.0, 0.0, 0.0))
    assert kin.inverse(far, kin.HOME_JOINTS) is None


def test_ik_refuses_solutions_outside_the_joint_limits() -> None:
    # J1 = 175 deg is outside +-170: the pose exists, the limits forbid it.
    q = (175.0, 20.0, 20.0, 0.0, 50.0, 0.0)
    assert not kin.within_limits(q)
    seed = (169.0, 20.0, 20.0, 0.0, 50.0, 0.0)
    assert kin.inverse(kin.forward(q), seed) is None


def test_jacobian_matches_finite_differences() -> None:
    q = np.array([10.0, 30.0, 10.0, 20.0, 40.0, 30.0])
    jac = kin.jacobian(q)
    eps = 1e-6
    for i in range(6):
        dq = q.copy()
        dq[i] += np.degrees(eps)
        dp = (kin.forward(dq)[:3, 3] - kin.forward(q)[:3, 3]) / eps
        assert np.allclose(dp, jac[:3, i], atol=1e-3)
