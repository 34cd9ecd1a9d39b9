"""How long a plan takes: lengths / speeds plus a per-segment overhead, and the timeouts the
runner waits with.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

from app import timing
from app.errors import InvalidInput
from app.lazy_numpy import FloatArray
from app.plan.geometry import PointLike, plan_geometry
from app.plan.segments import Plan
from app.points.ledger import (
    PointLedger,
)

if TYPE_CHECKING:
    import numpy as np
else:  # numpy is imported by its first use, not with this module (app/lazy_numpy.py)
    from app.lazy_numpy import np

#: Time added per segment to length / speed: command round trip, acceleration, settling (s).
SEGMENT_OVERHEAD_S = 0.3


def estimate_time(length: float, speed: float, overhead: float = SEGMENT_OVERHEAD_S) -> float:
    """Seconds for one segment: length / speed plus a fixed per-segment overhead."""
    if not speed > 0:
        raise InvalidInput(f"speed {speed:g} mm/s: must be > 0")
    return length / speed + overhead


def move_timeout(estimate: float) -> float:
    """Timeout for waiting on one move: 3 x its estimate, at least ``timing.MOVE_TIMEOUT_MIN``."""
    if not math.isfinite(estimate):
        return float(timing.MOVE_TIMEOUT_MIN)
    return max(float(timing.MOVE_TIMEOUT_MIN), 3.0 * estimate)


@dataclass(frozen=True)
class PlanEstimate:
    """Lengths (mm) and times (s) of a plan.

    ``lengths``/``times`` are the first loop's (segment 0 from the start pose); on later loops
    segment 0 starts at the last segment's end, which ``next_loop_*`` accounts for.
    ``unknown`` lists segments whose length could not be computed (left out of the sums).
    With ``loops == 0`` (endless) the totals are infinite.
    """

    lengths: FloatArray
    times: FloatArray
    loop_length: float
    loop_time: float
    next_loop_length: float
    next_loop_time: float
    wrap_length: float  # segment 0 on loops after the first (NaN if unknown)
    wrap_time: float
    loops: int
    total_length: float
    total_time: float
    unknown: tuple[int, ...]


def estimate_plan(
    plan: Plan,
    ledger: PointLedger,
    start: PointLike | None = None,
    *,
    loops: int | None = None,
    overhead: float = SEGMENT_OVERHEAD_S,
) -> PlanEstimate:
    loops = plan.loops if loops is None else loops
    geo = plan_geometry(plan, ledger, start)
    speeds = np.array([seg.speed for seg in plan.segments], dtype=np.float64)
    safe = np.where(speeds > 0, speeds, np.nan)
    times = geo.lengths / safe + overhead
    known = np.isfinite(times)
    loop_length = float(np.nansum(np.where(known, geo.lengths, np.nan)))
    loop_time = float(np.nansum(times))
    next_length, next_time = loop_length, loop_time
    wrap_length = wrap_time = math.nan
    if len(geo):
        wrap = plan_geometry(plan.segments[:1], ledger, geo.ends[-1])
        wrap_length = float(wrap.lengths[0])
        wrap_time = wrap_length / float(safe[0]) + overhead
        if math.isfinite(wrap_time):
            next_length = loop_length - (float(geo.lengths[0]) if known[0] else 0.0) + wrap_length
            next_time = loop_time - (float(times[0]) if known[0] else 0.0) + wrap_time
    if loops == 0:
        total_length = total_time = math.inf
    else:
        total_length = loop_length + (loops - 1) * next_length
        total_time = loop_time + (loops - 1) * next_time
    return PlanEstimate(
        lengths=geo.lengths,
        times=np.asarray(times, dtype=np.float64),
        loop_length=loop_length,
        loop_time=loop_time,
        next_loop_length=next_length,
        next_loop_time=next_time,
        wrap_length=wrap_length,
        wrap_time=wrap_time,
        loops=loops,
        total_length=total_length,
        total_time=total_time,
        unknown=tuple(int(i) for i in np.flatnonzero(~known)),
    )


def segment_timeouts(plan: Plan, ledger: PointLedger, start: PointLike | None = None) -> list[float | None]:
    """Per-segment wait timeouts (s) for the runner (see :func:`move_timeout`); None where the
    length is unknown (the client then uses its own default). Segment 0 gets the longer of its
    first-loop and later-loop estimates."""
    est = estimate_plan(plan, ledger, start)
    out: list[float | None] = [move_timeout(float(t)) if math.isfinite(t) else None for t in est.times]
    if len(plan) and plan.loops != 1 and math.isfinite(est.wrap_time):
        first = float(est.times[0])
        out[0] = move_timeout(max(est.wrap_time, first) if math.isfinite(first) else est.wrap_time)
    return out
