"""Regulated Pure Pursuit: pursuit on arcs, regulated speeds, turns on the spot, stops."""

from __future__ import annotations

import math

import numpy as np
import pytest

from models.errors import ModelError
from models.fleet.kinematics import DriveLimits, integrate, limit_commands
from models.navigation.fleet_inputs import packed
from models.navigation.pure_pursuit import (
    RppParams,
    _arc_distance_py,
    _rpp_py,
    rpp_batch,
)
from models.slicing import Rows

LIMITS = DriveLimits(1.0, 0.3, 2.0, 2.0, 3.0)
QUICK = DriveLimits(1.0, 0.3, 2.0, 100.0, 100.0)  # a window that never binds
RADIUS = 0.33
PARAMS = RppParams()
STILL = RppParams(lookahead_time_s=0.0)  # the carrot as given, whatever the speed
DT = PARAMS.control_period_s


def _call(
    pose,
    carrot,
    *,
    vel=(0.0, 0.0),
    goal=None,
    points=(),
    discs=(),
    limits=LIMITS,
    params=STILL,
):
    """One robot's command; ``goal`` defaults to far beyond the carrot."""
    points = np.asarray(points, dtype=float).reshape(-1, 2)
    discs = np.asarray(discs, dtype=float).reshape(-1, 3)
    goal = (100.0, 100.0) if goal is None else goal
    return rpp_batch(
        np.array([pose], dtype=float),
        np.array([vel], dtype=float),
        limits,
        np.array([RADIUS]),
        np.array([carrot], dtype=float),
        np.array([goal], dtype=float),
        points,
        np.array([0, len(points)], dtype=np.int64),
        discs,
        np.array([0, len(discs)], dtype=np.int64),
        params,
    )


def _wall(x: float, half: float = 1.5) -> list[list[float]]:
    """Hits every 2 cm along the line x = ``x`` (m)."""
    return [[x, y] for y in np.arange(-half, half + 1e-9, 0.02)]


def test_a_robot_on_a_straight_clear_path_keeps_full_speed_and_drives_straight():
    result = _call((0.0, 0.0, 0.0), (1.0, 0.0), vel=(1.0, 0.0), params=PARAMS)
    assert result.v[0] == pytest.approx(LIMITS.max_speed_mps)
    assert result.w[0] == pytest.approx(0.0, abs=1e-12)
    assert not result.blocked[0]


def test_a_robot_at_rest_speeds_up_by_what_its_acceleration_allows():
    result = _call((0.0, 0.0, 0.0), (1.0, 0.0))
    assert result.v[0] == pytest.approx(LIMITS.max_accel_mps2 * DT)


def test_rpp_slows_down_on_a_tight_turn_and_keeps_full_speed_on_a_gentle_one():
    # arcs through carrots 0.5 m away: radius L / (2 sin(bearing))
    tight = _call((0.0, 0.0, 0.0), (0.5 * math.cos(0.6), 0.5 * math.sin(0.6)), limits=QUICK)
    gentle = _call((0.0, 0.0, 0.0), (0.5 * math.cos(0.2), 0.5 * math.sin(0.2)), limits=QUICK)
    radius = 0.5 / (2.0 * math.sin(0.6))  # 0.44 m, below the 0.9 m of the defaults
    assert tight.v[0] == pytest.approx(radius / STILL.min_turn_radius_m)
    assert gentle.v[0] == pytest.approx(1.0)  # radius 1.26 m
    assert tight.w[0] == pytest.approx(tight.v[0] / radius)  # on the arc through the carrot
    assert tight.w[0] > 0 > _call((0, 0, 0), (0.45, -0.28), limits=QUICK).w[0]  # REP 103


def test_curvature_slows_the_robot_no_further_than_the_regulated_minimum():
    # radius 0.2 / (2 sin 0.75) = 0.15 m: 0.16 m/s by curvature, held at 0.25
    result = _call((0.0, 0.0, 0.0), (0.2 * math.cos(0.75), 0.2 * math.sin(0.75)), limits=QUICK)
    assert result.v[0] == pytest.approx(STILL.min_regulated_speed_mps)


def test_a_robot_slows_linearly_onto_its_goal_down_to_the_approach_minimum():
    speeds = [
        _call((0.0, 0.0, 0.0), (d, 0.0), goal=(d, 0.0), limits=QUICK).v[0]
        for d in (1.0, 0.6, 0.3, 0.15, 0.01)
    ]
    assert speeds[:4] == pytest.approx([1.0, 1.0, 0.5, 0.25])
    assert speeds[4] == pytest.approx(STILL.min_approach_speed_mps)


