import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from models.agents.features import sector_minima, to_body


def test_a_point_ahead_of_a_robot_facing_north_is_straight_ahead():
    ahead, left = to_body(np.array([0.0]), np.array([2.0]), np.array([np.pi / 2]))
    assert ahead[0] == pytest.approx(2.0)
    assert left[0] == pytest.approx(0.0, abs=1e-12)


def test_a_point_east_of_a_robot_facing_north_is_on_its_right():
    ahead, left = to_body(np.array([1.0]), np.array([0.0]), np.array([np.pi / 2]))
    assert left[0] == pytest.approx(-1.0)
    assert ahead[0] == pytest.approx(0.0, abs=1e-12)


@given(st.floats(-50, 50), st.floats(-50, 50), st.floats(-np.pi, np.pi, allow_subnormal=False))
def test_turning_into_the_body_frame_keeps_distances(dx, dy, yaw):
    ahead, left = to_body(np.array([[dx, -dy]]), np.array([[dy, dx]]), np.array([yaw]))
    assert np.hypot(ahead, left) == pytest.approx(np.hypot(dx, dy) * np.ones((1, 2)), abs=1e-9)


def test_sector_minima_take_the_nearest_return_of_each_sector():
    ranges = np.array([[5.0, 1.0, 4.0, 4.0, 0.5, 9.0]])
    assert sector_minima(ranges, 3).tolist() == [[1.0, 4.0, 0.5]]
    assert sector_minima(ranges, 1).tolist() == [[0.5]]


@given(
    arrays(np.float64, st.tuples(st.integers(1, 3), st.integers(1, 40)), elements=st.floats(0, 30)),
    st.integers(1, 64),
)
def test_every_sector_minimum_is_a_range_of_the_scan_and_the_nearest_is_kept(ranges, sectors):
    minima = sector_minima(ranges, sectors)
    assert minima.shape == (ranges.shape[0], sectors)
    assert np.isin(minima, ranges).all()
    if sectors <= ranges.shape[1]:
        assert np.array_equal(minima.min(axis=1), ranges.min(axis=1))


def test_a_scan_without_beams_is_refused():
    with pytest.raises(ValueError, match="at least one beam"):
        sector_minima(np.zeros((2, 0)), 4)
