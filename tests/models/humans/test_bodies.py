import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from models.humans.bodies import push_out, two_disc_cover, vehicle_centres


def test_the_body_centre_lies_half_a_length_behind_the_front_bumper():
    cx, cy = vehicle_centres(np.array([5.0]), np.array([2.0]), np.array([np.pi / 2]), 2.0)
    assert (cx[0], cy[0]) == pytest.approx((5.0, 1.0))


@settings(max_examples=50, deadline=None)
@given(
    yaw=st.floats(-np.pi, np.pi),
    length=st.floats(0.5, 5.0),
    width=st.floats(0.3, 2.5),
)
def test_two_discs_cover_every_point_of_the_body(yaw, length, width):
    discs = two_disc_cover(np.array([1.0]), np.array([-2.0]), np.array([yaw]), length, width)
    u, v = np.meshgrid(np.linspace(-0.5, 0.5, 21), np.linspace(-0.5, 0.5, 21))
    along, across = u.ravel() * length, v.ravel() * width
    x = 1.0 + np.cos(yaw) * along - np.sin(yaw) * across
    y = -2.0 + np.sin(yaw) * along + np.cos(yaw) * across
    inside = np.hypot(x[:, None] - discs[:, 0], y[:, None] - discs[:, 1]) <= discs[:, 2] + 1e-9
    assert inside.any(axis=1).all()


SHELF = np.array([[0.0, 0.0, 2.0, 1.0]])


def test_a_person_reaching_into_a_shelf_is_moved_out_until_it_touches_it():
    points = np.array([[1.0, 1.1], [2.1, 0.5], [1.0, 0.9], [5.0, 5.0]])
    moved, count = push_out(points, 0.25, SHELF)
    assert count == 3
    assert moved[0] == pytest.approx([1.0, 1.25])  # above the top face
    assert moved[1] == pytest.approx([2.25, 0.5])  # right of the right face
    assert moved[2] == pytest.approx([1.0, 1.25])  # centre inside: out the nearest face
    assert moved[3] == pytest.approx([5.0, 5.0])  # clear: untouched
    assert points[0] == pytest.approx([1.0, 1.1])  # the input is not changed


def test_a_person_at_a_corner_is_moved_away_diagonally():
    moved, _ = push_out(np.array([[2.1, 1.1]]), 0.25, SHELF)
    assert moved[0] == pytest.approx([2.0 + 0.25 / np.sqrt(2), 1.0 + 0.25 / np.sqrt(2)])


@settings(max_examples=100, deadline=None)
@given(x=st.floats(-1.0, 3.0), y=st.floats(-1.0, 2.0))
def test_after_pushing_nobody_overlaps_the_shelf(x, y):
    moved, _ = push_out(np.array([[x, y]]), 0.25, SHELF)
    cx = min(max(moved[0, 0], 0.0), 2.0)
    cy = min(max(moved[0, 1], 0.0), 1.0)
    assert np.hypot(moved[0, 0] - cx, moved[0, 1] - cy) >= 0.25 - 1e-9
