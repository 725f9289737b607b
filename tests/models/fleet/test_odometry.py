import numpy as np
import pytest

from models.fleet.odometry import advance, drift_increments


def test_zero_drift_leaves_the_increments_unchanged():
    ds = np.array([0.05, -0.02, 0.0])
    dth = np.array([0.01, 0.0, 0.3])
    out = drift_increments(ds, dth, 0.0, np.ones((3, 2)))
    np.testing.assert_array_equal(out[0], ds)
    np.testing.assert_array_equal(out[1], dth)


@pytest.mark.parametrize("steps", [10, 100, 1000])
def test_the_error_after_one_metre_has_the_drift_as_deviation_whatever_the_step(steps):
    rng = np.random.default_rng(1)
    robots = 4000
    drift = 0.05
    x = np.zeros(robots)
    y = np.zeros(robots)
    yaw = np.zeros(robots)
    distance = np.zeros(robots)
    heading = np.zeros(robots)
    for _ in range(steps):
        ds, dth = drift_increments(
            np.full(robots, 1.0 / steps), np.zeros(robots), drift, rng.standard_normal((robots, 2))
        )
        distance += ds
        heading += dth
        x, y, yaw = advance(x, y, yaw, ds, dth)
    assert np.std(distance - 1.0) == pytest.approx(drift, rel=0.06)
    assert np.std(heading) == pytest.approx(drift, rel=0.06)
    assert abs(np.mean(distance - 1.0)) < 0.005


def test_advance_integrates_an_arc_exactly():
    x, y, yaw = advance(
        np.array([0.0]),
        np.array([0.0]),
        np.array([0.0]),
        np.array([np.pi / 2]),
        np.array([np.pi / 2]),
    )
    assert (x[0], y[0], yaw[0]) == pytest.approx((1.0, 1.0, np.pi / 2))
