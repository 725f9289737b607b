import itertools
import math

import numpy as np
import pytest

from models.errors import ModelError
from models.fleet.kinematics import DriveLimits, FleetState, integrate
from models.geometry.angles import wrap_angles
from models.navigation.dwa import DwaParams, dwa_batch
from models.sensing.raycast import StaticScene, cast_batch
from models.world.warehouse import WarehouseSpec, generate_warehouse

LIMITS = DriveLimits(1.0, 0.3, 2.0, 2.0, 3.0)
RADIUS = 0.33
PARAMS = DwaParams()
DT = PARAMS.control_period_s
BEAMS = -math.pi + 2 * math.pi / 360 * np.arange(360)
NO_SEGMENTS = np.zeros((0, 4))
NO_DISCS = np.zeros((0, 3))


def _corridor(width, x0=-3.0, x1=12.0):
    h = width / 2
    return np.array([[x0, -h, x1, -h], [x0, h, x1, h]])


def _distance_to_segments(point, segments):
    if len(segments) == 0:
        return np.inf
    a, b = segments[:, :2], segments[:, 2:]
    ab = b - a
    t = np.clip(((point - a) * ab).sum(1) / (ab * ab).sum(1), 0.0, 1.0)
    return float(np.hypot(*(a + t[:, None] * ab - point).T).min())


def _scan(scene, fleet, keep_m=3.0):
    """Every robot's lidar hits within keep_m as map points, CSR by robot."""
    pos = fleet.positions
    circles = np.column_stack([pos, fleet.radius_m])
    ranges = cast_batch(
        scene, pos, fleet.yaw, BEAMS, circles, np.arange(len(fleet), dtype=np.int64), 10.0
    )
    points, counts = [], []
    for i in range(len(fleet)):
        hit = ranges[i] <= keep_m
        angle = fleet.yaw[i] + BEAMS[hit]
        r = ranges[i, hit, None]
        points.append(pos[i] + r * np.column_stack([np.cos(angle), np.sin(angle)]))
        counts.append(int(hit.sum()))
    return np.vstack(points), np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)


def _call(poses, velocities, carrots, goals, points, start=None, discs=NO_DISCS, params=PARAMS):
    poses = np.atleast_2d(np.asarray(poses, dtype=float))
    n = len(poses)
    points = np.asarray(points, dtype=float).reshape(-1, 2)
    if start is None:
        start = np.array([0, len(points)], dtype=np.int64)
    disc_start = np.array([0] * n + [len(discs)], dtype=np.int64)
    return dwa_batch(
        poses,
        np.atleast_2d(np.asarray(velocities, dtype=float)),
        LIMITS,
        np.full(n, RADIUS),
        np.atleast_2d(np.asarray(carrots, dtype=float)),
        np.atleast_2d(np.asarray(goals, dtype=float)),
        points,
        start,
        np.asarray(discs, dtype=float).reshape(-1, 3),
        disc_start,
        params,
    )


def _simulate(starts, goals, segments, seconds, carrots=None, on_command=None):
    """Closed loop: scan, command, step the fleet; returns the trace."""
    n = len(starts)
    fleet = FleetState([f"r{i}" for i in range(n)], np.array(starts, dtype=float), RADIUS)
    scene = StaticScene(segments)
    goals = np.array(goals, dtype=float)
    trace = {"pose": [], "v": [], "w": [], "blocked": [], "wall": [], "gap": []}
    for _ in range(round(seconds / DT)):
        points, start = _scan(scene, fleet)
        poses = np.column_stack([fleet.x, fleet.y, fleet.yaw])
        velocities = np.column_stack([fleet.v, fleet.w])
        result = dwa_batch(
            poses,
            velocities,
            LIMITS,
            fleet.radius_m,
            goals if carrots is None else carrots(poses),
            goals,
            points,
            start,
            NO_DISCS,
            np.zeros(n + 1, dtype=np.int64),
            PARAMS,
        )
        if on_command is not None:
            on_command(poses, velocities, points, start, result)
        fleet.v_cmd, fleet.w_cmd = result.v, result.w
        fleet.step(LIMITS, DT)
        trace["pose"].append(np.column_stack([fleet.x, fleet.y, fleet.yaw]))
        trace["v"].append(fleet.v.copy())
        trace["w"].append(fleet.w.copy())
        trace["blocked"].append(result.blocked)
        trace["wall"].append([_distance_to_segments(p, segments) - RADIUS for p in fleet.positions])
        pos = fleet.positions
        pair = np.hypot(pos[:, None, 0] - pos[None, :, 0], pos[:, None, 1] - pos[None, :, 1])
        trace["gap"].append((pair + np.eye(n) * 1e9).min() - 2 * RADIUS)
    return {key: np.array(value) for key, value in trace.items()}


