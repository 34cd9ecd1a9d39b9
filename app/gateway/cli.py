"""``teachpad-gateway CELL_FILE --broker mqtt://HOST:PORT [--group G] [--node N]``: headless, no widgets.

Polls every controller of the cell and publishes it as a Sparkplug B edge node
(:mod:`app.gateway.edge_node`) until SIGINT or SIGTERM, then publishes NDEATH and exits 0. Writes
from the plant (DCMD) only where the cell file enables them (``plant_writes``,
:mod:`app.gateway.plant`), none with ``--monitor-only``. SIGHUP reads the cell file again (a
controller that left gets its DDEATH, one that joined its DBIRTH). Exit 2 (nothing started) for bad
arguments, a cell file that cannot be used, or a safety envelope that cannot be read when plant
writes need it, with one line saying why.
"""

from __future__ import annotations

import argparse
import logging
import os
import signal
import socket
import sys
import threading
import traceback
from collections.abc import Sequence
from pathlib import Path
from urllib.parse import urlsplit

from app import timing
from app.cell.cell_file import Cell, load_cell
from app.errors import TeachPadError
from app.gateway.bdseq import default_bdseq_file
from app.gateway.edge_node import BrokerSettings, EdgeNode
from app.gateway.poller import GatewayTiming
from app.stop_signals import SignalNote
from app.version import VersionAction

PROG = "teachpad-gateway"
PASSWORD_ENV = "TEACHPAD_MQTT_PASSWORD"
EXIT_USAGE = 2
RELOAD_CHECK = 0.2  # s: how soon a SIGHUP (reload the cell file) is acted on
_BAD_NAME_CHARS = set("/+#")


class UsageError(Exception):
    """A bad argument: one line, exit 2."""


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog=PROG,
        description="Publish every controller of a TeachPad cell file to an MQTT broker as a Sparkplug B "
        "edge node. Writes from the plant (DCMD) are off unless the cell file enables them per robot "
        "(plant_writes).",
    )
    parser.add_argument("--version", action=VersionAction)
    parser.add_argument("cell", type=Path, metavar="CELL_FILE", help="the cell file (teachpad-cell JSON)")
    parser.add_argument(
        "--broker", required=True, help="mqtt://HOST[:PORT] (1883) or mqtts://HOST[:PORT] (8883)"
    )
    parser.add_argument("--group", default="teachpad", help="Sparkplug group id (default %(default)s)")
    parser.add_argument("--node", default=None, help="Sparkplug edge node id (default: this host's name)")
    parser.add_argument(
        "--primary-host",
        default=None,
        metavar="HOST_ID",
        help="publish only while this Sparkplug host application's STATE says online",
    )
    parser.add_argument("--username", default=None, help=f"broker user name (its password: ${PASSWORD_ENV})")
    parser.add_argument(
        "--password-file", type=Path, default=None, help="read the broker password from this file"
    )
    parser.add_argument("--tls", action="store_true", help="TLS to the broker (implied by mqtts://)")
    parser.add_argument("--cafile", default=None, help="CA certificates for TLS (default: the system's)")
    parser.add_argument("--certfile", default=None, help="client certificate for TLS")
    parser.add_argument("--keyfile", default=None, help="client certificate's private key")
    parser.add_argument(
        "--keepalive",
        type=int,
        default=timing.GATEWAY_KEEPALIVE,
        help="MQTT keepalive, s (default %(default)s): a crashed gateway's NDEATH comes within 1.5 x this",
    )
    parser.add_argument(
        "--poll-hz", type=float, default=timing.GATEWAY_POLL_HZ, help="polls per controller per s"
    )
    parser.add_argument(
        "--bdseq-file",
        type=Path,
        default=None,
        metavar="FILE",
        help="where the Sparkplug bdSeq is kept across restarts "
        "(default: TeachPad's data folder, gateway/GROUP.NODE.bdseq.json)",
    )
    parser.add_argument(
        "--monitor-only",
        action="store_true",
        help="write nothing to any controller, whatever the cell file's plant_writes enable",
    )
    parser.add_argument("-v", "--verbose", action="store_true", help="log every connection change")
    return parser


def broker_settings(args: argparse.Namespace) -> BrokerSettings:
    url = urlsplit(args.broker if "://" in args.broker else f"mqtt://{args.broker}")
    if url.scheme not in ("mqtt", "mqtts") or not url.hostname:
        raise UsageError(f"--broker must be mqtt://HOST[:PORT] or mqtts://HOST[:PORT], got {args.broker!r}")
    tls = args.tls or url.scheme == "mqtts" or args.cafile is not None
    try:
        port = url.port or (8883 if tls else 1883)
    except ValueError:
        raise UsageError(f"--broker: the port of {args.broker!r} is not a number 1..65535") from None
    password = os.environ.get(PASSWORD_ENV)
    if args.password_file is not None:
        try:
            password = args.password_file.read_text(encoding="utf-8").strip()
        except OSError as exc:
            raise UsageError(f"--password-file {args.password_file}: {exc.strerror}") from None
    return BrokerSettings(
        host=url.hostname,
        port=port,
        tls=tls,
        cafile=args.cafile,
        certfile=args.certfile,
        keyfile=args.keyfile,
        username=args.username or url.username,
        password=password if password is not None else url.password,
    )