@pytest.mark.parametrize(("carrot", "sign"), [((-1.0, 0.2), 1.0), ((-1.0, -0.2), -1.0)])
def test_a_robot_turns_on_the_spot_towards_a_carrot_behind_it(carrot, sign):
    result = _call((0.0, 0.0, 0.0), carrot, limits=QUICK, params=PARAMS)
    assert result.v[0] == 0.0
    assert result.w[0] == pytest.approx(sign * PARAMS.rotate_to_heading_speed_radps)
    assert not result.blocked[0]


def test_a_robot_turns_on_the_spot_only_beyond_the_rotate_to_heading_angle():
    angle = PARAMS.rotate_to_heading_min_angle_rad
    beyond = _call((0, 0, 0), (math.cos(angle + 0.05), math.sin(angle + 0.05)), limits=QUICK)
    within = _call((0, 0, 0), (math.cos(angle - 0.05), math.sin(angle - 0.05)), limits=QUICK)
    assert beyond.v[0] == 0.0 and beyond.w[0] > 0.0
    assert within.v[0] > 0.0


def test_a_turn_on_the_spot_slows_as_the_robot_comes_to_face_its_carrot():
    # a yaw acceleration of 1 rad/s^2 brakes a turn within 0.9 rad from sqrt(2 * 0.9) rad/s
    sluggish = DriveLimits(1.0, 0.3, 2.0, 2.0, 1.0)
    far = _call((0, 0, 0), (math.cos(2.5), math.sin(2.5)), vel=(0.0, 1.8), limits=sluggish)
    near = _call((0, 0, 0), (math.cos(0.9), math.sin(0.9)), vel=(0.0, 1.3), limits=sluggish)
    assert far.w[0] == pytest.approx(PARAMS.rotate_to_heading_speed_radps)
    assert near.w[0] == pytest.approx(math.sqrt(1.8))


def test_a_robot_slows_near_an_obstacle_beside_it():
    beside = [[x, -0.5] for x in np.arange(-1.0, 1.0, 0.02)]  # clearance 0.17 m, off the arc
    near = _call((0.0, 0.0, 0.0), (1.0, 0.0), points=beside, limits=QUICK)
    clear = _call((0.0, 0.0, 0.0), (1.0, 0.0), limits=QUICK)
    assert near.clearance_m[0] == pytest.approx(0.17)
    assert near.v[0] == pytest.approx(0.17 / STILL.proximity_clearance_m)
    assert clear.v[0] == pytest.approx(1.0) and clear.clearance_m[0] == math.inf
    assert not near.blocked[0]


def test_a_robot_stops_and_is_blocked_by_a_wall_on_its_arc_ahead():
    result = _call((0.0, 0.0, 0.0), (1.0, 0.0), vel=(0.6, 0.0), points=_wall(1.2))
    assert result.blocked[0]
    assert result.v[0] == 0.0 and result.w[0] == 0.0


def test_a_robot_is_blocked_by_another_robots_disc_on_its_arc():
    disc = [[1.0, 0.1, 0.33]]
    assert _call((0.0, 0.0, 0.0), (1.5, 0.0), vel=(0.5, 0.0), discs=disc).blocked[0]
    aside = [[1.0, 1.2, 0.33]]
    assert not _call((0.0, 0.0, 0.0), (1.5, 0.0), vel=(0.5, 0.0), discs=aside).blocked[0]


def test_an_obstacle_beyond_the_carrot_and_the_stopping_distance_does_not_block():
    result = _call((0.0, 0.0, 0.0), (0.5, 0.0), vel=(0.4, 0.0), points=_wall(1.3))
    assert not result.blocked[0] and result.v[0] > 0.0


def test_a_fast_robot_checks_at_least_as_far_as_it_needs_to_stop():
    # carrot 0.3 m ahead, but at 1 m/s the robot needs 0.1 + 0.25 m: the wall counts
    result = _call((0.0, 0.0, 0.0), (0.3, 0.0), vel=(1.0, 0.0), points=_wall(0.70))
    assert result.blocked[0]


def test_a_robot_turning_on_the_spot_is_never_blocked_even_boxed_in():
    ring = [[0.36 * math.cos(a), 0.36 * math.sin(a)] for a in np.linspace(0, 2 * math.pi, 90)]
    result = _call((0.0, 0.0, 0.0), (-1.0, 0.1), points=ring)
    assert not result.blocked[0] and result.v[0] == 0.0 and result.w[0] > 0.0


