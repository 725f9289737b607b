import math

import numpy as np

from models.drivers.wander import WanderParams, wander

ANGLES = -math.pi + 2 * math.pi / 360 * np.arange(360)


def test_a_robot_in_open_space_drives_at_full_speed_straight():
    v, w = wander(np.full((1, 360), np.inf), ANGLES, 10.0, 1.0, 2.0, WanderParams())
    assert v[0] == 1.0 and w[0] == 0.0


def test_a_robot_facing_a_close_wall_turns_in_place_towards_the_open_side():
    ranges = np.full((1, 360), 8.0)
    ranges[0, np.abs(ANGLES) < 0.7] = 0.5  # wall ahead
    ranges[0, (ANGLES > 0.7) & (ANGLES < 2.0)] = 1.0  # left is tight
    v, w = wander(ranges, ANGLES, 10.0, 1.0, 2.0, WanderParams())
    assert v[0] == 0.0
    assert w[0] == -2.0  # right is open


def test_speed_falls_as_the_way_ahead_closes_in():
    far = np.full((1, 360), 10.0)
    mid = far.copy()
    mid[0, np.abs(ANGLES) < 0.6] = 1.5
    v_far, _ = wander(far, ANGLES, 10.0, 1.0, 2.0, WanderParams())
    v_mid, _ = wander(mid, ANGLES, 10.0, 1.0, 2.0, WanderParams())
    assert 0 < v_mid[0] < v_far[0]


def test_dropped_and_out_of_range_beams_count_as_free():
    ranges = np.full((2, 360), np.nan)
    ranges[1] = np.inf
    v, _ = wander(ranges, ANGLES, 10.0, 1.0, 2.0, WanderParams())
    assert list(v) == [1.0, 1.0]
