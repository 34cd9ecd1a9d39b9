"""Guard-rail benchmarks: the audit trail's cost per record by fsync policy, the jog guard's
decision per poll, and the envelope check of a plan (lines and arcs).

Usage: python -m benchmarks.safety [--quick]   (prints one JSON object)
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from app.models import Pose
from app.plan.segments import Plan, Segment, SegmentKind
from app.points.ledger import PointLedger
from app.points.point import make_point
from app.protocol.enums import TeachFrame
from app.safety.audit import AuditLog, FsyncPolicy
from app.safety.box import Box
from app.safety.envelope import Envelope, plan_violations
from app.safety.jog_guard import JogGuard, JogMotion

# eight small zones among the plan's paths (z 350..450 around the plan's z = 400)
ZONES = tuple(Box(f"zone {i}", (i * 50.0 - 200, 400, 350), (i * 50.0 - 180, 420, 450)) for i in range(8))
ENV = Envelope(keep_in=Box("cell", (-900, -900, 0), (900, 900, 1200)), keep_out=ZONES)


def _per_call_us(fn: Any, n: int) -> float:
    t0 = time.perf_counter()
    for _ in range(n):
        fn()
    return (time.perf_counter() - t0) / n * 1e6


def run(quick: bool = False) -> dict[str, Any]:
    out: dict[str, Any] = {}
    base = Path(__file__).resolve().parent  # a real disk, not a tmpfs
    audit: dict[str, float] = {}
    for policy in FsyncPolicy:
        with tempfile.TemporaryDirectory(dir=base) as d:
            log = AuditLog(Path(d), fsync=policy)
            n = (50 if quick else 300) if policy is FsyncPolicy.ALWAYS else (500 if quick else 3000)
            per = _per_call_us(lambda log=log: log.record_write(406, [0, 0x41A0]), n)
            audit[policy.value] = round(per, 1)
            log.close()
    out["audit_us_per_write_record"] = audit
    guard = JogGuard(ENV, poll_period=0.02)
    pose = Pose(100.0, 500.0, 200.0, 180.0, 0.0, 0.0)
    motion = JogMotion(TeachFrame.BASE, 1, 1, 50.0)
    out["jog_guard_us_per_decision"] = round(_per_call_us(lambda: guard.decide(pose, motion), 2000), 1)
    n = 20 if quick else 100
    ledger = PointLedger(
        [
            make_point(i + 1, pose=(400 * (i % 2) - 200, 300 * ((i // 2) % 2) - 150, 400, 180, 0, 0))
            for i in range(n + 1)
        ]
    )
    segs = [
        Segment(SegmentKind.ARC, end_id=i + 2, via_id=i + 1, speed=100)
        if i % 2
        else Segment(SegmentKind.LINE, end_id=i + 1, speed=100)
        for i in range(n)
    ]
    plan = Plan("bench", segs)
    t0 = time.perf_counter()
    found = plan_violations(plan, ledger, ENV, Pose(0, 0, 400, 180, 0, 0))
    out["plan_check_ms"] = {
        "segments": n,
        "ms": round((time.perf_counter() - t0) * 1e3, 1),
        "violations": len(found),
    }
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args(argv)
    json.dump(run(args.quick), sys.stdout, indent=2)
    sys.stdout.write("\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