def _name(value: str, what: str) -> str:
    if not value or _BAD_NAME_CHARS & set(value):
        raise UsageError(f"{what} must be non-empty and without '/', '+' or '#', got {value!r}")
    return value


def _check(args: argparse.Namespace) -> None:
    if not 1 <= args.keepalive <= 65535:
        raise UsageError(f"--keepalive must be 1..65535 s, got {args.keepalive}")
    if not 0.1 <= args.poll_hz <= 200:
        raise UsageError(f"--poll-hz must be 0.1..200, got {args.poll_hz:g}")


def _reload(edge: EdgeNode, path: Path) -> None:
    """SIGHUP: the cell file again; a file that cannot be used is said and the running cell kept."""
    try:
        cell = load_cell(path)
        edge.set_cell(cell)
    except TeachPadError as exc:  # the cell file, or the envelope its plant writes need
        print(f"{PROG}: cell file not reloaded, the running cell stays: {exc}", file=sys.stderr, flush=True)


def _edge_node(
    args: argparse.Namespace, cell: Cell, broker: BrokerSettings, group: str, node: str, primary: str | None
) -> EdgeNode:
    """The edge node (the safety envelope read when a robot has plant writes: a bad one raises)."""
    return EdgeNode(
        cell,
        broker,
        group=group,
        node=node,
        gateway=GatewayTiming(poll_hz=args.poll_hz, keepalive=args.keepalive),
        primary_host=primary,
        bdseq_file=args.bdseq_file or default_bdseq_file(group, node),
        writes=not args.monitor_only,
    )


def main(argv: Sequence[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    logging.basicConfig(
        level=logging.INFO if args.verbose else logging.WARNING,
        format=f"{PROG}: %(levelname)s %(message)s",
    )
    if not args.verbose:  # paho's own lines ("Client is not connected ...") only with -v
        logging.getLogger("app.gateway.mqtt").setLevel(logging.CRITICAL)
    try:
        _check(args)
        broker = broker_settings(args)
        group = _name(args.group, "--group")
        node = _name(args.node if args.node is not None else socket.gethostname(), "--node")
        primary = None if args.primary_host is None else _name(args.primary_host, "--primary-host")
        cell = load_cell(args.cell)
        edge = _edge_node(args, cell, broker, group, node, primary)
    except (UsageError, TeachPadError) as exc:  # TeachPadError: the cell file, or the envelope
        print(f"{PROG}: {exc}", file=sys.stderr)
        return EXIT_USAGE
    stop, reload = _signal_notes()
    edge.start()
    print(
        f"{PROG}: {len(cell.controllers)} controller(s) of cell {cell.name!r} -> {broker.host}:{broker.port} "
        f"as spBv1.0/{group}/.../{node}",
        file=sys.stderr,
        flush=True,
    )
    while not stop.wait(RELOAD_CHECK):
        if reload.take():
            _reload(edge, args.cell)
    _stop(edge)
    return 0


def _signal_notes() -> tuple[SignalNote, SignalNote]:
    """Ctrl-C and SIGTERM (stop), SIGHUP (read the cell file again; none on Windows: read at start
    only), noted by handlers that take no lock (app/stop_signals.py: ``done.set()`` in a handler
    could wait forever for the lock of the Event the main loop was waiting on)."""
    hangup = getattr(signal, "SIGHUP", None)
    stop = SignalNote((signal.SIGINT, signal.SIGTERM)).install()
    return stop, SignalNote((hangup,) if hangup is not None else ()).install()


def _stop(edge: EdgeNode) -> None:
    """NDEATH and a clean disconnect, within :data:`app.timing.GATEWAY_STOP_BOUND`: a SIGTERM ends
    the process whatever part of the stop does not end (its threads are daemons; the broker then
    sends the will, the NDEATH of this session). What did not end is said, with every thread's
    stack, so that a stop that hangs is seen and can be found (once, in a CI run of stop 28)."""
    stopper = threading.Thread(target=edge.stop, name="gateway-stop", daemon=True)
    stopper.start()
    stopper.join(timing.GATEWAY_STOP_BOUND)
    if stopper.is_alive():
        print(
            f"{PROG}: warning: the stop did not end within {timing.GATEWAY_STOP_BOUND:g} s: exiting "
            "(the broker sends the will); the threads were:",
            file=sys.stderr,
            flush=True,
        )
        names = {t.ident: t.name for t in threading.enumerate()}
        for ident, frame in sys._current_frames().items():
            print(f"--- thread {names.get(ident, ident)}", file=sys.stderr)
            print("".join(traceback.format_stack(frame)), end="", file=sys.stderr, flush=True)