def test_a_robot_in_open_space_speeds_up_to_full_speed_towards_a_carrot_ahead():
    trace = _simulate([(0.0, 0.0, 0.0)], [(20.0, 0.0)], NO_SEGMENTS, 1.5)
    assert np.allclose(trace["v"][:5, 0], [0.2, 0.4, 0.6, 0.8, 1.0])
    assert np.all(trace["v"][5:, 0] == LIMITS.max_speed_mps)
    assert np.all(trace["w"] == 0.0) and np.all(trace["pose"][:, 0, 1] == 0.0)


def test_a_robot_turns_on_the_spot_towards_a_carrot_behind():
    trace = _simulate([(0.0, 0.0, 0.0)], [(-4.0, 0.1)], NO_SEGMENTS, 4.0)
    pose = trace["pose"][:, 0]
    bearing_error = np.abs(
        wrap_angles(np.arctan2(0.1 - pose[:, 1], -4.0 - pose[:, 0]) - pose[:, 2])
    )
    facing_away = bearing_error > math.pi / 2
    assert facing_away[0] and not facing_away[-1]
    assert np.hypot(pose[facing_away, 0], pose[facing_away, 1]).max() < 0.05
    assert bearing_error[-1] < 0.3


def test_a_robot_slows_and_stops_before_a_wall_between_it_and_its_goal():
    wall = np.array([[3.0, -5.0, 3.0, 5.0]])
    trace = _simulate([(0.0, 0.0, 0.0)], [(5.0, 0.0)], wall, 10.0)
    assert trace["v"].max() > 0.9  # it got going
    assert trace["wall"].min() > 0.0  # never touched
    assert trace["wall"].min() >= PARAMS.safety_margin_m - 0.01
    assert np.all(trace["v"][-20:] == 0.0)


def test_every_command_keeps_the_footprint_beyond_the_margin_along_its_arc():
    checked = []

    def check(poses, velocities, points, start, result):
        for i in range(len(poses)):
            own = points[start[i] : start[i + 1]]
            if result.v[i] == 0.0 or len(own) == 0:
                continue
            c0 = np.hypot(*(own - poses[i, :2]).T).min() - RADIUS
            t = PARAMS.sim_time_s * np.arange(1, PARAMS.sim_steps + 1) / PARAMS.sim_steps
            x, y, _ = integrate(poses[i, 0], poses[i, 1], poses[i, 2], result.v[i], result.w[i], t)
            arc = np.column_stack([x, y])
            clearance = np.hypot(*(arc[:, None] - own[None]).transpose(2, 0, 1)).min() - RADIUS
            assert clearance >= min(PARAMS.safety_margin_m, c0) - 1e-9
            checked.append(clearance)

    wall = np.array([[3.0, -5.0, 3.0, 5.0], [-1.0, 0.9, 6.0, 0.9]])
    _simulate([(0.0, 0.0, 0.3)], [(5.0, 0.5)], wall, 10.0, on_command=check)
    assert len(checked) > 20


def test_robots_meeting_head_on_in_a_1_6_m_corridor_never_touch():
    trace = _simulate(
        [(0.0, 0.0, 0.0), (6.0, 0.0, math.pi)], [(8.0, 0.0), (-2.0, 0.0)], _corridor(1.6), 10.0
    )
    assert trace["gap"].min() > 0.0
    assert trace["wall"].min() > 0.0


@pytest.mark.parametrize(("width", "offset"), [(3.2, 0.0), (3.2, 0.2), (2.4, 0.1)])
def test_robots_meeting_head_on_with_room_to_pass_pass_without_touching(width, offset):
    trace = _simulate(
        [(0.0, -offset, 0.0), (6.0, offset, math.pi)],
        [(8.0, -offset), (-2.0, offset)],
        _corridor(width),
        10.0,
    )
    assert trace["gap"].min() > 0.0
    assert trace["wall"].min() > 0.0
    final = trace["pose"][-1]
    assert final[0, 0] > 7.0 and final[1, 0] < -1.0  # both got past each other


