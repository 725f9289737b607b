"""Driving from place to place: turn first, straight on, brake onto the point, stop for things."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from models.fleet.kinematics import DriveLimits
from models.navigation.place_drive import STOP_MARGIN_M, THERE_M, free_ahead, place_drive

LIMITS = DriveLimits(1.0, 0.3, 2.0, 2.0, 3.0)
R = 0.33
NOTHING = (np.zeros(0, dtype=np.int64), np.zeros(0), np.zeros(0))


def _drive(pose, point, things=NOTHING):
    """Commands for one robot; ``things``: (owner, ahead, side) hits in its frame (m)."""
    _, ahead, side = things
    yaw = pose[2]
    hits = np.column_stack(
        [
            pose[0] + ahead * math.cos(yaw) - side * math.sin(yaw),
            pose[1] + ahead * math.sin(yaw) + side * math.cos(yaw),
        ]
    )
    poses = np.array([pose], float)
    free = free_ahead(hits, np.array([0, len(hits)]), poses, R)
    v, w = place_drive(poses, np.array([point], float), LIMITS, free)
    return float(v[0]), float(w[0])


def test_a_robot_facing_away_turns_on_the_spot_towards_its_point():
    v, w = _drive((0.0, 0.0, 0.0), (0.0, 1.0))  # the point to its left
    assert v == 0.0 and w > 0
    v, w = _drive((0.0, 0.0, 0.0), (0.0, -1.0))
    assert v == 0.0 and w < 0


def test_a_robot_facing_its_point_drives_at_full_speed_and_brakes_onto_it():
    assert _drive((0.0, 0.0, 0.0), (3.0, 0.0))[0] == LIMITS.max_speed_mps
    near = _drive((0.0, 0.0, 0.0), (0.1, 0.0))[0]
    assert 0 < near <= math.sqrt(LIMITS.max_accel_mps2 * 0.1)
    assert _drive((0.0, 0.0, 0.0), (THERE_M / 2, 0.0)) == (0.0, 0.0)  # there: stands


def test_a_robot_stops_short_of_a_hit_in_its_strip_and_ignores_others():
    ahead = (np.array([0]), np.array([R + 0.01]), np.array([0.0]))  # within the margin
    assert _drive((0.0, 0.0, 0.0), (2.0, 0.0), ahead)[0] == 0.0
    beside = (np.array([0]), np.array([0.5]), np.array([R + 0.01]))  # passes beside it
    assert _drive((0.0, 0.0, 0.0), (2.0, 0.0), beside)[0] == LIMITS.max_speed_mps
    beyond = (np.array([0]), np.array([1.5]), np.array([0.0]))  # past the point
    assert _drive((0.0, 0.0, 0.0), (0.5, 0.0), beyond)[0] > 0
    closer = (np.array([0]), np.array([R + 0.3]), np.array([0.0]))
    slowed = _drive((0.0, 0.0, 0.0), (2.0, 0.0), closer)[0]
    assert 0 < slowed < LIMITS.max_speed_mps  # slows to stop 2 cm short of it


def test_a_hit_near_the_strip_edge_stops_the_robot_where_its_disc_would_touch_it():
    # a hit 0.317 m ahead and 0.317 m to the left: the disc touches it after 0.225 m
    edge = (np.array([0]), np.array([0.317]), np.array([0.317]))
    touch = 0.317 - math.sqrt(R**2 - 0.317**2)
    assert _drive((0.0, 0.0, 0.0), (touch - 0.05, 0.0), edge) == _drive(
        (0.0, 0.0, 0.0), (touch - 0.05, 0.0)
    )  # the point short of it: as if the hit were not there
    # a point beyond it: brakes to stop STOP_MARGIN_M short of touching, not a radius short
    stop_at = (touch - STOP_MARGIN_M, 0.0)
    assert _drive((0.0, 0.0, 0.0), (1.0, 0.0), edge)[0] == pytest.approx(
        _drive((0.0, 0.0, 0.0), stop_at)[0]
    )


def _free_ahead_numpy(points, start, poses, radius_m):
    """The free distance ahead in numpy terms: every hit in its owner's frame."""
    owner = np.repeat(np.arange(len(start) - 1), np.diff(start))
    pose = poses[owner]
    dx, dy = points[:, 0] - pose[:, 0], points[:, 1] - pose[:, 1]
    cos_yaw, sin_yaw = np.cos(pose[:, 2]), np.sin(pose[:, 2])
    ahead, side = cos_yaw * dx + sin_yaw * dy, cos_yaw * dy - sin_yaw * dx
    strip = (ahead > 0) & (np.abs(side) < radius_m)
    free = np.full(len(poses), np.inf)
    touch = ahead[strip] - np.sqrt(radius_m * radius_m - side[strip] * side[strip])
    np.minimum.at(free, owner[strip], touch)
    return free


@settings(max_examples=60, deadline=None)
@given(robots=st.integers(1, 6), seed=st.integers(0, 2**31))
def test_the_free_distance_ahead_matches_its_numpy_formulation_bit_for_bit(robots, seed):
    rng = np.random.default_rng(seed)
    poses = np.column_stack([rng.uniform(0, 5, (robots, 2)), rng.uniform(-4, 4, robots)])
    counts = rng.integers(0, 30, robots)
    start = np.concatenate([[0], np.cumsum(counts)])
    points = rng.uniform(-1, 6, (int(start[-1]), 2))
    got = free_ahead(points, start, poses, R)
    np.testing.assert_array_equal(got, _free_ahead_numpy(points, start, poses, R))


def test_a_robot_is_free_to_go_up_to_where_its_disc_touches_the_nearest_hit_ahead():
    poses = np.array([[1.0, 2.0, math.pi / 2], [0.0, 0.0, 0.0]])
    # robot 0 faces +y: a hit 1 m ahead, one behind; robot 1 faces +x: one beside its strip
    points = np.array([[1.0, 3.0], [1.0, 1.0], [1.0, R + 0.01]])
    free = free_ahead(points, np.array([0, 2, 3]), poses, R)
    assert free[0] == pytest.approx(1.0 - R)
    assert free[1] == math.inf
