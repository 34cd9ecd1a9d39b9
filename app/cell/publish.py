"""The GUI's cell view publishing its cell through the gateway's edge node (issue 23; no Qt).

The same :class:`~app.gateway.edge_node.EdgeNode` as ``teachpad-gateway`` (NBIRTH, a DBIRTH per
answering controller, DDATA by exception, DDEATH, NDEATH as the will), made with ``poll=False``: the
cell view's pollers already read every controller, and they feed the node from their own threads
(:meth:`CellPublisher.answered`, :meth:`CellPublisher.silent`), so each controller still has one
monitor-only client. Nothing here runs network I/O on the caller's thread: :meth:`CellPublisher.start`
only hands the connection to paho's network thread, and :meth:`CellPublisher.stop` (NDEATH, then a
clean disconnect) runs in a thread of its own that the caller may join later.

:class:`PublishSettings` is what the GUI remembers (broker URL, group, node); the broker's password is
never kept there (plain text): it comes from ``$TEACHPAD_MQTT_PASSWORD``, as for the gateway.
"""

from __future__ import annotations

import os
import socket
import threading
from dataclasses import dataclass
from urllib.parse import urlsplit

from app.cell.cell_file import Cell
from app.gateway.cli import PASSWORD_ENV
from app.gateway.edge_node import BrokerSettings, EdgeNode
from app.gateway.metrics import Reading
from app.gateway.poller import GatewayTiming

__all__ = [
    "DEFAULT_BROKER",
    "DEFAULT_GROUP",
    "CellPublisher",
    "PublishSettings",
    "parse_broker",
    "valid_name",
]

DEFAULT_BROKER = "mqtt://127.0.0.1:1883"
DEFAULT_GROUP = "teachpad"
_BAD_NAME_CHARS = frozenset("/+#")


def valid_name(text: str) -> bool:
    """A Sparkplug group or node id: not empty, no ``/``, ``+`` or ``#``."""
    return bool(text) and not _BAD_NAME_CHARS & set(text)


def parse_broker(url: str) -> BrokerSettings | None:
    """``mqtt://[USER@]HOST[:PORT]`` (1883) or ``mqtts://...`` (8883, TLS); None when it is not one
    of those, or carries a password (settings are plain text: ``$TEACHPAD_MQTT_PASSWORD`` says it)."""
    parts = urlsplit(url.strip() if "://" in url else f"mqtt://{url.strip()}")
    if parts.scheme not in ("mqtt", "mqtts") or not parts.hostname or parts.password is not None:
        return None
    if parts.path not in ("", "/") or parts.query or parts.fragment:
        return None
    tls = parts.scheme == "mqtts"
    try:
        port = parts.port or (8883 if tls else 1883)
    except ValueError:
        return None
    return BrokerSettings(
        host=parts.hostname,
        port=port,
        tls=tls,
        username=parts.username,
        password=os.environ.get(PASSWORD_ENV) if parts.username else None,
    )


@dataclass(frozen=True)
class PublishSettings:
    """Where the GUI publishes its cell: the broker's URL, the Sparkplug group and node ids."""

    broker: str = DEFAULT_BROKER
    group: str = DEFAULT_GROUP
    node: str = ""  # empty: this host's name (as the gateway's default)

    @property
    def node_id(self) -> str:
        return self.node or socket.gethostname()

    def valid(self) -> bool:
        return parse_broker(self.broker) is not None and valid_name(self.group) and valid_name(self.node_id)


class CellPublisher:
    """One cell's edge node, fed by the cell view's pollers (a ``DeviceListener``)."""

    def __init__(self, cell: Cell, settings: PublishSettings, gateway: GatewayTiming | None = None) -> None:
        broker = parse_broker(settings.broker)
        if broker is None:
            raise ValueError(f"not an MQTT broker URL: {settings.broker!r}")
        self.settings = settings
        self.broker = broker
        self.edge = EdgeNode(
            cell, broker, group=settings.group, node=settings.node_id, gateway=gateway, poll=False
        )
        self._stopper: threading.Thread | None = None

    @property
    def online(self) -> bool:
        """Connected to the broker and born (NBIRTH sent)."""
        return self.edge.online

    def start(self) -> None:
        """Connect in paho's network thread (a broker that is not up yet is tried again there)."""
        self.edge.start()

    def stop(self) -> threading.Thread:
        """NDEATH and a clean disconnect, in a thread of its own (returned: join it to wait)."""
        if self._stopper is None:
            self._stopper = threading.Thread(target=self.edge.stop, name="cell-publish-stop", daemon=True)
            self._stopper.start()
        return self._stopper

    # -- the pollers (their threads) ------------------------------------------------------
    def answered(self, device: str, reading: Reading) -> None:
        if self._stopper is None:
            self.edge.answered(device, reading)

    def silent(self, device: str, reason: str) -> None:
        if self._stopper is None:
            self.edge.silent(device, reason)
