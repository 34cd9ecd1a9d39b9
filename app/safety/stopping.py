"""Measured stopping: how long the arm took to come to rest after a Stop or a jog release, and
how far it went meanwhile -- the number a safety engineer asks for.

An observer, not part of the stop: :class:`StopWatch` is told the moment of the operator's
click (``time.monotonic()``) and the pose known then, and is fed every good poll afterwards
(its ``time.monotonic()`` and the pose it read); it never sends anything. The arm is **still**
when two consecutive polls agree within :data:`STILL_MM` (position and external axes) and
:data:`STILL_DEG` (orientation) and are at least :data:`app.timing.STOP_STILL_SPAN` apart (a
poll closer to the one before is passed over: polls in a bunch may read one controller update
twice); the stop's time is from the click to the first poll of that
pair (the first time the arm was seen where it came to rest), so it is the controller's own
stopping time plus at most one poll period. The pose known at the click counts as the poll
before the first: an arm that was not moving measures 0 ms. The distance is the path the
polls saw after the click: the sum of the straight steps between them, the first from where the
arm was at the click (between the poll before the click and the one after it, as if it moved
evenly: the pose known at the click is as old as its poll). No rest within
:data:`app.timing.STOP_STILL_TIMEOUT` s: the measurement says so ("not seen still within 5 s")
with the distance up to then.

:class:`StopLog` keeps one session's measurements (the monitor's "last stop" line, the support
bundle's summary). Qt-free: ``ui/controllers/stop_timing.py`` wires it to the Stop button, the
jog release and ``RobotState.polled``.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Final

from app import timing
from app.geometry import abc_to_matrix
from app.models import Pose

__all__ = [
    "STILL_DEG",
    "STILL_MM",
    "StopKind",
    "StopLog",
    "StopMeasurement",
    "StopWatch",
    "summary_lines",
]

STILL_MM: Final = 0.02  # mm (and external axis units) two polls may differ by and count as still
STILL_DEG: Final = 0.02  # degrees of orientation two polls may differ by and count as still


class StopKind(enum.Enum):
    STOP = "stop"  # the Stop button (or Esc)
    JOG_RELEASE = "jog release"  # a jog button or key let go


@dataclass(frozen=True)
class StopMeasurement:
    """One measured stop. ``seconds``: from the click to the arm seen still (to the timeout when
    ``still`` is False); ``distance_mm``: the path travelled after the click (as far as seen)."""

    kind: StopKind
    clicked_at: float  # time.monotonic() of the click
    still: bool
    seconds: float
    distance_mm: float
    rotation_deg: float  # orientation turned after the click (pose at the click to the last seen)
    polls: int  # polls seen after the click
    timeout: float
    #: how exact ``seconds`` is: the time between the first still poll and the poll (or the
    #: click) before it -- the arm came to rest somewhere in there (about one poll period)
    poll_gap: float = 0.0

    @property
    def ms(self) -> int:
        return round(self.seconds * 1000.0)

    @property
    def text(self) -> str:
        """English, for logs and the audit: ``180 ms, 4.2 mm`` or ``not seen still within 5 s, 4.2 mm``."""
        if self.still:
            return f"{self.ms} ms, {self.distance_mm:.1f} mm"
        return f"not seen still within {self.timeout:g} s, {self.distance_mm:.1f} mm"

    def audit_args(self) -> dict[str, object]:
        return {
            "kind": self.kind.value,
            "still": self.still,
            "ms": self.ms,
            "mm": round(self.distance_mm, 3),
            "deg": round(self.rotation_deg, 3),
            "polls": self.polls,
        }


def _apart(a: Pose, b: Pose) -> tuple[float, float]:
    """(largest of the position distance and the external axes' change, orientation angle)."""
    ext = max((abs(p - q) for p, q in zip(a.ext, b.ext, strict=False)), default=0.0)
    return max(math.dist((a.x, a.y, a.z), (b.x, b.y, b.z)), ext), _angle(a, b)


def _angle(a: Pose, b: Pose) -> float:
    if (a.a, a.b, a.c) == (b.a, b.b, b.c):
        return 0.0
    rel = abc_to_matrix(a.a, a.b, a.c).T @ abc_to_matrix(b.a, b.b, b.c)
    sine = 0.5 * math.hypot(
        float(rel[2, 1] - rel[1, 2]), float(rel[0, 2] - rel[2, 0]), float(rel[1, 0] - rel[0, 1])
    )
    cosine = 0.5 * (float(rel[0, 0] + rel[1, 1] + rel[2, 2]) - 1.0)
    return math.degrees(math.atan2(sine, cosine))


class StopWatch:
    """Times one stop at a time (see the module docstring). A click while one is being timed
    starts over: the arm has not been seen still since the first, so the second's time is the
    one that matters."""

    def __init__(
        self, *, still_mm: float = STILL_MM, still_deg: float = STILL_DEG, timeout: float | None = None
    ) -> None:
        self.still_mm = still_mm
        self.still_deg = still_deg
        self._timeout = timeout
        self._kind = StopKind.STOP
        self._clicked: float | None = None
        self._start: Pose | None = None  # the pose known at the click
        self._seen_at: float | None = None  # when that pose was polled
        self._prev: tuple[float, Pose] | None = None
        self._before: float | None = None  # the time of the sample before self._prev
        self._distance = 0.0
        self._polls = 0

    @property
    def timeout(self) -> float:
        return timing.STOP_STILL_TIMEOUT if self._timeout is None else self._timeout

    @property
    def measuring(self) -> bool:
        return self._clicked is not None

    @property
    def deadline(self) -> float | None:
        """``time.monotonic()`` by which the arm must be seen still (None: not measuring)."""
        return None if self._clicked is None else self._clicked + self.timeout

    def click(self, kind: StopKind, at: float, pose: Pose | None, seen_at: float | None = None) -> None:
        """The operator's Stop or jog release at ``at``; ``pose``: the last pose polled before it,
        at ``seen_at`` (None: not known; the distance then starts at ``pose`` itself)."""
        self._kind = kind
        self._clicked = at
        self._start = pose
        self._seen_at = seen_at
        self._prev = None if pose is None else (at, pose)
        self._before = None
        self._distance = 0.0
        self._polls = 0

    def sample(self, at: float, pose: Pose) -> StopMeasurement | None:
        """A good poll at ``at`` read ``pose``; the measurement once the arm is seen still (or the
        timeout passed), else None. Polls from before the click are ignored."""
        clicked = self._clicked
        if clicked is None or at < clicked:
            return None
        self._polls += 1
        prev = self._prev
        before = self._before
        self._before = prev[0] if prev is not None else clicked
        self._prev = (at, pose)
        if self._start is None:
            self._start = pose
        if prev is not None:
            moved, turned = _apart(prev[1], pose)
            alike = moved <= self.still_mm and turned <= self.still_deg
            if alike and at - prev[0] < timing.STOP_STILL_SPAN:
                self._prev, self._before = prev, before  # too close to tell: wait for a later poll
            else:
                self._distance += math.dist(self._from(prev, at, pose), (pose.x, pose.y, pose.z))
            if alike and at - prev[0] >= timing.STOP_STILL_SPAN:
                gap = prev[0] - (before if before is not None else clicked)
                return self._finish(still=True, seconds=max(0.0, prev[0] - clicked), last=pose, gap=gap)
        if at - clicked >= self.timeout:
            return self._finish(still=False, seconds=self.timeout, last=pose)
        return None

    def _from(self, prev: tuple[float, Pose], at: float, pose: Pose) -> tuple[float, float, float]:
        """Where the step to the poll at ``at`` (``pose``) starts: the previous poll's position; for
        the first poll after the click, the position at the click itself, between the poll before
        it (at ``seen_at``) and this one, as if the arm moved evenly (the pose known at the click
        is as old as that poll: counting from it would add what the arm did before the click)."""
        p = prev[1]
        seen, clicked = self._seen_at, self._clicked
        if prev[0] != clicked or seen is None or clicked is None or not seen < clicked <= at:
            return (p.x, p.y, p.z)
        f = (clicked - seen) / (at - seen)
        return (p.x + f * (pose.x - p.x), p.y + f * (pose.y - p.y), p.z + f * (pose.z - p.z))

    def expire(self, now: float) -> StopMeasurement | None:
        """The timeout passed without a poll showing rest (no polls at all: a lost link)."""
        clicked = self._clicked
        if clicked is None or now - clicked < self.timeout:
            return None
        last = self._prev[1] if self._prev is not None else self._start
        return self._finish(still=False, seconds=self.timeout, last=last)

    def cancel(self) -> None:
        self._clicked = None

    def _finish(self, *, still: bool, seconds: float, last: Pose | None, gap: float = 0.0) -> StopMeasurement:
        start = self._start
        turned = _angle(start, last) if start is not None and last is not None else 0.0
        measurement = StopMeasurement(
            self._kind,
            self._clicked if self._clicked is not None else 0.0,
            still,
            seconds,
            self._distance,
            turned,
            self._polls,
            self.timeout,
            max(0.0, gap),
        )
        self._clicked = None
        return measurement


class StopLog:
    """One session's measurements, oldest first (at most :data:`LIMIT`, the oldest dropped)."""

    LIMIT: Final = 10_000

    def __init__(self) -> None:
        self._items: list[StopMeasurement] = []
        self.dropped = 0

    def add(self, measurement: StopMeasurement) -> None:
        self._items.append(measurement)
        if len(self._items) > self.LIMIT:
            del self._items[0]
            self.dropped += 1

    @property
    def measurements(self) -> tuple[StopMeasurement, ...]:
        return tuple(self._items)

    @property
    def last(self) -> StopMeasurement | None:
        return self._items[-1] if self._items else None

    def __len__(self) -> int:
        return len(self._items)

    def summary_lines(self) -> list[str]:
        return summary_lines(self._items)


def summary_lines(measurements: Iterable[StopMeasurement]) -> list[str]:
    """English lines for the support bundle: per kind, how many, the times and distances (median
    and largest), the timeouts; then every measurement, one a line."""
    items = list(measurements)
    if not items:
        return ["measured stopping: no Stop or jog release in this session"]
    lines = [f"measured stopping: {len(items)} in this session (click to the arm seen still)"]
    for kind in StopKind:
        of_kind = [m for m in items if m.kind is kind]
        still = [m for m in of_kind if m.still]
        if not of_kind:
            continue
        line = f"{kind.value}: {len(of_kind)}"
        if still:
            import statistics  # with fractions and decimal: a report's, not the window's start (~2 ms)

            times = [m.seconds * 1000.0 for m in still]
            mm = [m.distance_mm for m in still]
            line += (
                f"; time median {statistics.median(times):.0f} ms, largest {max(times):.0f} ms"
                f"; distance median {statistics.median(mm):.1f} mm, largest {max(mm):.1f} mm"
            )
        if len(still) < len(of_kind):
            line += f"; {len(of_kind) - len(still)} not seen still within the timeout"
        lines.append(line)
    lines.append("each (seconds after the first, kind, result, polls):")
    first = items[0].clicked_at
    lines.extend(
        f"  +{m.clicked_at - first:.3f} s  {m.kind.value}: {m.text} ({m.polls} polls)" for m in items
    )
    return lines
