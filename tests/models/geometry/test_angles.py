import math

import numba
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from models.geometry.angles import TAU, wrap_angle, wrap_angles

ANY_ANGLE = st.floats(min_value=-1e6, max_value=1e6, allow_nan=False)


def test_an_angle_already_in_range_comes_back_bit_for_bit():
    inside = np.linspace(-math.pi, math.pi, 10_001)[:-1]
    assert np.array_equal(wrap_angles(inside), inside)
    assert all(wrap_angle(a) == a for a in inside.tolist())


def test_pi_wraps_to_minus_pi_and_a_hair_below_minus_pi_never_to_plus_pi():
    assert wrap_angle(math.pi) == -math.pi
    below = math.nextafter(-math.pi, -math.inf)
    assert -math.pi <= wrap_angle(below) < math.pi
    assert wrap_angles(np.array([math.pi, below]))[0] == -math.pi


@given(ANY_ANGLE)
def test_every_angle_lands_in_minus_pi_to_pi_as_the_same_direction(angle):
    wrapped = wrap_angle(angle)
    assert -math.pi <= wrapped < math.pi
    assert math.cos(wrapped) == pytest.approx(math.cos(angle), abs=1e-6)
    assert math.sin(wrapped) == pytest.approx(math.sin(angle), abs=1e-6)


@given(st.lists(ANY_ANGLE, min_size=1, max_size=20))
def test_the_array_wrap_is_the_scalar_wrap_element_for_element(angles):
    assert wrap_angles(np.array(angles)).tolist() == [wrap_angle(a) for a in angles]


def test_the_compiled_wrap_is_the_python_wrap_bit_for_bit():
    compiled = numba.njit(wrap_angle)
    angles = np.random.default_rng(1).uniform(-4 * TAU, 4 * TAU, 2_000).tolist()
    angles += [math.pi, -math.pi, 0.1, 3 * math.pi]
    assert [compiled(a) for a in angles] == [wrap_angle(a) for a in angles]


def test_nan_stays_nan():
    assert math.isnan(wrap_angle(math.nan))
    assert np.isnan(wrap_angles(np.array([math.nan]))).all()
