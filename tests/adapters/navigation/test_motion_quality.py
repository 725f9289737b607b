"""Jerk of the robots' motion and the controller's decision time."""

from __future__ import annotations

import numpy as np
import pytest

from adapters.navigation.motion_quality import MOTION_SUMMARY, MotionQuality

DRIVING = np.array([True, True])


def test_a_steady_speed_or_a_steady_acceleration_has_no_jerk():
    quality = MotionQuality(2, control_hz=10.0)
    for k in range(5):
        quality.sample(np.array([0.5, 0.1 * k]), np.array([0.2, 0.0]), DRIVING)
    summary = quality.summary()
    assert summary["mean_abs_jerk_mps3"] == 0.0
    assert summary["mean_abs_yaw_jerk_radps3"] == 0.0
    assert quality.jerk_count == 2 * 3  # the first two samples of each robot give none


def test_dithering_between_braking_and_driving_is_jerky():
    quality = MotionQuality(1, control_hz=10.0)
    for v in (0.5, 0.4, 0.5, 0.4):
        quality.sample(np.array([v]), np.array([0.0]), DRIVING[:1])
    # second differences +-0.2 m/s over (0.1 s)^2
    assert quality.summary()["mean_abs_jerk_mps3"] == pytest.approx(20.0)


def test_a_robot_not_driving_is_not_counted_and_starts_afresh():
    quality = MotionQuality(1, control_hz=10.0)
    quality.sample(np.array([0.0]), np.array([0.0]), np.array([True]))
    quality.sample(np.array([0.5]), np.array([0.0]), np.array([False]))  # goal reached
    quality.sample(np.array([0.5]), np.array([0.0]), np.array([True]))
    quality.sample(np.array([0.5]), np.array([0.0]), np.array([True]))
    assert quality.jerk_count == 0  # only one fresh sample before the last
    quality.sample(np.array([0.5]), np.array([0.0]), np.array([True]))
    assert quality.jerk_count == 1 and quality.summary()["mean_abs_jerk_mps3"] == 0.0


def test_decision_time_is_given_per_tick_and_per_robot():
    quality = MotionQuality(50, control_hz=10.0)
    assert quality.summary()["controller_ms_per_tick"] is None
    quality.decided(0.002)
    quality.decided(0.004)
    summary = quality.summary()
    assert summary["controller_ms_per_tick"] == pytest.approx(3.0)
    assert summary["controller_us_per_robot"] == pytest.approx(60.0)


def test_every_key_it_writes_is_declared_and_wall_clock_ones_are_volatile():
    assert set(MotionQuality(1, 10.0).summary()) == set(MOTION_SUMMARY)
    assert MOTION_SUMMARY["controller_ms_per_tick"].volatile
    assert not MOTION_SUMMARY["mean_abs_jerk_mps3"].volatile
