"""The link's typed errors carry a reason (code + arguments) beside their English text."""

from __future__ import annotations

import socket
from typing import Any

import pytest

from app.errors import LinkError, WriteBlocked
from app.link.types import Operation, WorkerError


def _closed_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def test_a_refused_connection_has_its_code_and_endpoint(make_client: Any) -> None:
    port = _closed_port()
    client = make_client(port=port, connect=False, timeout=0.5)
    with pytest.raises(LinkError) as caught:
        client.connect()
    reason = caught.value.as_reason()
    assert reason.code == "connection_refused"
    assert reason.args["endpoint"] == f"127.0.0.1:{port}" and reason.args["reconnect"] is False
    assert "connection refused" in str(caught.value)  # the English for the CLI stays
    error = WorkerError.from_exception(Operation.CONNECT, caught.value)
    assert error.reason == reason and error.message == str(caught.value)


def test_a_closed_link_says_so(sim: Any, make_client: Any) -> None:
    client = make_client(sim)
    client.read_status()
    assert sim.drop_connections() >= 1
    with pytest.raises(LinkError) as caught:
        client.read_status()
    assert caught.value.as_reason().code in ("link_closed", "link_lost")
    assert caught.value.as_reason().args["endpoint"] == f"127.0.0.1:{sim.port}"


def test_monitor_only_refusal_has_its_code(sim: Any, make_client: Any) -> None:
    client = make_client(sim, monitor_only=True)
    with pytest.raises(WriteBlocked) as caught:
        client.stop()
    assert caught.value.as_reason().code == "monitor_only"
    assert sim.writes_to(441) == []
