"""Planar rigid transforms: composition, inverse and relative motion keep their identities."""

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from models.geometry.se2 import compose, inverse, relative, yaw_of_quaternion

coordinate = st.floats(-1e3, 1e3)
angle = st.floats(-10.0, 10.0)
poses = st.tuples(coordinate, coordinate, angle)
IDENTITY = (0.0, 0.0, 0.0)


def _close(a, b, tol=1e-6) -> bool:
    dyaw = math.remainder(a[2] - b[2], 2 * math.pi)
    return abs(a[0] - b[0]) <= tol and abs(a[1] - b[1]) <= tol and abs(dyaw) <= 1e-9


def test_a_step_forward_in_a_turned_frame_moves_along_its_heading():
    assert _close(compose((1.0, 2.0, math.pi / 2), (3.0, 0.0, 0.0)), (1.0, 5.0, math.pi / 2))
    assert _close(compose((0.0, 0.0, math.pi), (1.0, 1.0, 0.0)), (-1.0, -1.0, math.pi))


def test_the_yaw_of_a_composition_is_wrapped():
    _, _, yaw = compose((0.0, 0.0, 3.0), (0.0, 0.0, 3.0))
    assert yaw == pytest.approx(6.0 - 2 * math.pi) and -math.pi <= yaw <= math.pi


@given(a=poses)
def test_a_transform_composed_with_its_inverse_is_the_identity(a):
    assert _close(compose(a, inverse(a)), IDENTITY)
    assert _close(compose(inverse(a), a), IDENTITY)


@given(a=poses)
def test_the_identity_changes_nothing(a):
    assert _close(compose(a, IDENTITY), compose(IDENTITY, a))
    wrapped = (a[0], a[1], math.remainder(a[2], 2 * math.pi))
    assert _close(compose(a, IDENTITY), wrapped)


@given(a=poses, b=poses, c=poses)
def test_composition_is_associative(a, b, c):
    assert _close(compose(compose(a, b), c), compose(a, compose(b, c)), tol=1e-6)


@given(a=poses, b=poses)
def test_the_motion_from_a_to_b_applied_at_a_is_b(a, b):
    assert _close(compose(a, relative(a, b)), b)
    assert _close(relative(a, a), IDENTITY)


@given(a=poses, b=poses)
def test_the_inverse_of_a_composition_is_the_reversed_composition_of_inverses(a, b):
    assert _close(inverse(compose(a, b)), compose(inverse(b), inverse(a)))


@given(yaw=st.floats(-math.pi, math.pi))
def test_the_yaw_of_a_rotation_about_z_is_its_angle_in_minus_pi_to_pi(yaw):
    found = yaw_of_quaternion(0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))
    assert -math.pi <= found <= math.pi
    assert math.remainder(found - yaw, 2 * math.pi) == pytest.approx(0.0, abs=1e-12)


def test_the_yaw_of_a_quaternion_tilted_about_x_keeps_its_heading():
    # a 90 degree heading then a roll: the yaw tf2 reports is still the heading
    h, r = math.pi / 2, 0.3
    cy, sy, cr, sr = math.cos(h / 2), math.sin(h / 2), math.cos(r / 2), math.sin(r / 2)
    x, y, z, w = cy * sr, sy * sr, sy * cr, cy * cr
    assert yaw_of_quaternion(x, y, z, w) == pytest.approx(h)
