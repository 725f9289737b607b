import math

import numpy as np

from models.mapping.drift import DriftModel, drifting_odometry

SQUARE = np.array(
    [(x, 0.0, 0.0) for x in np.arange(0.0, 10.0, 0.5)]
    + [(10.0, y, math.pi / 2) for y in np.arange(0.0, 10.0, 0.5)]
)
NO_NOISE = DriftModel(
    scale=1.0, per_m=0.0, floor_m=0.0, per_rad=0.0, rad_per_m=0.0, bias_rad_per_m=0.0
)


def test_without_noise_odometry_only_overshoots_by_its_scale():
    drawn = drifting_odometry(
        SQUARE, seed=1, model=DriftModel(**{**NO_NOISE.__dict__, "scale": 1.1})
    )
    assert np.allclose(drawn[19], (9.5 * 1.1, 0.0, 0.0))
    assert np.allclose(drifting_odometry(SQUARE, seed=1, model=NO_NOISE), SQUARE)


def test_a_heading_bias_bends_a_straight_line_to_the_left():
    bent = drifting_odometry(
        SQUARE[:20], seed=1, model=DriftModel(**{**NO_NOISE.__dict__, "bias_rad_per_m": 0.01})
    )
    assert bent[-1, 2] > 0.09 and bent[-1, 1] > 0.3


def test_the_same_seed_draws_the_same_odometry_and_another_seed_another():
    first, again, other = (drifting_odometry(SQUARE, s) for s in (3, 3, 4))
    assert np.array_equal(first, again)
    assert not np.allclose(first, other)
    assert np.array_equal(first[0], SQUARE[0])  # odometry starts where the reference does
