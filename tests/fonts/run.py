"""The layout and relayout tests under each font set and scale factor (``make test-fonts``).

For each font set of :mod:`tests.fonts.fontsets` whose folders are on this machine, a fontconfig
file that lists only them, then pytest in a process of its own with ``FONTCONFIG_FILE``,
``QT_SCALE_FACTOR`` and ``TEACHPAD_LAYOUT_SCREENS`` set: at 100 % the layout check
(``test_layout.py``), the live views' relayout checks (``test_live_views_cost.py``) and the
whole-number readouts (``test_readouts_whole.py``) at the README's minimum screen, 1280×800 and
1920×1080, both languages, the "another master" banner's two lines (``test_foreign_banner_layout.py``)
and the few-line labels (``tests/ui/widgets/test_lines_label.py``); at 125 % and 150 % the main
window's layout check on those screens (each as large as the scale leaves it; see
``test_layout.window_sizes``) and the relayout check.
Two processes at a time (the machine has two cores). A missing set is named with the packages
that bring it and fails the run only with ``--require-all`` (CI installs them first).
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

from tests.fonts.fontsets import FONT_SETS, describe_fonts, fontset_roots, write_config

SCREENS = "1024x768,1280x800,1920x1080,1920x1200"
SCALES = ("1", "1.25", "1.5")
FULL = [
    "tests/ui/test_layout.py",
    "tests/ui/panels/test_live_views_cost.py",
    "tests/ui/test_readouts_whole.py",
    "tests/ui/test_foreign_banner_layout.py",
    "tests/ui/widgets/test_lines_label.py",
]
SCALED = [
    "tests/ui/test_layout.py::test_main_window_layout",
    "tests/ui/test_layout.py::test_main_window_layout_with_an_alarm",
    "tests/ui/panels/test_live_views_cost.py::test_streaming_status_and_traffic_do_not_relayout_the_main_window",
]
RUN_TIMEOUT_S = 900


@dataclass
class Run:
    fontset: str
    scale: str
    config: Path
    log: Path
    fonts: str = ""
    code: int = -1
    summary: str = ""
    seconds: float = 0.0


def _env(run: Run) -> dict[str, str]:
    env = dict(os.environ)
    env.update(
        FONTCONFIG_FILE=str(run.config),
        QT_SCALE_FACTOR=run.scale,
        TEACHPAD_LAYOUT_SCREENS=SCREENS,
        TEACHPAD_FONTSET=run.fontset,
        QT_QPA_PLATFORM="offscreen",
    )
    env.pop("QT_FONT_DPI", None)
    return env


def _execute(run: Run) -> Run:
    tests = FULL if run.scale == "1" else SCALED
    command = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", *tests]
    env = _env(run)
    run.fonts = describe_fonts(env)
    started = time.monotonic()
    with run.log.open("w", encoding="utf-8") as out:
        try:
            result = subprocess.run(
                command, env=env, stdout=out, stderr=subprocess.STDOUT, timeout=RUN_TIMEOUT_S
            )
            run.code = result.returncode
        except subprocess.TimeoutExpired:
            run.code = 124
    run.seconds = time.monotonic() - started
    lines = [line.strip() for line in run.log.read_text(encoding="utf-8").splitlines() if line.strip()]
    run.summary = lines[-1].strip("= ") if lines else "(no output)"
    return run


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument(
        "--sets", default=",".join(s.name for s in FONT_SETS), help="font sets, comma-separated"
    )
    parser.add_argument("--scales", default=",".join(SCALES), help="QT_SCALE_FACTORs, comma-separated")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--require-all", action="store_true", help="a missing font set fails the run")
    args = parser.parse_args(argv)
    work = Path(tempfile.mkdtemp(prefix="teachpad-fontsets-"))
    runs: list[Run] = []
    missing = []
    for fonts in FONT_SETS:
        if fonts.name not in args.sets.split(","):
            continue
        folders = fonts.located(fontset_roots())
        if folders is None:
            missing.append(f"{fonts.name} (install {' '.join(fonts.packages)})")
            continue
        config = write_config(folders, work / fonts.name)
        for scale in args.scales.split(","):
            runs.append(Run(fonts.name, scale, config, work / f"{fonts.name}-{scale}.log"))
    for name in missing:
        print(f"font set missing: {name}", flush=True)
    print(f"{len(runs)} runs, {args.jobs} at a time; logs in {work} (removed when all pass)", flush=True)
    with ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        for run in pool.map(_execute, runs):
            verdict = "ok" if run.code == 0 else f"FAILED (exit {run.code})"
            print(
                f"[{run.fontset} @ {run.scale}] {verdict} in {run.seconds:.0f} s: {run.summary}", flush=True
            )
            print(f"    fonts: {run.fonts}", flush=True)
    failed = [run for run in runs if run.code != 0]
    for run in failed:
        print(f"\n----- {run.fontset} @ {run.scale}: {run.log} -----")
        text = run.log.read_text(encoding="utf-8")
        print(
            "\n".join(line for line in text.splitlines() if line.startswith(("E  ", "FAILED", "ERROR")))[
                -6000:
            ]
        )
    print(f"font sets: {len(runs) - len(failed)} passed, {len(failed)} failed")
    if failed or (missing and args.require_all) or not runs:
        return 1
    shutil.rmtree(work, ignore_errors=True)  # kept only when something failed (its logs)
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