def test_a_robot_drives_a_1_6_m_aisle_at_full_speed():
    trace = _simulate([(0.0, 0.0, 0.0)], [(11.0, 0.0)], _corridor(1.6), 5.0)
    assert trace["v"][-20:].min() == LIMITS.max_speed_mps
    assert trace["wall"].min() > 0.4


def test_commands_stay_within_the_dynamic_window_and_the_limits():
    rng = np.random.default_rng(3)
    spec = WarehouseSpec(size_m=(12.0, 12.0), shelf_count=4, robot_count=12, placement="random")
    world = generate_warehouse(spec, rng)
    starts = world.starts
    fleet = FleetState([f"r{i}" for i in range(12)], starts, RADIUS)
    points, start = _scan(StaticScene(world.segments()), fleet)
    for _ in range(20):
        v0 = rng.uniform(0.0, LIMITS.max_speed_mps, 12)
        w0 = rng.uniform(-LIMITS.max_yaw_rate_radps, LIMITS.max_yaw_rate_radps, 12)
        carrots = starts[:, :2] + rng.uniform(-3.0, 3.0, (12, 2))
        result = _call(starts, np.column_stack([v0, w0]), carrots, carrots, points, start)
        tol = 1e-12
        assert np.all(np.abs(result.v - v0) <= LIMITS.max_accel_mps2 * DT + tol)
        assert np.all(np.abs(result.w - w0) <= LIMITS.max_yaw_accel_radps2 * DT + tol)
        assert np.all((result.v >= 0.0) & (result.v <= LIMITS.max_speed_mps))
        assert np.all(np.abs(result.w) <= LIMITS.max_yaw_rate_radps)


def _ring(radius_m, count=72, centre=(0.0, 0.0)):
    angle = 2 * math.pi * np.arange(count) / count
    return np.column_stack([np.cos(angle), np.sin(angle)]) * radius_m + np.asarray(centre)


def test_a_boxed_in_robot_is_blocked_and_may_only_turn_on_the_spot():
    ring = _ring(RADIUS + 0.12)
    aside = _call((0.0, 0.0, 0.0), (0.0, 0.0), (1.0, 1.5), (1.0, 1.5), ring)
    assert aside.blocked[0] and aside.v[0] == 0.0
    assert aside.w[0] == pytest.approx(LIMITS.max_yaw_accel_radps2 * DT)  # turning left
    ahead = _call((0.0, 0.0, 0.0), (0.0, 0.0), (3.0, 0.0), (3.0, 0.0), ring)
    assert ahead.blocked[0] and ahead.v[0] == 0.0 and ahead.w[0] == 0.0
    assert ahead.best_clearance_m[0] == pytest.approx(0.12)


def test_an_overlapping_robot_is_blocked_and_does_not_move():
    result = _call((0.0, 0.0, 0.0), (0.0, 0.5), (3.0, 0.5), (3.0, 0.5), _ring(RADIUS - 0.05))
    assert result.blocked[0] and result.v[0] == 0.0
    assert result.w[0] == pytest.approx(0.2)  # yaw rate brought down as fast as allowed


def test_a_robot_too_fast_to_stop_brakes_along_its_arc():
    wall = np.column_stack([np.full(41, 0.6), np.linspace(-2.0, 2.0, 41)])
    result = _call((0.0, 0.0, 0.0), (1.0, 0.5), (5.0, 0.0), (5.0, 0.0), wall)
    assert result.blocked[0]
    assert result.v[0] == pytest.approx(0.8) and result.w[0] == pytest.approx(0.4)


def test_a_robot_slows_onto_its_goal_without_overshooting():
    trace = _simulate([(0.0, 0.0, 0.0)], [(3.0, 0.0)], NO_SEGMENTS, 10.0)
    x = trace["pose"][:, 0, 0]
    assert np.all(np.diff(x) >= 0.0) and x.max() <= 3.0
    assert 3.0 - x[-1] < 0.01 and trace["v"][-1, 0] < 0.01


def test_a_goal_near_a_wall_is_reached():
    wall = np.array([[-5.0, 0.0, 10.0, 0.0]])
    goal = (2.0, RADIUS + 0.3)
    trace = _simulate([(-3.0, 2.0, 0.0)], [goal], wall, 10.0)
    assert np.hypot(*(trace["pose"][-1, 0, :2] - goal)) < 0.05
    assert trace["wall"].min() > 0.2


