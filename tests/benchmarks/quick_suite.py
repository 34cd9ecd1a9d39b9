"""The one way a test runs a ``make bench`` suite's quick run: ``python -m benchmarks.run --quick
--only SUITE`` in a child process (real simulators, brokers and windows, as ``make bench`` runs
them), its JSON parsed and the suite's figures checked to be measured.

A quick run takes ~5-20 s on a quiet machine and over 120 s beside a busy one (the gateway's did,
in a CI run beside eight engineers' work), so a test that calls :func:`quick_run` carries its own
limit, :data:`QUICK_RUN_LIMIT`, not the suite's 120 s per test.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

__all__ = ["QUICK_RUN_LIMIT", "RUN_TIMEOUT", "lookup", "quick_run"]

ROOT = Path(__file__).resolve().parents[2]
RUN_TIMEOUT = 360.0  # s the child may take
QUICK_RUN_LIMIT = RUN_TIMEOUT + 60  # s for the test (pytest.mark.timeout)


def quick_run(suite: str) -> dict[str, Any]:
    """The whole JSON object of the quick run of ``suite`` (its figures measured, goals beside)."""
    env = dict(os.environ, PYTHONPATH=str(ROOT), QT_QPA_PLATFORM="offscreen")
    done = subprocess.run(
        [sys.executable, "-m", "benchmarks.run", "--quick", "--only", suite, "--no-compile"],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=RUN_TIMEOUT,
        check=False,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    out: dict[str, Any] = json.loads(done.stdout)
    assert "not_measured" not in out[suite], out[suite]
    return out


def lookup(data: dict[str, Any], key: str) -> Any:
    """The figure at a dotted ``key`` (``gateway.gateway_64.cpu_pct_of_one_core``)."""
    node: Any = data
    for part in key.split("."):
        assert isinstance(node, dict) and part in node, f"{key}: no {part!r} in {node!r:.300}"
        node = node[part]
    return node
