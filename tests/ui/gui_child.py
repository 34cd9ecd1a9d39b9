"""A TeachPad start in a child process (a fresh Python, offscreen, fresh per-user folders): what
only a real start shows -- imports before the first paint, the collector, code caches."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from app.user_dirs import fresh_user_dirs_env

ROOT = Path(__file__).resolve().parents[2]


def run_gui_child(
    code: str, tmp_path: Path, *args: str, env: Mapping[str, str] | None = None, expect: str
) -> dict[str, Any]:
    """Run ``code`` (``sys.argv[1]``: a settings file in ``tmp_path``, then ``args``) in the tree's
    folder with ``env`` (default: this process's) and its per-user folders under ``tmp_path``;
    the lines it printed as ``NAME json``, by name. Fails with the child's stderr when it did not
    end well or printed no ``expect`` line."""
    child_env = {
        **(os.environ if env is None else env),
        "QT_QPA_PLATFORM": "offscreen",
        **fresh_user_dirs_env(tmp_path),
    }
    out = subprocess.run(
        [sys.executable, "-c", code, str(tmp_path / "teachpad.ini"), *args],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
        env=child_env,
        check=False,
    )
    lines = {
        name: json.loads(rest)
        for name, _, rest in (x.partition(" ") for x in out.stdout.splitlines())
        if rest and name.isupper()
    }
    assert out.returncode == 0 and expect in lines, out.stderr[-2000:]
    return lines
