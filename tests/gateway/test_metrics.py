"""Report by exception: the deadband rule of one metric (pure)."""

from __future__ import annotations

import math

from app.gateway.metrics import ALL_METRICS, DEVICE_METRICS, METRIC_INDEX, changed, device_alias

POSE_X = DEVICE_METRICS[METRIC_INDEX["Pose/X"]]  # deadband 0.01 mm
MODE = DEVICE_METRICS[METRIC_INDEX["Status/Work mode"]]
CLOCK = DEVICE_METRICS[METRIC_INDEX["Controller/Clock"]]
ALARM = DEVICE_METRICS[METRIC_INDEX["Alarms/Servo"]]


def test_a_float_is_sent_past_its_deadband_only() -> None:
    assert not changed(POSE_X, 100.0, 100.009, {})
    assert changed(POSE_X, 100.0, 100.011, {})
    assert changed(POSE_X, 100.0, 100.001, {"Pose/X": 0.0})  # a deadband of 0: every change
    assert not changed(POSE_X, 100.0, 100.5, {"Pose/X": 1.0})


def test_discrete_values_on_any_change() -> None:
    assert changed(MODE, 0, 1, {}) and not changed(MODE, 1, 1, {})
    assert changed(ALARM, False, True, {}) and not changed(ALARM, True, True, {})
    assert changed(CLOCK, "2026-11-29T10:00:00", "2026-11-29T10:00:01", {})


def test_null_and_nan() -> None:
    assert (
        changed(CLOCK, None, "x", {}) and changed(CLOCK, "x", None, {}) and not changed(CLOCK, None, None, {})
    )
    assert changed(POSE_X, math.nan, 1.0, {}) and not changed(POSE_X, math.nan, math.nan, {})


def test_aliases_are_unique_over_the_node() -> None:
    aliases = {device_alias(d, i) for d in range(256) for i in range(len(ALL_METRICS))}
    assert len(aliases) == 256 * len(ALL_METRICS)
    assert 1 not in aliases  # Node Control/Rebirth's
