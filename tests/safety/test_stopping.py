"""Measured stopping's core (app/safety/stopping.py): still, the time, the distance, the timeout."""

from __future__ import annotations

import io
import json
import zipfile

import pytest

from app.models import Pose
from app.safety.bundle import build_support_bundle
from app.safety.stopping import StopKind, StopLog, StopWatch, summary_lines


def _pose(x: float, c: float = 0.0, e1: float = 0.0) -> Pose:
    return Pose(x, 0.0, 450.0, 180.0, 0.0, c, ext=(e1, 0.0, 0.0, 0.0, 0.0))


def test_a_stop_is_timed_to_the_first_poll_of_the_still_pair() -> None:
    watch = StopWatch()
    watch.click(StopKind.STOP, 10.0, _pose(100.0))
    assert watch.sample(9.99, _pose(99.0)) is None  # a poll from before the click: ignored
    assert watch.sample(10.02, _pose(102.0)) is None
    assert watch.sample(10.04, _pose(104.0)) is None
    assert watch.sample(10.06, _pose(105.0)) is None  # comes to rest here
    assert watch.sample(10.08, _pose(105.0 + 0.005)) is None  # alike, but too close to tell
    result = watch.sample(10.10, _pose(105.0 + 0.005))  # within STILL_MM, STOP_STILL_SPAN on: still
    assert result is not None and result.still
    assert result.seconds == pytest.approx(0.06)
    assert result.poll_gap == pytest.approx(0.02)
    assert result.distance_mm == pytest.approx(5.005)
    assert result.text == "60 ms, 5.0 mm" and result.polls == 5
    assert not watch.measuring


def test_the_distance_starts_where_the_arm_was_at_the_click() -> None:
    watch = StopWatch()
    # polled at x = 100 at t = 9.99; the click at 10.00; the next poll (10.01) reads x = 102:
    # the arm was at 101 at the click, not at the 100 of the last poll
    watch.click(StopKind.STOP, 10.0, _pose(100.0), seen_at=9.99)
    assert watch.sample(10.01, _pose(102.0)) is None
    result = watch.sample(10.05, _pose(102.0))
    assert result is not None and result.distance_mm == pytest.approx(1.0)
    assert result.seconds == pytest.approx(0.01)


def test_an_arm_not_moving_measures_zero() -> None:
    watch = StopWatch()
    watch.click(StopKind.JOG_RELEASE, 5.0, _pose(1.0))
    result = watch.sample(5.04, _pose(1.0))
    assert result is not None and result.seconds == 0.0 and result.distance_mm == 0.0
    assert result.kind is StopKind.JOG_RELEASE


def test_an_external_axis_or_orientation_still_turning_is_not_still() -> None:
    watch = StopWatch()
    watch.click(StopKind.JOG_RELEASE, 0.0, _pose(1.0))
    assert watch.sample(0.04, _pose(1.0, e1=0.5)) is None  # J7 moves, the TCP does not
    assert watch.sample(0.08, _pose(1.0, e1=0.5, c=0.3)) is None  # turning
    result = watch.sample(0.12, _pose(1.0, e1=0.5, c=0.3))
    assert result is not None and result.seconds == pytest.approx(0.08)
    assert result.rotation_deg == pytest.approx(0.3)


def test_orientation_across_the_wrap_is_still() -> None:
    watch = StopWatch()
    watch.click(StopKind.STOP, 0.0, None)  # no pose known at the click: the first poll starts
    assert watch.sample(0.04, Pose(0, 0, 0, 180.0, 0, 0)) is None
    result = watch.sample(0.08, Pose(0, 0, 0, -180.0, 0, 0))  # the same orientation
    assert result is not None and result.still and result.seconds == pytest.approx(0.04)


def test_polls_in_a_bunch_reading_one_update_twice_are_not_still() -> None:
    watch = StopWatch()
    watch.click(StopKind.STOP, 0.0, _pose(0.0))
    assert watch.sample(0.050, _pose(5.0)) is None
    assert watch.sample(0.052, _pose(5.0)) is None  # a late poller catching up: the same update
    assert watch.sample(0.060, _pose(6.0)) is None  # the arm still moves
    assert watch.sample(0.080, _pose(8.0)) is None
    assert watch.sample(0.100, _pose(8.0)) is None
    result = watch.sample(0.120, _pose(8.0))
    assert (
        result is not None
        and result.seconds == pytest.approx(0.08)
        and result.distance_mm == pytest.approx(8.0)
    )


def test_not_seen_still_within_the_timeout() -> None:
    watch = StopWatch(timeout=1.0)
    watch.click(StopKind.STOP, 0.0, _pose(0.0))
    for i in range(1, 50):
        assert watch.sample(i * 0.02, _pose(i * 1.0)) is None
    result = watch.sample(1.0, _pose(51.0))
    assert result is not None and not result.still and result.seconds == 1.0
    assert result.text == "not seen still within 1 s, 51.0 mm"


def test_no_poll_at_all_expires() -> None:
    watch = StopWatch(timeout=2.0)
    watch.click(StopKind.STOP, 0.0, _pose(0.0))
    assert watch.expire(1.9) is None
    result = watch.expire(2.0)
    assert result is not None and not result.still and result.polls == 0


def test_the_session_summary_and_the_bundle() -> None:
    log = StopLog()
    assert summary_lines([]) == ["measured stopping: no Stop or jog release in this session"]
    for at, x in ((0.0, 4.0), (10.0, 2.0)):
        watch = StopWatch()
        watch.click(StopKind.STOP, at, _pose(0.0))
        watch.sample(at + 0.1, _pose(x))
        result = watch.sample(at + 0.14, _pose(x))
        assert result is not None
        log.add(result)
    lines = log.summary_lines()
    assert lines[0] == "measured stopping: 2 in this session (click to the arm seen still)"
    assert lines[1] == "stop: 2; time median 100 ms, largest 100 ms; distance median 3.0 mm, largest 4.0 mm"
    data, manifest = build_support_bundle(stopping=lines)
    with zipfile.ZipFile(io.BytesIO(data)) as zf:
        text = zf.read("stopping.txt").decode("utf-8")
        assert json.loads(zf.read("manifest.json"))["files"].count("stopping.txt") == 1
    assert text.splitlines()[:2] == lines[:2]
    _, manifest = build_support_bundle(stopping=[])
    assert "measured stopping: nothing measured in this session" in manifest.left_out
    data, _ = build_support_bundle()  # teachpad-cli's: no session, no file
    assert "stopping.txt" not in zipfile.ZipFile(io.BytesIO(data)).namelist()
