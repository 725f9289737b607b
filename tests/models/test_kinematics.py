import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from models.kinematics import DriveLimits, FleetState, integrate, limit_commands, wrap_angle

LIMITS = DriveLimits(1.0, 0.3, 2.0, 2.0, 3.0)


def _rk4(x, y, yaw, v, w, dt, steps=200):
    """Independent reference: classical Runge-Kutta on the unicycle ODE."""

    def f(state):
        return np.array([v * math.cos(state[2]), v * math.sin(state[2]), w])

    state = np.array([x, y, yaw])
    h = dt / steps
    for _ in range(steps):
        k1 = f(state)
        k2 = f(state + h / 2 * k1)
        k3 = f(state + h / 2 * k2)
        k4 = f(state + h * k3)
        state = state + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return state


@given(
    v=st.floats(-2, 2),
    w=st.floats(-4, 4),
    yaw=st.floats(-math.pi, math.pi),
    dt=st.floats(0.001, 0.5),
)
def test_integration_matches_a_fine_numerical_solution(v, w, yaw, dt):
    x1, y1, yaw1 = integrate(
        np.array([1.0]), np.array([2.0]), np.array([yaw]), np.array([v]), np.array([w]), dt
    )
    xr, yr, yawr = _rk4(1.0, 2.0, yaw, v, w, dt)
    assert x1[0] == pytest.approx(xr, abs=1e-9)
    assert y1[0] == pytest.approx(yr, abs=1e-9)
    assert wrap_angle(yaw1[0] - yawr) == pytest.approx(0.0, abs=1e-9)


def test_a_full_circle_returns_to_the_start():
    x, y, yaw = np.array([0.0]), np.array([0.0]), np.array([0.0])
    for _ in range(100):
        x, y, yaw = integrate(x, y, yaw, np.array([1.0]), np.array([2 * math.pi / 10]), 0.1)
    assert x[0] == pytest.approx(0.0, abs=1e-9)
    assert y[0] == pytest.approx(0.0, abs=1e-9)


def test_a_straight_line_is_exact():
    x, y, _ = integrate(
        np.array([0.0]),
        np.array([0.0]),
        np.array([math.pi / 4]),
        np.array([math.sqrt(2)]),
        np.array([0.0]),
        1.0,
    )
    assert (x[0], y[0]) == pytest.approx((1.0, 1.0), abs=1e-15)


def test_commands_are_clamped_and_slewed_by_the_acceleration_limits():
    v, w = limit_commands(
        np.array([0.0]), np.array([0.0]), np.array([5.0]), np.array([-9.0]), LIMITS, 0.05
    )
    assert v[0] == pytest.approx(0.1)  # 2 m/s^2 * 0.05 s
    assert w[0] == pytest.approx(-0.15)  # 3 rad/s^2 * 0.05 s
    v, w = limit_commands(
        np.array([0.95]), np.array([-1.95]), np.array([5.0]), np.array([-9.0]), LIMITS, 0.05
    )
    assert v[0] == pytest.approx(1.0)
    assert w[0] == pytest.approx(-2.0)
    v, _ = limit_commands(
        np.array([0.0]), np.array([0.0]), np.array([-5.0]), np.array([0.0]), LIMITS, 1.0
    )
    assert v[0] == pytest.approx(-0.3)


def test_the_fleet_steps_all_robots_at_once_and_stopped_robots_stay_put():
    fleet = FleetState(["a", "b"], np.array([[0.0, 0.0, 0.0], [5.0, 5.0, math.pi / 2]]), 0.3)
    fleet.v_cmd[:] = 1.0
    fleet.stopped[1] = True
    for _ in range(100):
        fleet.step(LIMITS, 0.05)
    # ramp of 10 steps (0.1, 0.2, ... 1.0 m/s, each held 0.05 s) = 0.275 m, then 90 x 0.05 m
    assert fleet.x[0] == pytest.approx(4.775, abs=1e-9)
    assert (fleet.x[1], fleet.y[1]) == (5.0, 5.0)
    assert fleet.distance_m[0] == pytest.approx(4.775, abs=1e-9)
    assert fleet.distance_m[1] == 0.0


def test_wrap_angle_maps_into_minus_pi_to_pi():
    angles = wrap_angle(np.array([math.pi, -math.pi, 3 * math.pi, 0.1, -7.0]))
    assert np.all(angles >= -math.pi) and np.all(angles < math.pi)
    assert angles[3] == pytest.approx(0.1)