def test_a_robot_inside_the_margin_may_drive_along_the_wall_but_not_into_it():
    along = [[x, -0.35] for x in np.arange(-1.0, 2.0, 0.02)]  # clearance 0.02 m, beside
    assert not _call((0.0, 0.0, 0.0), (1.0, 0.0), vel=(0.3, 0.0), points=along).blocked[0]
    ahead = [[0.36, y] for y in np.arange(-1.0, 1.0, 0.02)]  # clearance 0.03 m, in front
    assert _call((0.0, 0.0, 0.0), (1.0, 0.0), vel=(0.3, 0.0), points=ahead).blocked[0]


def test_a_robot_along_a_wall_at_the_margin_is_not_stopped_by_the_noise_of_its_hits():
    # 5.5 cm beside, hits ahead 1.3 cm nearer (lidar noise): within the 2 cm allowed
    beside = [[x, -0.385] for x in np.arange(-1.0, 0.25, 0.02)]
    ahead = [[x, -0.372] for x in np.arange(0.25, 2.0, 0.02)]
    result = _call((0.0, 0.0, 0.0), (1.0, 0.0), vel=(0.5, 0.0), points=beside + ahead)
    assert result.clearance_m[0] == pytest.approx(0.055)
    assert not result.blocked[0]
    nearer = [[x, -0.36] for x in np.arange(0.25, 2.0, 0.02)]  # 3 cm short: blocked
    assert _call((0.0, 0.0, 0.0), (1.0, 0.0), vel=(0.5, 0.0), points=beside + nearer).blocked[0]


def test_a_robot_closing_in_on_a_wall_stops_without_touching_it():
    x, y, yaw, v, w = (np.zeros(1) for _ in range(5))
    wall = np.array(_wall(3.0))
    blocked = False
    for _ in range(60):
        seen = wall[np.hypot(wall[:, 0] - x[0], wall[:, 1] - y[0]) < 2.8]
        result = _call((x[0], y[0], yaw[0]), (x[0] + 1.0, 0.0), vel=(v[0], w[0]), points=seen)
        blocked |= bool(result.blocked[0])
        v, w = limit_commands(v, w, result.v, result.w, LIMITS, DT)
        x, y, yaw = integrate(x, y, yaw, v, w, DT)
        assert 3.0 - x[0] - RADIUS > 0.0
    assert blocked and v[0] == 0.0
    assert 3.0 - x[0] - RADIUS >= STILL.collision_margin_m - 0.02


def test_commands_stay_within_the_speed_limits_and_the_acceleration_window():
    rng = np.random.default_rng(3)
    n = 300
    poses = np.column_stack([rng.uniform(-5, 5, (n, 2)), rng.uniform(-math.pi, math.pi, n)])
    vel = np.column_stack([rng.uniform(0.0, 1.0, n), rng.uniform(-2.0, 2.0, n)])
    carrots = poses[:, :2] + rng.uniform(-1.0, 1.0, (n, 2))
    goals = carrots + rng.uniform(-1.0, 1.0, (n, 2))
    points = np.repeat(poses[:, :2], 8, axis=0) + rng.uniform(-1.5, 1.5, (8 * n, 2))
    start = np.arange(0, 8 * n + 1, 8)
    result = rpp_batch(
        poses, vel, LIMITS, np.full(n, RADIUS), carrots, goals, points, start,
        np.zeros((0, 3)), np.zeros(n + 1, dtype=np.int64), PARAMS,
    )  # fmt: skip
    v, w, free = result.v, result.w, ~result.blocked
    assert free.any() and result.blocked.any()
    assert np.all((v >= 0.0) & (v <= LIMITS.max_speed_mps))
    assert np.all(np.abs(w) <= LIMITS.max_yaw_rate_radps + 1e-12)
    assert np.all(np.abs(v - vel[:, 0])[free] <= LIMITS.max_accel_mps2 * DT + 1e-12)
    assert np.all(np.abs(w - vel[:, 1])[free] <= LIMITS.max_yaw_accel_radps2 * DT + 1e-12)
    assert np.all((v == 0.0) & (w == 0.0) | free)


