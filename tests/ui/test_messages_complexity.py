"""The operator's sentences stay readable code: no function of ``ui/messages*.py`` over ruff's
C901 complexity 10 (issue 21: ``reason_text`` was 12, two jobs in one -- the codes with a sentence
of their own and the template tables; split along that seam)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.timeout(60)
def test_message_functions_within_complexity_ten() -> None:
    files = sorted(str(p.relative_to(ROOT)) for p in (ROOT / "ui").glob("messages*.py"))
    assert files
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "ruff",
            "check",
            "--isolated",
            "--select",
            "C901",
            "--config",
            "lint.mccabe.max-complexity=10",
            "--output-format",
            "concise",
            *files,
        ],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 0, done.stdout + done.stderr
