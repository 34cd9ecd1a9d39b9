"""Is the register profile's float word order probably wrong? Judged from one pose read.

A float32 read in the wrong word order is its two 16-bit words swapped. The swap of a value a
controller really reports is rarely a number a robot could stand at: a round value (180.0, 30.0,
0.5: its low word is 0) becomes a denormal below 1.2e-38, and any other value gets the exponent of
what were its low mantissa bits -- mostly far below a micrometre or far beyond any reach, now and
then NaN. So with the wrong order the pose reads like that, while the same registers read in the
other order are an ordinary pose.

The rule (:func:`judge_values`) looks at the documented live floats only -- X Y Z A B C (GV206..211)
and the external axes EJ1..EJ5 (GV212..216); not the joints, which a real controller may not
publish (PROTOCOL.md section 3: the simulator's extension), so their registers may hold anything.
A read is **a pose** when every value is finite and within :data:`MAX_PLAUSIBLE` (1e6: a kilometre
in mm, thousands of turns in degrees) and the tool centre point is at least :data:`MIN_REACH`
(10 mm) from the base frame's origin (no arm folds its flange into its own base). The profile's
order is **probably wrong** when the read is not a pose and the same registers read in the other
order are one.

Per value rules do not work: real arithmetic leaves residuals anywhere down to 1e-31 (the
simulator's C at its start pose is 3.5e-31), and a wrong-order read of a pose is often only small
numbers (the simulator's start pose reads X = 5.7e-6, Z = 4.9e-8 mm). The tool centre point's
distance tells them apart: a real pose is never at the origin, a misread one nearly always is (or
holds a value beyond any reach).

A correct profile never fires: its read is the controller's own pose, finite, within reach and away
from the origin (a controller that reports zeros, or NaN, reads the same or worse the other way
round: no warning either). Measured over random poses, the simulator's poses and its zero pose
(tests/protocol/test_word_order_check.py prints the figures): no false warning; with the wrong
order the warning comes for nearly every single read, and a missed read is followed by the next.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from app.models import Pose
from app.protocol.codec import WordOrder, decode_floats, encode_floats

__all__ = [
    "MAX_PLAUSIBLE",
    "MIN_REACH",
    "WordOrderVerdict",
    "is_pose",
    "judge_pose",
    "judge_values",
    "other_order",
    "warning_text",
]

MAX_PLAUSIBLE = 1e6
MIN_REACH = 10.0  # mm from the base frame's origin to the tool centre point, at least


def other_order(order: WordOrder) -> WordOrder:
    return WordOrder.HIGH_FIRST if order is WordOrder.LOW_FIRST else WordOrder.LOW_FIRST


def is_pose(values: Sequence[float]) -> bool:
    """X Y Z A B C (and the external axes) a controller could report (see the module docstring)."""
    if not all(math.isfinite(v) and abs(v) <= MAX_PLAUSIBLE for v in values):
        return False
    x, y, z = values[0], values[1], values[2]
    return math.sqrt(x * x + y * y + z * z) >= MIN_REACH


@dataclass(frozen=True)
class WordOrderVerdict:
    """The judgement of one read: ``swapped`` True when the profile's ``order`` is probably wrong
    and ``suggested`` is the order to set; ``read`` the values as read, ``other`` the same
    registers in the other order (the same length, X Y Z A B C then EJ1..EJ5)."""

    order: WordOrder
    swapped: bool
    read: tuple[float, ...]
    other: tuple[float, ...]

    @property
    def suggested(self) -> WordOrder:
        return other_order(self.order) if self.swapped else self.order


def judge_values(values: Sequence[float], order: WordOrder) -> WordOrderVerdict:
    """The verdict on ``values`` decoded from the controller's registers in ``order``."""
    read = tuple(float(v) for v in values)
    # the registers back from the decoded float32 values (exact for every finite float32), then
    # read the other way round
    other = tuple(decode_floats(encode_floats(read, order), other_order(order)))
    return WordOrderVerdict(order, not is_pose(read) and is_pose(other), read, other)


def judge_pose(pose: Pose, order: WordOrder) -> WordOrderVerdict:
    """The verdict on one pose read in ``order`` (X Y Z A B C and the external axes)."""
    return judge_values((*pose.xyzabc, *pose.ext), order)


def _plain(values: Sequence[float]) -> str:
    names = ("X", "Y", "Z", "A", "B", "C")
    return " ".join(f"{name}={value:.6g}" for name, value in zip(names, values, strict=False))


def warning_text(verdict: WordOrderVerdict) -> str:
    """The warning in plain English (teachpad-cli, logs): what is wrong, the evidence, what to set."""
    order, other = verdict.order.value, verdict.suggested.value
    return (
        f"the controller's floats look word-swapped: read {order} the pose is {_plain(verdict.read[:6])}, "
        f"read {other} it is {_plain(verdict.other[:6])}; set the register profile's word_order to "
        f'"{other}" (or --word-order {other}): until then every position and speed read or sent is wrong'
    )
