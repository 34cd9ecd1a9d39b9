"""Fixtures of the worker-part tests: a Qt-free host of the real parts, closed after the test."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from tests.link.harness import PartsHost


@pytest.fixture
def host() -> Iterator[PartsHost]:
    parts = PartsHost()
    try:
        yield parts
    finally:
        parts.close()
