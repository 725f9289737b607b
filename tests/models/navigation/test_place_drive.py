"""Driving from place to place: turn first, straight on, brake onto the point, stop for things."""

import math

import numpy as np
import pytest

from models.kinematics import DriveLimits
from models.navigation.place_drive import STOP_MARGIN_M, THERE_M, in_robot_frames, place_drive

LIMITS = DriveLimits(1.0, 0.3, 2.0, 2.0, 3.0)
R = 0.33
NOTHING = (np.zeros(0, dtype=np.int64), np.zeros(0), np.zeros(0))


def _drive(pose, point, things=NOTHING):
    v, w = place_drive(np.array([pose], float), np.array([point], float), LIMITS, R, *things)
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


def test_hits_in_robot_frames_are_ahead_and_to_the_left_of_their_owner():
    poses = np.array([[1.0, 2.0, math.pi / 2], [0.0, 0.0, 0.0]])
    points = np.array([[1.0, 3.0], [0.0, 2.0], [-1.0, 0.5]])  # robot 0: 2, robot 1: 1
    owner, ahead, side = in_robot_frames(points, np.array([0, 2, 3]), poses)
    assert owner.tolist() == [0, 0, 1]
    np.testing.assert_allclose(ahead, [1.0, 0.0, -1.0], atol=1e-12)
    np.testing.assert_allclose(side, [0.0, 1.0, 0.5], atol=1e-12)
