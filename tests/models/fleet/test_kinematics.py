import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from models.fleet.kinematics import (
    DriveLimits,
    FleetState,
    integrate,
    integrate_fleet,
    limit_commands,
)
from models.geometry.angles import wrap_angles

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
    assert wrap_angles(yaw1[0] - yawr) == pytest.approx(0.0, abs=1e-9)


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


def _bits(*arrays):
    return [np.asarray(a, dtype=np.float64).view(np.int64) for a in arrays]


def _numpy_propose(state, limits, dt):
    """The step as limit_commands, the stopped mask and integrate define it."""
    v, w = limit_commands(state.v, state.w, state.v_cmd, state.w_cmd, limits, dt)
    v = np.where(state.stopped, 0.0, v)
    w = np.where(state.stopped, 0.0, w)
    return (*integrate(state.x, state.y, state.yaw, v, w, dt), v, w)


def _random_fleet(rng, n):
    starts = np.column_stack(
        [rng.uniform(-50, 50, n), rng.uniform(-50, 50, n), rng.uniform(-4, 4, n)]
    )
    state = FleetState([f"r{i}" for i in range(n)], starts, 0.3)
    state.v = rng.uniform(-0.5, 1.2, n)
    state.w = rng.uniform(-2.5, 2.5, n)
    # commands beyond the limits, on them, signed zeros, exact ties with the slew bounds
    special = np.array([0.0, -0.0, 1.0, -0.3, 2.0, -2.0, 7.0, -7.0])
    state.v_cmd = np.where(rng.random(n) < 0.4, rng.choice(special, n), rng.uniform(-2, 2, n))
    state.w_cmd = np.where(rng.random(n) < 0.4, rng.choice(special, n), rng.uniform(-4, 4, n))
    tie = rng.random(n) < 0.1
    state.v_cmd[tie] = state.v[tie] + LIMITS.max_accel_mps2 * 0.05
    state.stopped = rng.random(n) < 0.2
    return state


def test_the_compiled_fleet_step_matches_the_numpy_definition_bit_for_bit():
    rng = np.random.default_rng(8)
    for trial in range(3000):
        state = _random_fleet(rng, int(rng.integers(1, 12)))
        if trial % 10 == 0:
            state.w[:] = 0.0
            state.w_cmd[:] = -0.0
        dt = float(rng.choice([0.05, 0.1, 1 / 30, 0.5]))
        motion = state.propose(LIMITS, dt)
        got = _bits(motion.x, motion.y, motion.yaw, motion.v, motion.w)
        want = _bits(*_numpy_propose(state, LIMITS, dt))
        for name, g, e in zip(["x", "y", "yaw", "v", "w"], got, want, strict=True):
            np.testing.assert_array_equal(g, e, err_msg=f"{name}, trial {trial}")


def test_a_nan_command_propagates_as_numpy_clip_keeps_it():
    state = FleetState(["r0", "r1"], np.zeros((2, 3)), 0.3)
    state.v_cmd = np.array([np.nan, 0.5])
    state.w_cmd = np.array([0.1, np.nan])
    motion = state.propose(LIMITS, 0.05)
    want = _numpy_propose(state, LIMITS, 0.05)
    moved = (motion.x, motion.y, motion.yaw, motion.v, motion.w)
    for got, expected in zip(moved, want, strict=True):
        np.testing.assert_array_equal(got, expected)


def test_integrate_fleet_matches_integrate_bit_for_bit_at_wrap_edges_and_zero_rates():
    rng = np.random.default_rng(9)
    n = 20_000
    x, y = rng.uniform(-100, 100, n), rng.uniform(-100, 100, n)
    yaw = np.concatenate([rng.uniform(-4, 4, n - 8), [math.pi, -math.pi, 0.0, -0.0] * 2])
    v = rng.uniform(-2, 2, n)
    w = np.where(rng.random(n) < 0.2, 0.0, rng.uniform(-6, 6, n))
    w[-8:] = [0.0, 0.0, math.pi, -math.pi, 2 * math.pi, -2 * math.pi, -0.0, 1e-300]
    for dt in (0.05, 1.0, 0.5):
        got = _bits(*integrate_fleet(x, y, yaw, v, w, dt))
        want = _bits(*integrate(x, y, yaw, v, w, dt))
        for g, e in zip(got, want, strict=True):
            np.testing.assert_array_equal(g, e)
