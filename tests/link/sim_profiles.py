"""Simulator timing profiles for the completion tests: every (timing, GV291) pair, shrunk."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest

from app import timing
from app.sim.config import GV291_MODES, TIMING_PROFILES

# every pair: ("classic" | "fast" | "slow", "ignored" | "writable" | "read-only")
SIM_PROFILES = [pytest.param((t, g), id=f"{t}-{g}") for t in TIMING_PROFILES for g in GV291_MODES]


@pytest.fixture
def quick_profiles(monkeypatch: pytest.MonkeyPatch) -> None:
    """The slow profile and the observe window shrunk so hundreds of points take seconds."""
    monkeypatch.setattr(timing, "SIM_SLOW_PICKUP", (0.002, 0.008))
    monkeypatch.setattr(timing, "SIM_SLOW_ZERO", (0.001, 0.004))
    monkeypatch.setattr(timing, "UNCONFIRMED_AFTER", 0.02)
    monkeypatch.setattr(timing, "SENTINEL_PROBE_SETTLE", 0.01)


@pytest.fixture(params=SIM_PROFILES)
def profile_sim(request: pytest.FixtureRequest, sim_factory: Any, quick_profiles: None) -> Iterator[Any]:
    """A simulator in one timing profile (parametrized over all of them)."""
    timing_name, gv291 = request.param
    yield sim_factory(timing=timing_name, gv291=gv291)
