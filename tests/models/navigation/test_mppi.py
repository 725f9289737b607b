"""MPPI for a whole fleet: sampled rollouts scored by critics, one compiled call."""

from __future__ import annotations

import dataclasses
import itertools

import numpy as np
import pytest

import models.navigation.mppi as mppi_module
from models.errors import ModelError
from models.fleet.kinematics import DriveLimits, FleetState
from models.navigation.mppi import MppiParams, mppi_batch, noise_knots

LIMITS = DriveLimits(1.0, 0.3, 2.0, 2.0, 3.0)
RADIUS = 0.33
PARAMS = MppiParams()
DT = PARAMS.control_period_s
NO_DISCS = np.zeros((0, 3))
FAR = (60.0, 0.0)  # a goal well beyond every carrot: the robots follow their paths


def _noise(n, seed, params=PARAMS):
    return np.random.default_rng(seed).standard_normal((n, noise_knots(params), 2, params.samples))


def _call(poses, velocities, carrots, goals, points, nominal, noise, discs=NO_DISCS, **kw):
    poses = np.atleast_2d(np.asarray(poses, dtype=float))
    n = len(poses)
    points = np.asarray(points, dtype=float).reshape(-1, 2)
    starts = kw.pop("start", np.array([0] * n + [len(points)], dtype=np.int64))
    disc_start = kw.pop("disc_start", np.array([0] * n + [len(discs)], dtype=np.int64))
    return mppi_batch(
        poses,
        np.atleast_2d(np.asarray(velocities, dtype=float)),
        LIMITS,
        np.full(n, RADIUS),
        np.atleast_2d(np.asarray(carrots, dtype=float)),
        np.atleast_2d(np.asarray(goals, dtype=float)),
        points,
        starts,
        np.asarray(discs, dtype=float).reshape(-1, 3),
        disc_start,
        nominal,
        noise,
        kw.pop("params", PARAMS),
        **kw,
    )


def _drive(start, carrot, seconds, points=(), discs=NO_DISCS, goal=FAR, seed=0):
    """Closed loop for one robot: decide, step the unicycle; the trace of poses and commands."""
    fleet = FleetState(["r"], np.array([start], dtype=float), RADIUS)
    nominal = np.zeros((1, PARAMS.time_steps, 2))
    rng = np.random.default_rng(seed)
    trace = []
    for _ in range(round(seconds / DT)):
        pose = np.column_stack([fleet.x, fleet.y, fleet.yaw])
        noise = rng.standard_normal((1, noise_knots(PARAMS), 2, PARAMS.samples))
        result = _call(
            pose, [[fleet.v[0], fleet.w[0]]], carrot, goal, points, nominal, noise, discs
        )
        fleet.v_cmd, fleet.w_cmd = result.v, result.w
        fleet.step(LIMITS, DT)
        trace.append((fleet.x[0], fleet.y[0], fleet.yaw[0], result.v[0], result.w[0]))
    return np.array(trace)


def _ring(radius, count=90, centre=(0.0, 0.0)):
    angles = np.linspace(0.0, 2 * np.pi, count, endpoint=False)
    return np.column_stack(
        [centre[0] + radius * np.cos(angles), centre[1] + radius * np.sin(angles)]
    )


def test_a_robot_drives_towards_a_carrot_straight_ahead():
    trace = _drive((0.0, 0.0, 0.0), (30.0, 0.0), 4.0)
    x, y, v = trace[:, 0], trace[:, 1], trace[:, 3]
    assert x[-1] > 3.0  # at 1 m/s after a second of speeding up
    assert np.abs(y).max() < 0.3
    assert v[-10:].mean() > 0.8 and np.all(v >= 0.0)


@pytest.mark.parametrize("side", [1.0, -1.0])
def test_a_robot_turns_towards_a_carrot_on_its_side(side):
    trace = _drive((0.0, 0.0, 0.0), (0.0, 10.0 * side), 2.5)
    assert side * trace[:5, 4].mean() > 0.5  # left is counter-clockwise (REP 103)
    assert abs(trace[-1, 2] - side * np.pi / 2) < 0.3  # facing it after the turn
    assert side * trace[-1, 1] > 0.5  # and driving to it


@pytest.mark.parametrize("as_disc", [False, True])
def test_a_robot_avoids_an_obstacle_in_its_way_and_passes_it(as_disc):
    centre = np.array([2.0, 0.05])
    points = [] if as_disc else _ring(0.2, 40, centre)
    discs = np.array([[*centre, 0.2]]) if as_disc else NO_DISCS
    trace = _drive((0.0, 0.0, 0.0), (20.0, 0.0), 6.0, points, discs)
    clearance = np.hypot(*(trace[:, :2] - centre).T) - 0.2 - RADIUS
    assert clearance.min() > PARAMS.footprint_padding_m - 0.02
    assert trace[-1, 0] > 4.0  # round it and on


