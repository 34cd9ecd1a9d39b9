"""Issue 13's "done when", by hand: ``teachpad-cli points upload`` of N points and a plan ``run``
against one simulator timing profile, with an error code injected for one point mid-upload.

The simulator runs in this process (so its state can be checked: a success the controller does
not hold is a false success); ``teachpad-cli`` runs as a subprocess with default settings
(completion "auto"). Prints one JSON line.

Usage: python -m benchmarks.completion_check --timing fast --gv291 read-only [--points 10000]
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from app.plan.segments import Plan, Segment
from app.points.ledger import PointLedger
from app.points.point import SyncState, make_point
from app.points.project import load_project, save_project
from app.points.project_model import Project
from app.sim.config import SimConfig
from app.sim.server import SimController

PLAN_SEGMENTS = 40


def build_project(n: int) -> Project:
    """Ids 1..61: a helix the plan runs through (lines and arcs); the rest: a grid of poses."""
    helix = PLAN_SEGMENTS + PLAN_SEGMENTS // 2 + 1
    pts = []
    for i in range(1, n + 1):
        if i <= helix:
            t = 0.35 * i
            pose = (450.0 + 80.0 * math.cos(t), 80.0 * math.sin(t), 300.0 + 0.05 * i, 180.0, 0.0, 0.0)
        else:
            pose = (300.0 + i % 100, -100.0 + i % 50, 300.0 + i % 20, 180.0, 0.0, float(i % 90))
        pts.append(make_point(i, f"p{i}", pose, sync=SyncState.UNKNOWN))
    segs: list[Segment] = []
    pid = 1
    for k in range(PLAN_SEGMENTS):
        if k % 2 == 0:
            segs.append(Segment.line(pid, speed=400.0))
            pid += 1
        else:
            segs.append(Segment.arc(pid, pid + 1, speed=300.0))
            pid += 2
    return Project("completion", PointLedger(pts), [Plan("helix", segs)])


def cli(port: int, *argv: str) -> tuple[int, str, str, float]:
    t0 = time.perf_counter()
    proc = subprocess.run(
        [sys.executable, "-m", "app.cli.main", "--host", "127.0.0.1", "--port", str(port), *argv],
        capture_output=True,
        text=True,
        check=False,
    )
    return proc.returncode, proc.stdout, proc.stderr, time.perf_counter() - t0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--timing", default="classic")
    parser.add_argument("--gv291", default="ignored")
    parser.add_argument("--points", type=int, default=10_000)
    parser.add_argument("--refuse", type=int, default=5000, help="point id the controller refuses")
    args = parser.parse_args(argv)
    sim = SimController(SimConfig(host="127.0.0.1", port=0, timing=args.timing, gv291=args.gv291))
    sim.start()
    try:
        sim.refuse_point(args.refuse)
        with tempfile.TemporaryDirectory(prefix="teachpad-completion-") as tmp:
            path = Path(tmp) / "completion.teachpad.json"
            save_project(build_project(args.points), path)
            before = sim.requests_count
            code, out, err, upload_s = cli(sim.port, "points", "upload", str(path))
            requests = sim.requests_count - before
            reported = [
                line.split(": P", 1)[1].split(":", 1)[0] for line in err.splitlines() if ": P" in line
            ]
            held = sim.state().points
            ledger = load_project(path).ledger
            claimed = [p for p in ledger if p.sync is SyncState.ON_CONTROLLER]
            false_ok = [
                p.id
                for p in claimed
                if p.id not in held  # float32 on the wire: compare to 1e-3
                or any(abs(a - b) > 1e-3 for a, b in zip(held[p.id], p.xyzabc, strict=True))
            ]
            missing = [p.id for p in ledger if p.id != args.refuse and p.id not in held]
            unconfirmed = next(
                (int(line.split()[0]) for line in out.splitlines() if "unconfirmed" in line), 0
            )
            run_code, run_out, run_err, run_s = cli(sim.port, "run", str(path), "--plan", "helix")
    finally:
        sim.stop()
    print(
        json.dumps(
            {
                "profile": f"{args.timing}/{args.gv291}",
                "points": args.points,
                "upload_exit": code,
                "failed_reported": reported,
                "false_successes": len(false_ok),
                "missing_on_controller": len(missing),
                "unconfirmed": unconfirmed,
                "requests_per_point": round(requests / args.points, 2),
                "upload_s": round(upload_s, 1),
                "ms_per_point": round(1000 * upload_s / args.points, 2),
                "run_exit": run_code,
                "run_s": round(run_s, 1),
                "run_tail": (run_out.strip().splitlines() or [""])[-1][:120],
                "run_err": run_err.strip()[:200],
            }
        )
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
