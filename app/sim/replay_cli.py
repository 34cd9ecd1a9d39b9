"""``teachpad-sim --replay CAPTURE``: serve a traffic capture (:mod:`app.sim.replay`) in the
foreground until Ctrl-C, ``quit`` on stdin or the end of stdin (``--stop-with-stdin``); ``status``
on stdin prints what was answered and what could not be matched. The summary and every unmatched
request are printed when it stops."""

from __future__ import annotations

import argparse
import sys
import threading
from collections.abc import Callable
from pathlib import Path

from app.sim.replay import ReplayBook, ReplayError, ReplayServer, read_capture
from app.stop_signals import SignalNote

__all__ = ["run_replay"]

#: How many unmatched requests the final report lists one by one (the rest are counted).
LISTED = 50


def run_replay(
    args: argparse.Namespace,
    stop_on_signals: Callable[[], SignalNote],
    say: Callable[[str], None],
    wait_for_end_of_stdin: Callable[[threading.Event], None],
) -> int:
    """Serve ``args.replay``; the simulator's own helpers (app/sim/cli.py) are passed in."""
    try:
        exchanges = read_capture(Path(args.replay))
    except ReplayError as exc:
        print(f"teachpad-sim: {exc}", file=sys.stderr)
        return 2
    book = ReplayBook(exchanges)
    server = ReplayServer(book, args.host, args.port)
    try:
        server.start()
    except OSError as exc:
        print(f"teachpad-sim: {exc}", file=sys.stderr)
        return 1
    done = threading.Event()
    stop = stop_on_signals()
    say(
        f"teachpad-sim replaying {Path(args.replay).name} ({len(exchanges)} captured requests) on "
        f"{server.endpoint}; Ctrl-C to stop"
    )
    if not args.no_stdin:
        threading.Thread(target=_read_commands, args=(book, done), name="replay-stdin", daemon=True).start()
    elif args.stop_with_stdin:
        threading.Thread(target=wait_for_end_of_stdin, args=(done,), daemon=True).start()
    try:
        while not stop.wait(0.2, done):
            pass
    except KeyboardInterrupt:
        pass
    finally:
        server.stop()
        stop.restore()
    for line in report_lines(book):
        say(line)
    return 0


def report_lines(book: ReplayBook) -> list[str]:
    """The summary, then each unmatched request (the first :data:`LISTED`)."""
    lines = [f"teachpad-sim replay: {book.summary()}"]
    lines += [f"  unmatched: {item.text}" for item in book.unmatched[:LISTED]]
    if len(book.unmatched) > LISTED:
        lines.append(f"  ... and {len(book.unmatched) - LISTED} more unmatched")
    return lines


def _read_commands(book: ReplayBook, done: threading.Event) -> None:
    try:
        for line in sys.stdin:
            word = line.strip().lower()
            if word in ("quit", "exit"):
                break
            if word == "status":
                print("\n".join(report_lines(book)), flush=True)
            elif word:
                print(f"unknown command: {word!r} (replay: status, quit)", flush=True)
    except BrokenPipeError:
        pass
    done.set()
