import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from models.humans.bodies import two_disc_cover, vehicle_centres


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