def _batch_of(n: int, seed: int):
    """Arguments of :func:`rpp_batch` for ``n`` robots, robot 5 hearing of one disc."""
    rng = np.random.default_rng(seed)
    poses = np.column_stack([rng.uniform(0, 20, (n, 2)), rng.uniform(-math.pi, math.pi, n)])
    counts = rng.integers(0, 40, n)
    points = np.concatenate(
        [p[:2] + rng.uniform(-2, 2, (c, 2)) for p, c in zip(poses, counts, strict=True)]
    )
    return (
        poses,
        np.column_stack([rng.uniform(0, 1, n), rng.uniform(-1, 1, n)]),
        LIMITS,
        np.full(n, RADIUS),
        poses[:, :2] + rng.uniform(-1, 1, (n, 2)),
        poses[:, :2] + rng.uniform(-3, 3, (n, 2)),
        points,
        np.concatenate([[0], np.cumsum(counts)]).astype(np.int64),
        np.array([[poses[5, 0] + 0.8, poses[5, 1], 0.33]]),
        np.array([0] * 6 + [1] * (n - 5), dtype=np.int64),
        PARAMS,
    )


def test_each_robots_command_is_the_same_alone_in_any_batch_and_any_cut():
    args = _batch_of(12, seed=5)
    whole = rpp_batch(*args)
    again = rpp_batch(*args)

    def threes(count: int, rows: Rows) -> None:
        for first in range(0, count, 3):
            rows(first, min(first + 3, count))

    cut = rpp_batch(*args, slices=threes)
    for a, b, c in zip(whole, again, cut, strict=True):
        np.testing.assert_array_equal(a, b)
        np.testing.assert_array_equal(a, c)
    poses, vel, limits, radii, carrots, goals, points, start, discs = args[:9]
    for i in (0, 5, 11):
        lo, hi = start[i], start[i + 1]
        disc = discs if i == 5 else np.zeros((0, 3))
        one = slice(i, i + 1)
        alone = rpp_batch(
            poses[one], vel[one], limits, radii[one], carrots[one], goals[one], points[lo:hi],
            np.array([0, hi - lo]), disc, np.array([0, len(disc)]), PARAMS,
        )  # fmt: skip
        assert alone.v[0] == whole.v[i] and alone.w[0] == whole.w[i]
        assert alone.blocked[0] == whole.blocked[i]


def test_the_compiled_kernel_and_the_python_one_agree():
    args = _batch_of(20, seed=9)
    compiled = rpp_batch(*args)
    poses, vel, limits, radii, carrots, goals, points, start, discs, disc_start, params = args
    state = np.column_stack([poses, vel, radii, carrots, goals])
    out = np.zeros((20, 4))
    _rpp_py(state, points, start, discs, disc_start, packed(params, limits), out)
    np.testing.assert_array_equal(out[:, 0], compiled.v)
    np.testing.assert_array_equal(out[:, 1], compiled.w)
    np.testing.assert_array_equal(out[:, 2] > 0.5, compiled.blocked)


def test_the_distance_to_an_arc_matches_a_finely_sampled_arc():
    rng = np.random.default_rng(11)
    for _ in range(300):
        k, s = rng.uniform(-4.0, 4.0), rng.uniform(0.05, 2.5)
        px, py = rng.uniform(-2.0, 2.0, 2)
        t = np.linspace(0.0, s, 20001)
        x, y, _ = integrate(np.zeros_like(t), np.zeros_like(t), np.zeros_like(t), t, k * t, 1.0)
        sampled = np.hypot(x - px, y - py).min()
        assert _arc_distance_py(px, py, k, s) == pytest.approx(sampled, abs=2e-4)
    assert _arc_distance_py(0.5, 0.3, 1e-9, 1.0) == pytest.approx(0.3)  # a straight arc


@pytest.mark.parametrize(
    ("change", "key"),
    [
        ({"collision_time_s": 0.0}, "rpp.collision_time_s"),
        ({"desired_speed_mps": -1.0}, "rpp.desired_speed_mps"),
        ({"collision_margin_m": math.nan}, "rpp.collision_margin_m"),
        ({"proximity_gain": 1.5}, "rpp.proximity_gain"),
    ],
)
def test_bad_parameters_are_refused_by_name(change, key):
    with pytest.raises(ModelError, match=key):
        RppParams(**change)


def test_inputs_of_the_wrong_shape_or_offsets_are_refused():
    args = list(_batch_of(8, seed=1))
    with pytest.raises(ValueError, match="carrots"):
        rpp_batch(*args[:4], args[4][:7], *args[5:])
    with pytest.raises(ValueError, match="obstacle_start"):
        rpp_batch(*args[:7], args[7][:-1], *args[8:])
    with pytest.raises(ValueError, match="disc_start"):
        rpp_batch(*args[:9], args[9] + 1, *args[10:])
    with pytest.raises(ModelError, match="max_accel_mps2"):
        rpp_batch(*args[:2], DriveLimits(1.0, 0.3, 2.0, 0.0, 3.0), *args[3:])
