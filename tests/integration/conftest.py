"""Fixtures of the end-to-end tests: real RobotClients on the real simulator over TCP."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest

from app.client import ConnectionSettings, RobotClient
from tests.integration.support import MakeClient


@pytest.fixture
def make_client() -> Iterator[MakeClient]:
    """Connected RobotClients for a simulator (or any port); all closed after the test."""
    made: list[RobotClient] = []

    def make(sim: Any = None, *, port: int | None = None, connect: bool = True) -> RobotClient:
        target = sim.port if port is None else port
        client = RobotClient(ConnectionSettings(host="127.0.0.1", port=target))
        made.append(client)
        if connect:
            client.connect()
        return client

    try:
        yield make
    finally:
        for client in made:
            client.close()
