"""``teachpad-cli watch --gv 10 --gv 11 --reg 560``: the watch list from a shell.

Each ``--gv N[:TYPE][=NAME]`` / ``--reg R[:TYPE][=NAME]`` adds a watched value (TYPE: float32,
int16 or bits; a GV is float32 unless told, a register int16; float32 in the register profile's
word order). With any of them, ``watch`` prints the watched values instead of the pose, one line
per sample, at ``--rate`` for ``--count`` lines, as text or JSON lines; a missed sample is a
*stale* line, as for the pose (app/cli/watching.py). A bad value (GV out of range, unknown type)
is a usage error, exit 2, before anything is sent. Read-only: writing a value is the GUI's
(an engineer's, confirmed and audited) or ``teachpad-cli write``'s (an administrator's).

Text::

    t=0.100 GV10=12.5 GV11=-3.25 reg560=1 reg562.bits=0b0000000000000101

JSON (``--json``)::

    {"t": 0.1, "stale": false, "values": [{"key": "GV10", "name": "tool length", "type": "float32",
     "value": 12.5, "raw": [0, 16712]}, ...]}
"""

from __future__ import annotations

import argparse
import json
from typing import Any

from app.cli.context import CliContext
from app.errors import InvalidInput
from app.watchlist.entry import MAX_ENTRIES, Source, ValueType, WatchEntry, WatchValue, parse_spec
from app.watchlist.plan import merge_blocks, read_blocks

__all__ = ["add_watch_list_arguments", "watch_list_entries", "watch_list_line"]

DEST = "watch_entries"


def _spec(source: Source) -> Any:
    def parse(text: str) -> WatchEntry:
        try:
            return parse_spec(source, text)
        except InvalidInput as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None

    parse.__name__ = source.value  # argparse names the option's type in its message
    return parse


def add_watch_list_arguments(parser: argparse.ArgumentParser) -> None:
    """``--gv`` and ``--reg`` on ``watch`` (in the order given, into one list)."""
    group = parser.add_argument_group(
        "watch list", "watch these GVs or registers instead of the pose (TYPE: float32, int16, bits)"
    )
    group.add_argument(
        "--gv",
        dest=DEST,
        action="append",
        type=_spec(Source.GV),
        metavar="N[:TYPE][=NAME]",
        help="a GV by its number (0..32767), float32 unless TYPE says otherwise",
    )
    group.add_argument(
        "--reg",
        dest=DEST,
        action="append",
        type=_spec(Source.REGISTER),
        metavar="R[:TYPE][=NAME]",
        help="a holding register by its address (0..65535), int16 unless TYPE says otherwise",
    )


def watch_list_entries(args: argparse.Namespace) -> list[WatchEntry]:
    entries: list[WatchEntry] = list(getattr(args, DEST, None) or [])
    if len(entries) > MAX_ENTRIES:
        raise InvalidInput(f"at most {MAX_ENTRIES} watched values")
    return entries


def _text(value: WatchValue) -> str:
    entry = value.entry
    if value.value is None:
        return f"{entry.key}=error"
    if entry.type is ValueType.BITS:
        return f"{entry.key}=0b{int(value.value):016b}"
    if entry.type is ValueType.INT16:
        return f"{entry.key}={int(value.value)}"
    return f"{entry.key}={float(value.value):.7g}"


def _as_dict(value: WatchValue) -> dict[str, Any]:
    entry = value.entry
    out: dict[str, Any] = {
        "key": entry.key,
        "name": entry.name,
        "source": entry.source.value,
        "number": entry.number,
        "type": entry.type.value,
        "value": value.value,
        "raw": list(value.raw),
    }
    if value.error is not None:
        out["error"] = value.error
    return out


def watch_list_line(ctx: CliContext, elapsed: float) -> str:
    """One sample of the watch list (raises the link's error: the caller prints a stale line)."""
    entries = watch_list_entries(ctx.args)
    client = ctx.client
    with client.io_timeout(ctx.settings.effective_poll_timeout):
        values = read_blocks(client.read_registers, merge_blocks(entries), entries, ctx.settings.word_order)
    order = {entry: i for i, entry in enumerate(entries)}
    values.sort(key=lambda v: order[v.entry])
    if ctx.args.json:
        doc = {"t": round(elapsed, 3), "stale": False, "values": [_as_dict(v) for v in values]}
        return json.dumps(doc, ensure_ascii=False)
    return f"t={elapsed:.3f} " + " ".join(_text(v) for v in values)
