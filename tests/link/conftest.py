"""Fixtures of the link's tests: a Qt-free host of the real worker parts, closed after the test; the
simulator's timing profiles for the completion tests (tests/link/sim_profiles.py)."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from tests.link.harness import PartsHost
from tests.link.sim_profiles import profile_sim, quick_profiles  # noqa: F401 - fixtures


@pytest.fixture
def host() -> Iterator[PartsHost]:
    parts = PartsHost()
    try:
        yield parts
    finally:
        parts.close()
