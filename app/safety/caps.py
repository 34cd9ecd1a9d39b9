"""The caps of reduced-speed mode, as the client applies them to every motion it sends.

Reduced-speed mode is a promise about *every* motion: each one the mode allows goes out at or
below its cap, whoever asked for it (a panel, a plan run, a move to a point, the CLI). So the
caps are applied where the values are written, by :class:`~app.link.client.RobotClient`
(``client.caps``), and shown where the operator sets a speed:

* a **ratio** (%): the teach jog's GV203 and a program run's speed ratio (449);
* a **TCP speed** (mm/s): base-frame steps and moves to a point (GV225);
* a **joint step** (GV225 in rpm): the rpm at which no point of the arm moves faster than the TCP
  cap. A point at distance r from a joint's axis moves at ``omega * r``, and no point of the arm
  is farther from any joint axis than the robot model's reach bound R, so one joint at
  ``cap / R`` rad/s keeps the TCP under the cap; when several robot joints move together (the
  controller runs them in step, the largest offset at the given rpm), their speeds add up, so
  the cap is divided by ``sum(|offset|) / max(|offset|)``. External axes (J7-J11) are not part
  of the arm's reach; a step of external axes alone gets the one-joint cap.
* **go to zero** has no speed the host sets (445 only): reduced-speed mode does not allow it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

__all__ = ["MotionCaps"]

_ROBOT_AXES = 6  # J1..J6: the arm; J7..J11 are external axes


@dataclass(frozen=True)
class MotionCaps:
    """Reduced-speed mode's caps: ``ratio`` (%), ``speed`` (mm/s), ``reach`` (mm, the robot
    model's reach bound, for the joint steps' rpm)."""

    ratio: float
    speed: float
    reach: float

    def __post_init__(self) -> None:
        for name in ("ratio", "speed", "reach"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"the {name} cap must be a number > 0, got {value!r}")

    def jog_ratio(self, ratio: float) -> float:
        """GV203 to send (0, the jog's stop, stays 0)."""
        return min(ratio, self.ratio)

    @property
    def program_ratio_cap(self) -> int:
        """The highest program speed ratio (449 takes whole percents, 1..100)."""
        return max(1, min(100, math.floor(self.ratio)))

    def program_ratio(self, ratio: int) -> int:
        return min(ratio, self.program_ratio_cap)

    def linear_speed(self, speed: float) -> float:
        """GV225 of a base-frame step or a move to a point (mm/s)."""
        return min(speed, self.speed)

    @property
    def joint_rpm_cap(self) -> float:
        """The rpm cap of one robot joint moving alone (see the module docstring)."""
        return self.speed / self.reach * 60.0 / (2.0 * math.pi)

    def joint_rpm_cap_for(self, offsets: Sequence[float]) -> float:
        """The rpm cap of a joint-frame step by ``offsets`` (J1..J11, degrees)."""
        robot = [abs(v) for v in list(offsets)[:_ROBOT_AXES] if v]
        together = sum(robot) / max(robot) if robot else 1.0
        return self.joint_rpm_cap / together

    def joint_speed(self, speed: float, offsets: Sequence[float]) -> float:
        """GV225 of a joint-frame step (rpm)."""
        return min(speed, self.joint_rpm_cap_for(offsets))