def test_a_disc_is_avoided_like_the_points_on_its_edge():
    disc = np.array([[1.2, 0.1, 0.33]])
    edge = _ring(0.33, count=720, centre=(1.2, 0.1))
    for velocity in [(0.0, 0.0), (0.6, 0.0), (1.0, 0.3)]:
        as_disc = _call((0.0, 0.0, 0.0), velocity, (5.0, 0.0), (5.0, 0.0), [], discs=disc)
        as_points = _call((0.0, 0.0, 0.0), velocity, (5.0, 0.0), (5.0, 0.0), edge)
        assert as_disc.v[0] == as_points.v[0] and as_disc.w[0] == as_points.w[0]
        assert as_disc.blocked[0] == as_points.blocked[0]
        assert as_disc.best_clearance_m[0] == pytest.approx(as_points.best_clearance_m[0], abs=1e-3)


def test_results_are_deterministic_and_do_not_depend_on_the_rest_of_the_batch():
    rng = np.random.default_rng(7)
    spec = WarehouseSpec(size_m=(12.0, 12.0), shelf_count=4, robot_count=10, placement="random")
    world = generate_warehouse(spec, rng)
    fleet = FleetState([f"r{i}" for i in range(10)], world.starts, RADIUS)
    points, start = _scan(StaticScene(world.segments()), fleet)
    velocities = np.column_stack([rng.uniform(0, 1, 10), rng.uniform(-1, 1, 10)])
    carrots = world.starts[:, :2] + rng.uniform(-2.0, 2.0, (10, 2))
    first = _call(world.starts, velocities, carrots, carrots, points, start)
    again = _call(world.starts, velocities, carrots, carrots, points, start)
    for a, b in zip(first, again, strict=True):
        assert np.array_equal(a, b)
    for i in range(10):
        alone = _call(
            world.starts[i], velocities[i], carrots[i], carrots[i], points[start[i] : start[i + 1]]
        )
        assert alone.v[0] == first.v[i] and alone.w[0] == first.w[i]
        assert alone.blocked[0] == first.blocked[i]


def test_invalid_parameters_and_inputs_are_rejected():
    with pytest.raises(ModelError) as steps:
        DwaParams(sim_steps=0)
    assert steps.value.key == "navigation.sim_steps" and steps.value.value == 0
    with pytest.raises(ModelError) as cap:
        DwaParams(clearance_cap_m=0.0)
    assert cap.value.key == "navigation.clearance_cap_m"
    with pytest.raises(ValueError, match="obstacle_start"):
        _call((0.0, 0.0, 0.0), (0.0, 0.0), (1.0, 0.0), (1.0, 0.0), [[1.0, 1.0]], np.array([0, 2]))
    with pytest.raises(ValueError, match="velocities"):
        _call((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (1.0, 0.0), (1.0, 0.0), [])


def _cut_at(edges):
    """A ``slices`` function that cuts the robots at ``edges`` (sorted, within the count)."""

    def slices(count, rows):
        bounds = [0, *[e for e in edges if 0 < e < count], count]
        for start, stop in itertools.pairwise(bounds):
            rows(start, stop)

    return slices


@pytest.mark.parametrize("edges", [[], [1], [5], [3, 4, 9], list(range(1, 10))])
def test_commands_are_the_same_whatever_the_robots_are_cut_into(edges):
    rng = np.random.default_rng(11)
    spec = WarehouseSpec(size_m=(12.0, 12.0), shelf_count=4, robot_count=10, placement="random")
    world = generate_warehouse(spec, rng)
    fleet = FleetState([f"r{i}" for i in range(10)], world.starts, RADIUS)
    points, start = _scan(StaticScene(world.segments()), fleet)
    velocities = np.column_stack([rng.uniform(0, 1, 10), rng.uniform(-1, 1, 10)])
    carrots = world.starts[:, :2] + rng.uniform(-2.0, 2.0, (10, 2))
    # robot i hears of robot i + 1 (the last of the first)
    discs = np.column_stack([np.roll(world.starts[:, :2], -1, axis=0), np.full(10, RADIUS)])
    disc_start = np.arange(11, dtype=np.int64)
    args = (world.starts, velocities, LIMITS, np.full(10, RADIUS), carrots, carrots)
    whole = dwa_batch(*args, points, start, discs, disc_start, PARAMS)
    cut = dwa_batch(*args, points, start, discs, disc_start, PARAMS, _cut_at(edges))
    for a, b in zip(whole, cut, strict=True):
        assert np.array_equal(a, b)
