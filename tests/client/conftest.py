"""Clients connected to the simulator; every client is closed after the test."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any

import pytest

from app.client import ConnectionSettings, RobotClient

MakeClient = Callable[..., RobotClient]


@pytest.fixture
def make_client() -> Iterator[MakeClient]:
    made: list[RobotClient] = []

    def make(sim: Any, *, connect: bool = True, **kwargs: Any) -> RobotClient:
        kwargs.setdefault("host", "127.0.0.1")
        kwargs.setdefault("port", sim.port)
        kwargs.setdefault("framer", sim.config.framer)
        kwargs.setdefault("word_order", sim.config.word_order)
        client = RobotClient(ConnectionSettings(**kwargs))
        made.append(client)
        if connect:
            client.connect()
        return client

    try:
        yield make
    finally:
        for client in made:
            client.close()
