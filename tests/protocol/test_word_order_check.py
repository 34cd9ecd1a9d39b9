"""The word-order detector (app/protocol/word_order_check.py) on many poses: never a warning with
the right word order -- random poses, the simulator arm's own poses (forward kinematics of random
joints, the zero pose), round values, residuals, zeros -- and a warning for nearly every pose read
the wrong way round. The figures are printed (``-s``)."""

from __future__ import annotations

import math
import random
import struct

import pytest

from app.models import Pose
from app.protocol.codec import WordOrder, decode_floats, encode_floats
from app.protocol.word_order_check import judge_pose, judge_values, other_order
from app.sim.kinematics import forward_pose

SAMPLES = 3_000


def _f32(value: float) -> float:
    return float(struct.unpack("<f", struct.pack("<f", value))[0])


def _random_values(rng: random.Random) -> list[float]:
    """X Y Z A B C EJ1..EJ5 as a controller could report them (float32; the tool centre point is
    never at the base's origin: drawn again when the roll put it within 50 mm)."""
    while True:
        values = _draw(rng)
        if math.hypot(*values[:3]) >= 50.0:
            return values


def _draw(rng: random.Random) -> list[float]:
    kind = rng.random()
    if kind < 0.3:  # the arm's own poses
        joints = [rng.uniform(-170.0, 170.0) for _ in range(6)]
        pose = list(forward_pose(joints))
    elif kind < 0.4:
        pose = list(forward_pose([0.0] * 6))  # the zero pose
    else:
        pose = [rng.uniform(-2500.0, 2500.0) for _ in range(3)] + [
            rng.uniform(-180.0, 180.0) for _ in range(3)
        ]
    for i in range(6):  # round values, exact zeros and tiny residuals of real arithmetic
        roll = rng.random()
        if roll < 0.1:
            pose[i] = float(round(pose[i]))
        elif roll < 0.15:
            pose[i] = 0.0
        elif roll < 0.2:
            pose[i] = rng.choice((-1.0, 1.0)) * 10 ** rng.uniform(-35.0, -6.0)
        elif roll < 0.25:
            pose[i] = rng.choice((-180.0, 180.0, 90.0, -90.0))
    ext = [0.0] * 5 if rng.random() < 0.7 else [rng.uniform(-20_000.0, 20_000.0) for _ in range(5)]
    return [_f32(v) for v in pose + ext]


def _misread(values: list[float], written: WordOrder) -> list[float]:
    """The same registers decoded in the other word order than the controller wrote them."""
    return decode_floats(encode_floats(values, written), other_order(written))


@pytest.mark.parametrize("order", list(WordOrder))
def test_the_right_word_order_never_warns_and_the_wrong_one_nearly_always(order: WordOrder) -> None:
    rng = random.Random(21 + len(order.value))
    false_warnings = detected = 0
    for _ in range(SAMPLES):
        values = _random_values(rng)
        assert not judge_values(values, order).swapped or values == _misread(values, order)
        false_warnings += judge_values(values, order).swapped
        verdict = judge_values(_misread(values, order), other_order(order))
        detected += verdict.swapped
        if verdict.swapped:  # it says what to set: the order the controller writes
            assert verdict.suggested is order
            # (a misread that is a signalling NaN comes back quiet: one mantissa bit of the true
            # value, far below a display's precision)
            assert list(verdict.other) == pytest.approx(values, rel=1e-5)
    print(f"{order.value}: false warnings {false_warnings} of {SAMPLES}, wrong order found in {detected}")
    assert false_warnings == 0
    assert detected >= 0.97 * SAMPLES


def _pose(values: list[float]) -> Pose:
    x, y, z, a, b, c, *ext = values
    return Pose(x, y, z, a, b, c, ext=(ext[0], ext[1], ext[2], ext[3], ext[4]))


def test_the_simulator_zero_pose_read_both_ways() -> None:
    values = [_f32(v) for v in forward_pose([0.0] * 6)] + [0.0] * 5
    for order in WordOrder:
        assert not judge_pose(_pose(values), order).swapped
        assert judge_pose(_pose(_misread(values, order)), other_order(order)).swapped


def test_nothing_to_judge_at_all_zero() -> None:
    assert not judge_values([0.0] * 11, WordOrder.LOW_FIRST).swapped
