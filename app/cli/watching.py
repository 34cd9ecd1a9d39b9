"""``teachpad-cli watch``: one status line per sample, as text or as JSON lines (``--json``).

A sample the controller did not answer in time (one missed 0.15 s poll, a dropped connection
that the next request opens again, a garbled answer) is printed as *stale* and the watch goes
on. The watch ends with exit 3 (a link problem) only when the link is down: the connection
cannot be opened again, or no sample has been answered for ``--down-after`` seconds.

Text lines::

    t=0.100 X=400 Y=0 Z=300 A=180 B=0 C=0 mode=auto program=stopped alarms=none cmd=0
    t=0.200 stale: controller did not answer within 0.15 s (127.0.0.1:1502)

JSON lines (one object a line, ``"stale"`` in every one)::

    {"t": 0.1, "stale": false, "pose": {...}, "mode": {...}, ...}   # as ``status --json``
    {"t": 0.2, "stale": true, "error": "controller did not answer within 0.15 s (...)"}
"""

from __future__ import annotations

import json
import time
from typing import Any

from app.cli.context import CliContext
from app.cli.exit_codes import LINK_ERRORS, ExitCode
from app.cli.format import format_watch_line, parse_positive_float, status_to_dict
from app.cli.watch_list_cmd import add_watch_list_arguments, watch_list_entries, watch_list_line
from app.errors import LinkError, ResponseTimeout, TeachPadError

__all__ = ["DOWN_AFTER_DEFAULT", "WATCH_RATE_DEFAULT", "add_watch_parser", "cmd_watch"]

WATCH_RATE_DEFAULT = 10.0  # Hz
DOWN_AFTER_DEFAULT = 3.0  # s without one answered sample: the link is down (exit 3)


def add_watch_parser(sub: Any) -> None:
    """Add ``watch`` to the main parser's subcommands."""
    p = sub.add_parser("watch", help="stream one status line per sample")
    p.add_argument(
        "--rate",
        type=parse_positive_float,
        default=WATCH_RATE_DEFAULT,
        metavar="HZ",
        help="samples per second, Hz (default %(default)g)",
    )
    p.add_argument("--count", type=int, default=0, metavar="N", help="stop after N lines (0: until Ctrl-C)")
    p.add_argument(
        "--json",
        action="store_true",
        help='JSON lines: one object per sample, as status --json plus "t" and "stale"',
    )
    p.add_argument(
        "--down-after",
        type=parse_positive_float,
        default=DOWN_AFTER_DEFAULT,
        metavar="S",
        help="a missed poll prints a stale line and the watch goes on; exit 3 when nothing has "
        "answered for S seconds or the connection cannot be opened again (default %(default)g)",
    )
    add_watch_list_arguments(p)  # --gv / --reg: the watch list instead of the pose
    p.set_defaults(handler=cmd_watch)


def _link_down(error: TeachPadError) -> bool:
    """The connection could not be opened (again): no later sample can be answered."""
    return isinstance(error, LinkError) and "reconnect" in error.params


def _sample_line(ctx: CliContext, elapsed: float) -> str:
    if watch_list_entries(ctx.args):
        return watch_list_line(ctx, elapsed)
    client = ctx.client
    timeout = ctx.settings.effective_poll_timeout
    status = client.read_status(timeout=timeout)
    pose = client.read_pose(timeout=timeout)
    if ctx.args.json:
        return json.dumps({"t": round(elapsed, 3), "stale": False, **status_to_dict(pose, status)})
    return format_watch_line(elapsed, pose, status)


def _stale_line(ctx: CliContext, elapsed: float, error: TeachPadError) -> str:
    if ctx.args.json:
        return json.dumps({"t": round(elapsed, 3), "stale": True, "error": str(error)}, ensure_ascii=False)
    return f"t={elapsed:.3f} stale: {error}"


def cmd_watch(ctx: CliContext) -> ExitCode:
    _ = ctx.client  # connect first: a controller that is not there at all is exit 3 at once
    period = 1.0 / ctx.args.rate
    count = ctx.args.count
    start = time.monotonic()
    answered = start  # when a sample was last answered
    next_t = start
    n = 0
    try:
        while count <= 0 or n < count:
            now = time.monotonic()
            try:
                line = _sample_line(ctx, now - start)
                answered = time.monotonic()
            except LINK_ERRORS as error:
                if _link_down(error):
                    raise
                if time.monotonic() - answered >= ctx.args.down_after:
                    raise ResponseTimeout(
                        f"the link is down: no answer for {ctx.args.down_after:g} s (last: {error})"
                    ) from None
                line = _stale_line(ctx, now - start, error)
            ctx.print(line)
            n += 1
            if count > 0 and n >= count:
                break
            next_t += period
            delay = next_t - time.monotonic()
            if delay > 0:
                time.sleep(delay)
            else:
                next_t = time.monotonic()  # fell behind: do not burst
    except KeyboardInterrupt:
        return ExitCode.OK  # Ctrl-C is how a watch normally ends
    return ExitCode.OK
