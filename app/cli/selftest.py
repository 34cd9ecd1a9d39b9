"""``teachpad-cli selftest``: the register-map self-test (:mod:`app.selftest.checks`), write-free.

Reads the documented registers once (0x03 only), checks them against the register profile in
force (``--register-profile`` and the overrides) and the robot model (``--robot-profile``, else
the default), and prints one line per check: what matches, what does not and the likely fix.
Exit 0 only when everything that could be checked matched; 1 when something did not; 3 when the
controller could not be read.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from app.cli.context import CliContext
from app.cli.exit_codes import ExitCode
from app.link.register_reads import read_blocks
from app.selftest.checks import SELFTEST_BLOCKS, SelfTestReport, check_register_map

__all__ = ["cmd_selftest", "register", "report_to_dict"]


def register(sub: Any) -> None:
    """Add ``selftest`` to the main parser's subcommands."""
    p = sub.add_parser(
        "selftest",
        help="check the controller's register map against the register profile (reads only)",
        description="Read the registers the vendor document defines (nothing is written, nothing "
        "moves) and check them against the register profile in force: the pose against the joints "
        "through the robot model (word order, units, the A B C convention), the date/time registers "
        "against this PC's clock, the mode, program state and alarm words within their tables, GV291 "
        "within its codes. One line per check, with the likely fix of what does not match. Exit 0 "
        "only when everything that could be checked matched.",
    )
    p.add_argument(
        "--robot-profile",
        type=Path,
        metavar="FILE",
        help="the robot model to compute the pose from the joints (default: the simulator's arm)",
    )
    p.add_argument("--json", action="store_true", help="one JSON object")
    p.set_defaults(handler=cmd_selftest)


def report_to_dict(report: SelfTestReport) -> dict[str, Any]:
    return {
        "passed": report.passed,
        "summary": report.summary(),
        "word_order": report.word_order.value,
        "datetime_layout": report.datetime_layout.value,
        "settings_to_change": report.settings_to_change,
        "lines": [
            {
                "check": line.check,
                "verdict": line.verdict.value,
                "code": line.code,
                "text": line.text,
                "fix": line.fix or None,
                "setting": None if line.setting is None else {line.setting[0]: line.setting[1]},
            }
            for line in report.lines
        ],
    }


def cmd_selftest(ctx: CliContext) -> ExitCode:
    from app.cli.run_plan import robot_model  # numpy and the model: only for this command

    model = robot_model(ctx.args.robot_profile)  # a bad file: a usage error before anything is read
    read = read_blocks(ctx.client, SELFTEST_BLOCKS)
    settings = ctx.settings
    report = check_register_map(read, settings.word_order, settings.datetime_layout, model)
    if ctx.args.json:
        ctx.print(json.dumps(report_to_dict(report), ensure_ascii=False))
    else:
        for line in report.lines:
            ctx.print(line.line)
        ctx.print(report.summary())
    return ExitCode.OK if report.passed else ExitCode.FAILED