def test_a_robot_stops_on_its_goal():
    goal = (2.5, 0.5)
    trace = _drive((0.0, 0.0, 0.0), goal, 8.0, goal=goal)
    assert np.hypot(trace[-1, 0] - goal[0], trace[-1, 1] - goal[1]) < 0.15
    assert abs(trace[-1, 3]) < 0.1


@pytest.mark.parametrize("goal", [(-0.8, 0.0), (-1.5, 0.5)])
def test_a_robot_turns_round_to_a_goal_behind_it(goal):
    trace = _drive((0.0, 0.0, 0.0), goal, 6.0, goal=goal)
    gap = np.hypot(trace[:, 0] - goal[0], trace[:, 1] - goal[1])
    assert (gap[:35] < 0.25).any()  # within 3.5 s: it turns, it does not back up the way
    assert gap[-1] < 0.1  # and stays there


def test_the_same_noise_gives_the_same_commands_and_other_noise_other_ones():
    args = ((0.0, 0.0, 0.0), (0.5, 0.0), (3.0, 1.0), FAR, _ring(0.3, 20, (1.5, 1.0)))
    results = []
    for seed in (1, 1, 2):
        nominal = np.zeros((1, PARAMS.time_steps, 2))
        results.append((_call(*args, nominal, _noise(1, seed)), nominal))
    (first, nom_1), (again, nom_2), (other, nom_3) = results
    assert np.array_equal(first.v, again.v) and np.array_equal(first.w, again.w)
    assert np.array_equal(nom_1, nom_2)
    assert first.v[0] != other.v[0] and first.w[0] != other.w[0]
    assert not np.array_equal(nom_1, nom_3)


def test_commands_stay_within_the_limits_and_what_one_step_of_acceleration_reaches():
    rng = np.random.default_rng(5)
    n = 40
    poses = np.column_stack([rng.uniform(0, 20, n), rng.uniform(0, 20, n), rng.uniform(-3, 3, n)])
    velocities = np.column_stack([rng.uniform(-0.3, 1.0, n), rng.uniform(-2.0, 2.0, n)])
    carrots = poses[:, :2] + rng.uniform(-3, 3, (n, 2))
    points = poses[:, :2].repeat(30, axis=0) + rng.uniform(-2.0, 2.0, (30 * n, 2))
    start = np.arange(0, 30 * n + 1, 30, dtype=np.int64)
    nominal = rng.uniform(-3.0, 3.0, (n, PARAMS.time_steps, 2))  # beyond every limit
    result = _call(poses, velocities, carrots, carrots, points, nominal, _noise(n, 3), start=start)
    assert result.blocked.any() and not result.blocked.all()
    reach_v, reach_w = LIMITS.max_accel_mps2 * DT, LIMITS.max_yaw_accel_radps2 * DT
    assert np.all(result.v <= LIMITS.max_speed_mps) and np.all(result.v >= -LIMITS.max_reverse_mps)
    assert np.all(np.abs(result.w) <= LIMITS.max_yaw_rate_radps)
    assert np.all(np.abs(result.v - velocities[:, 0]) <= reach_v + 1e-12)
    assert np.all(np.abs(result.w - velocities[:, 1]) <= reach_w + 1e-12)
    assert np.all(np.abs(nominal[:, :, 0]) <= LIMITS.max_speed_mps)


def test_a_boxed_in_robot_is_blocked_brakes_and_starts_its_sequence_again():
    ring = _ring(RADIUS + 0.12)
    nominal = np.full((1, PARAMS.time_steps, 2), 0.5)
    result = _call((0.0, 0.0, 0.0), (0.5, 0.5), (3.0, 0.0), FAR, ring, nominal, _noise(1, 0))
    assert result.blocked.tolist() == [True]
    assert result.v[0] == pytest.approx(0.5 - LIMITS.max_accel_mps2 * DT)
    assert result.w[0] == pytest.approx(0.5 - LIMITS.max_yaw_accel_radps2 * DT)
    assert not nominal.any()
    free = _call((0.0, 0.0, 0.0), (0.0, 0.0), (3.0, 0.0), FAR, _ring(1.5), nominal, _noise(1, 0))
    assert free.blocked.tolist() == [False] and free.v[0] > 0.0


def test_the_nominal_is_shifted_by_the_control_period():
    still = dataclasses.replace(PARAMS, v_std_mps=0.0, w_std_radps=0.0)  # every sample alike
    ramp = 0.5 + 0.01 * np.arange(PARAMS.time_steps)
    for period, shifted in [(DT, np.append(ramp[1:], ramp[-1])), (DT / 2, ramp + 0.005)]:
        params = dataclasses.replace(still, control_period_s=period)
        nominal = np.stack([ramp, np.zeros_like(ramp)], axis=1)[None].copy()
        result = _call(
            (0.0, 0.0, 0.0), (0.5, 0.0), (30.0, 0.0), FAR, [], nominal, _noise(1, 0), params=params
        )
        assert result.v[0] == pytest.approx(0.5)  # the first control
        expected = shifted if period == DT else np.append(shifted[:-1], ramp[-1])
        np.testing.assert_allclose(nominal[0, :, 0], expected, atol=1e-12)


def _cut_at(edges):
    def slices(count, rows):
        bounds = [0, *[e for e in edges if 0 < e < count], count]
        for start, stop in itertools.pairwise(bounds):
            rows(start, stop)

    return slices


@pytest.mark.parametrize("edges", [[1], [5], [3, 4, 9], list(range(1, 10))])
def test_commands_are_the_same_whatever_the_robots_are_cut_into(edges):
    rng = np.random.default_rng(11)
    n = 10
    poses = np.column_stack([rng.uniform(0, 10, n), rng.uniform(0, 10, n), rng.uniform(-3, 3, n)])
    velocities = np.column_stack([rng.uniform(0, 1, n), rng.uniform(-1, 1, n)])
    carrots = poses[:, :2] + rng.uniform(-2.0, 2.0, (n, 2))
    points = poses[:, :2].repeat(20, axis=0) + rng.uniform(-1.5, 1.5, (20 * n, 2))
    start = np.arange(0, 20 * n + 1, 20, dtype=np.int64)
    # robot i hears of robot i + 1
    discs = np.column_stack([np.roll(poses[:, :2], -1, axis=0), np.full(n, RADIUS)])
    disc_start = np.arange(n + 1, dtype=np.int64)
    noise = _noise(n, 4)
    outcomes = []
    for slices in (None, _cut_at(edges)):
        nominal = np.zeros((n, PARAMS.time_steps, 2))
        extra = {} if slices is None else {"slices": slices}
        result = _call(
            poses, velocities, carrots, carrots, points, nominal, noise, discs,
            start=start, disc_start=disc_start, **extra,
        )  # fmt: skip
        outcomes.append((*result, nominal))
    for a, b in zip(*outcomes, strict=True):
        assert np.array_equal(a, b)


def test_the_python_kernel_computes_what_the_compiled_one_does(monkeypatch):
    poses, velocities = [(0.0, 0.0, 0.3), (0.0, 0.0, 0.3)], [(0.4, 0.2), (0.4, 0.2)]
    carrots, goals = [(2.0, 1.0), (2.0, 1.0)], [FAR, (2.0, 1.0)]  # following, arriving
    points, start = _ring(0.3, 30, (1.2, 0.4)), np.array([0, 30, 30], dtype=np.int64)
    discs, disc_start = np.array([[0.0, 1.5, RADIUS]]), np.array([0, 1, 1], dtype=np.int64)
    results = []
    for kernel in (mppi_module._mppi, mppi_module._mppi_py):
        monkeypatch.setattr(mppi_module, "_mppi", kernel)
        nominal = np.full((2, PARAMS.time_steps, 2), 0.3)
        result = _call(
            poses, velocities, carrots, goals, points, nominal, _noise(2, 6), discs,
            start=start, disc_start=disc_start,
        )  # fmt: skip
        results.append((*result, nominal))
    for compiled, python in zip(*results, strict=True):
        np.testing.assert_allclose(compiled, python, rtol=0, atol=1e-9)
    assert results[0][0].min() > 0.0  # both robots drive


def test_invalid_parameters_and_inputs_are_rejected():
    with pytest.raises(ModelError) as samples:
        MppiParams(samples=0)
    assert samples.value.key == "mppi.samples" and samples.value.value == 0
    with pytest.raises(ModelError, match=r"mppi\.temperature"):
        MppiParams(temperature=0.0)
    with pytest.raises(ModelError, match=r"mppi\.path_weight"):
        MppiParams(path_weight=float("nan"))
    nominal = np.zeros((1, PARAMS.time_steps, 2))
    args = ((0.0, 0.0, 0.0), (0.0, 0.0), (1.0, 0.0), FAR, [[1.0, 1.0]])
    with pytest.raises(ValueError, match="noise"):
        _call(*args, nominal, np.zeros((1, PARAMS.samples, PARAMS.time_steps, 2)))
    with pytest.raises(ValueError, match="nominal"):
        _call(*args, np.zeros((1, PARAMS.time_steps + 1, 2)), _noise(1, 0))
    with pytest.raises(ValueError, match="obstacle_start"):
        _call(*args, nominal, _noise(1, 0), start=np.array([0, 2]))
