import math

import numpy as np
import pytest

from models.errors import ModelError
from models.fleet.kinematics import DriveLimits, FleetState
from models.navigation.orca import OrcaParams, orca_batch, orca_half_plane
from models.sensing.raycast import StaticScene, cast_batch

LIMITS = DriveLimits(1.0, 0.3, 2.0, 2.0, 3.0)
RADIUS = 0.33
PARAMS = OrcaParams()
DT = PARAMS.control_period_s
BEAMS = -math.pi + 2 * math.pi / 360 * np.arange(360)
NO_HITS = np.zeros((0, 2))
NO_SEGMENTS = np.zeros((0, 4))


def _corridor(width, x0=-3.0, x1=12.0):
    h = width / 2
    return np.array([[x0, -h, x1, -h], [x0, h, x1, h]])


def _scan(scene, fleet, keep_m=3.0):
    """Every robot's lidar hits within keep_m (walls and the other robots), CSR by robot."""
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


def _call(pose, vel, carrot, goal=None, hits=NO_HITS, heard=None, params=PARAMS):
    """One robot; ``heard`` rows ``x, y, vx, vy, age_s`` of the robots it heard of."""
    heard = np.zeros((0, 5)) if heard is None else np.atleast_2d(np.asarray(heard, dtype=float))
    discs = np.column_stack([heard[:, :2], np.full(len(heard), RADIUS)])
    hits = np.asarray(hits, dtype=float).reshape(-1, 2)
    return orca_batch(
        np.array([pose], dtype=float),
        np.array([vel], dtype=float),
        LIMITS,
        np.array([RADIUS]),
        np.array([carrot], dtype=float),
        np.array([carrot if goal is None else goal], dtype=float),
        hits,
        np.array([0, len(hits)], dtype=np.int64),
        discs,
        heard,
        np.array([0, len(heard)], dtype=np.int64),
        params,
    )


def _simulate(
    starts, goals, seconds, segments=NO_SEGMENTS, delay_ticks=0, params=PARAMS, lidar=True
):
    """Closed loop of the whole fleet: scan, hear the others ``delay_ticks`` late, command, step."""
    n = len(starts)
    fleet = FleetState([f"r{i}" for i in range(n)], np.array(starts, dtype=float), RADIUS)
    scene, goals = StaticScene(segments), np.array(goals, dtype=float)
    others = np.array([j for i in range(n) for j in range(n) if j != i], dtype=np.int64)
    disc_start = np.arange(n + 1, dtype=np.int64) * (n - 1)
    sent: list[np.ndarray] = []
    trace: dict[str, list[object]] = {
        key: [] for key in ("pose", "v", "w", "blocked", "gap", "wall")
    }
    for _ in range(round(seconds / DT)):
        hits, start = _scan(scene, fleet) if lidar else (NO_HITS, np.zeros(n + 1, np.int64))
        sent.append(
            np.column_stack(
                [fleet.x, fleet.y, fleet.v * np.cos(fleet.yaw), fleet.v * np.sin(fleet.yaw)]
            )
        )
        heard = sent[max(len(sent) - 1 - delay_ticks, 0)][others]
        age = np.full((len(others), 1), DT * min(delay_ticks, len(sent) - 1))
        result = orca_batch(
            np.column_stack([fleet.x, fleet.y, fleet.yaw]),
            np.column_stack([fleet.v, fleet.w]),
            LIMITS,
            fleet.radius_m,
            goals,
            goals,
            hits,
            start,
            np.column_stack([heard[:, :2], np.full(len(others), RADIUS)]),
            np.column_stack([heard, age]),
            disc_start,
            params,
        )
        fleet.v_cmd, fleet.w_cmd = result.v, result.w
        fleet.step(LIMITS, DT)
        pos = fleet.positions
        pair = np.hypot(pos[:, None, 0] - pos[None, :, 0], pos[:, None, 1] - pos[None, :, 1])
        trace["pose"].append(np.column_stack([fleet.x, fleet.y, fleet.yaw]))
        trace["v"].append(result.v)
        trace["w"].append(result.w)
        trace["blocked"].append(result.blocked)
        trace["gap"].append((pair + np.eye(n) * 1e9).min() - 2 * RADIUS)
        trace["wall"].append(
            min((abs(abs(y) - abs(s[1])) for s in segments for y in fleet.y), default=np.inf)
            - RADIUS
        )
    return {key: np.array(value) for key, value in trace.items()}


def test_the_half_plane_of_a_head_on_encounter_turns_the_robot_to_its_right():
    # 4 m apart, closing at 2 m/s, radii 1 m together, 2 s horizon: the relative velocity
    # is inside the cone, nearest its right leg at sin(half angle) * |v| = 0.25 * 2 m/s
    u, direction = orca_half_plane(np.array([4.0, 0.0]), np.array([2.0, 0.0]), 1.0, 2.0, 0.1)
    root = math.sqrt(15.0)
    np.testing.assert_allclose(u, [-1.0 / 8.0, -root / 8.0], atol=1e-12)
    np.testing.assert_allclose(direction, [-root / 4.0, 0.25], atol=1e-12)
    assert np.hypot(*u) == pytest.approx(0.5)
    # the allowed side is left of the line through v + u / 2: going straight on is not
    point = np.array([1.0, 0.0]) + 0.5 * u
    for velocity, allowed in (([1.0, 0.0], False), ([1.0, -1.0], True), ([1.0, 1.0], False)):
        side = direction[0] * (point[1] - velocity[1]) - direction[1] * (point[0] - velocity[0])
        assert (side <= 0.0) == allowed


def test_a_relative_velocity_clear_of_the_cut_off_disc_is_left_as_it_is():
    # 5 m apart at 2 m/s: within 2 s the gap closes to 1 m, more than the radii's 0.5 m
    # so the relative velocity may still grow by 0.25 m/s: 2.25 m/s closes 4.5 m in 2 s
    u, _ = orca_half_plane(np.array([5.0, 0.0]), np.array([2.0, 0.0]), 0.5, 2.0, 0.1)
    np.testing.assert_allclose(u, [0.25, 0.0], atol=1e-12)


def test_robots_overlapping_already_are_pushed_apart_within_one_control_period():
    u, _ = orca_half_plane(np.array([0.5, 0.0]), np.array([0.0, 0.0]), 0.66, 2.0, 0.1)
    np.testing.assert_allclose(u, [-(0.66 - 0.5) / 0.1, 0.0], atol=1e-12)


def test_two_robots_head_on_in_the_open_pass_each_other_without_contact():
    trace = _simulate([(0.0, 0.0, 0.0), (8.0, 0.0, math.pi)], [(10.0, 0.0), (-2.0, 0.0)], 14.0)
    assert trace["gap"].min() > 2 * PARAMS.margin_m - 0.02  # the margins kept, nearly
    final = trace["pose"][-1]
    assert final[0, 0] > 9.5 and final[1, 0] < -1.5  # both got past each other
    # each passed the other on its own right: robot 0 (heading +x) below, robot 1 above
    closest = np.argmin(trace["gap"])
    assert trace["pose"][closest][0, 1] < trace["pose"][closest][1, 1]


def test_two_robots_crossing_at_right_angles_pass_keeping_their_margins():
    starts, goals = [(0.0, 0.0, 0.0), (4.0, -4.0, math.pi / 2)], [(8.0, 0.0), (4.0, 4.0)]
    trace = _simulate(starts, goals, 14.0)
    assert trace["gap"].min() > 2 * PARAMS.margin_m - 0.02
    assert np.hypot(*(trace["pose"][-1][:, :2] - goals).T).max() < 0.1


def test_three_robots_meeting_exactly_symmetrically_stall_apart_and_say_they_are_blocked():
    # every pair meets exactly head-on: ORCA only slows them (a known limit of the method);
    # they stop short of each other and report it, and the navigation's recovery takes over
    angles = np.arange(3) * 2 * math.pi / 3
    starts = [(4 * math.cos(a), 4 * math.sin(a), a + math.pi) for a in angles]
    goals = [(-4 * math.cos(a), -4 * math.sin(a)) for a in angles]
    trace = _simulate(starts, goals, 25.0)
    assert trace["gap"].min() > 2 * PARAMS.margin_m
    assert trace["blocked"][-1].all()
    assert (trace["v"][-1] == 0.0).all()


def test_with_news_a_second_old_extrapolation_keeps_a_crossing_clear():
    # robot 1 crosses robot 0's way; each hears of the other 1 s late and sees no lidar
    starts, goals = [(0.0, 0.0, 0.0), (4.0, -4.0, math.pi / 2)], [(8.0, 0.0), (4.0, 4.0)]
    late = _simulate(starts, goals, 14.0, delay_ticks=10, lidar=False)
    assert late["gap"].min() > 2 * PARAMS.margin_m
    blind = OrcaParams(extrapolate=False)  # avoiding each other where they were: contact
    assert (
        _simulate(starts, goals, 14.0, delay_ticks=10, lidar=False, params=blind)["gap"].min() < 0.0
    )


def test_a_robot_keeps_out_of_a_static_hit_on_its_way_and_still_arrives():
    hit = np.array([3.0, 0.02])
    fleet = FleetState(["r"], np.array([[0.0, 0.0, 0.0]]), RADIUS)
    nearest = np.inf
    for _ in range(100):
        result = _call(
            (fleet.x[0], fleet.y[0], fleet.yaw[0]), (fleet.v[0], fleet.w[0]), (6.0, 0.0), hits=[hit]
        )
        fleet.v_cmd, fleet.w_cmd = result.v, result.w
        fleet.step(LIMITS, DT)
        nearest = min(nearest, float(np.hypot(fleet.x[0] - hit[0], fleet.y[0] - hit[1])))
    assert nearest > RADIUS + PARAMS.margin_m - 0.05
    assert np.hypot(fleet.x[0] - 6.0, fleet.y[0]) < 0.2


def test_a_robot_drives_a_1_6_m_aisle_at_full_speed():
    trace = _simulate([(0.0, 0.0, 0.0)], [(11.0, 0.0)], 5.0, segments=_corridor(1.6))
    assert trace["v"][-15:].min() == LIMITS.max_speed_mps
    assert trace["wall"].min() > 0.4


def test_a_robot_stops_before_a_wall_across_its_way():
    wall = [[2.0, y] for y in np.arange(-1.0, 1.05, 0.05)]
    fleet = FleetState(["r"], np.array([[0.0, 0.0, 0.0]]), RADIUS)
    for _ in range(60):
        result = _call(
            (fleet.x[0], fleet.y[0], fleet.yaw[0]), (fleet.v[0], fleet.w[0]), (5.0, 0.0), hits=wall
        )
        fleet.v_cmd, fleet.w_cmd = result.v, result.w
        fleet.step(LIMITS, DT)
        assert 2.0 - fleet.x[0] > RADIUS
    assert 2.0 - fleet.x[0] < RADIUS + PARAMS.margin_m + 0.1  # it came up to its margin


def test_news_of_a_robot_coming_closer_is_avoided_where_it_is_now_not_where_it_was():
    # heard 2 s ago 5 m ahead driving at us at 1 m/s: it is 3 m ahead now
    heard = [[5.0, 0.0, -1.0, 0.0, 2.0]]
    fresh = _call((0.0, 0.0, 0.0), (1.0, 0.0), (10.0, 0.0), heard=[[5.0, 0.0, -1.0, 0.0, 0.0]])
    aged = _call((0.0, 0.0, 0.0), (1.0, 0.0), (10.0, 0.0), heard=heard)
    blind = _call(
        (0.0, 0.0, 0.0), (1.0, 0.0), (10.0, 0.0), heard=heard, params=OrcaParams(extrapolate=False)
    )
    np.testing.assert_allclose(fresh.velocity, [[1.0, 0.0]], atol=1e-12)
    np.testing.assert_array_equal(blind.velocity, fresh.velocity)
    assert aged.velocity[0, 1] < -0.1  # it gives way to its right
    assert aged.w[0] < 0.0


def test_hits_on_a_heard_robot_are_left_to_the_reciprocal_constraint():
    heard = [[1.5, 0.2, -1.0, 0.0, 0.0]]
    edge = [[1.5 - RADIUS * math.cos(a), 0.2 + RADIUS * math.sin(a)] for a in (-0.3, 0.0, 0.3)]
    alone = _call((0.0, 0.0, 0.0), (1.0, 0.0), (10.0, 0.0), heard=heard)
    seen = _call((0.0, 0.0, 0.0), (1.0, 0.0), (10.0, 0.0), heard=heard, hits=edge)
    np.testing.assert_array_equal(seen.velocity, alone.velocity)
    static = _call((0.0, 0.0, 0.0), (1.0, 0.0), (10.0, 0.0), hits=edge)
    assert not np.array_equal(static.velocity, alone.velocity)


def test_a_robot_turns_on_the_spot_towards_a_carrot_behind():
    result = _call((0.0, 0.0, 0.0), (0.0, 0.0), (-3.0, 0.5))
    assert result.v[0] == 0.0
    assert result.w[0] == LIMITS.max_yaw_rate_radps
    assert not result.blocked[0]


def test_a_robot_slows_onto_its_goal():
    far = _call((0.0, 0.0, 0.0), (1.0, 0.0), (3.0, 0.0))
    near = _call((0.0, 0.0, 0.0), (0.4, 0.0), (0.4, 0.0))
    assert far.v[0] == pytest.approx(1.0)
    assert near.v[0] == pytest.approx(PARAMS.arrive_gain_per_s * 0.4)


def test_a_boxed_in_robot_is_blocked_and_stands():
    ring = [[0.4 * math.cos(a), 0.4 * math.sin(a)] for a in np.linspace(0, 2 * math.pi, 90)]
    result = _call((0.0, 0.0, 0.0), (0.0, 0.0), (3.0, 0.0), hits=ring)
    assert result.blocked.tolist() == [True]
    assert result.v[0] == 0.0


def _crowd(n, seed=7):
    """``n`` robots at random in a 6 m square, each hearing all others, 200 hits in all."""
    rng = np.random.default_rng(seed)
    poses = np.column_stack([rng.uniform(0, 6, (n, 2)), rng.uniform(-math.pi, math.pi, n)])
    vel = np.column_stack([rng.uniform(0, 1, n), rng.uniform(-2, 2, n)])
    heard_of = np.array([j for i in range(n) for j in range(n) if j != i], dtype=np.int64)
    heading = np.column_stack([np.cos(poses[heard_of, 2]), np.sin(poses[heard_of, 2])])
    moving = vel[heard_of, :1] * heading
    return (
        poses,
        vel,
        LIMITS,
        np.full(n, RADIUS),
        rng.uniform(0, 6, (n, 2)),
        rng.uniform(0, 6, (n, 2)),
        rng.uniform(0, 6, (200, 2)),
        np.linspace(0, 200, n + 1).astype(np.int64),
        np.column_stack([poses[heard_of, :2], np.full(len(heard_of), RADIUS)]),
        np.column_stack([poses[heard_of, :2], moving, rng.uniform(0, 1, len(heard_of))]),
        np.arange(n + 1, dtype=np.int64) * (n - 1),
        PARAMS,
    )


def test_commands_stay_within_the_limits_and_never_go_backwards():
    result = orca_batch(*_crowd(40))
    assert np.isfinite(result.v).all() and np.isfinite(result.w).all()
    assert (result.v >= 0).all() and (result.v <= LIMITS.max_speed_mps).all()
    assert (np.abs(result.w) <= LIMITS.max_yaw_rate_radps).all()
    assert (np.hypot(*result.velocity.T) <= LIMITS.max_speed_mps + 1e-9).all()


def test_commands_are_the_same_again_and_whatever_the_robots_are_cut_into():
    def thirds(count, rows):
        for a, b in ((0, 13), (13, 14), (14, count)):
            rows(a, b)

    first, second = orca_batch(*_crowd(40)), orca_batch(*_crowd(40), thirds)
    for a, b in zip(first, second, strict=True):
        np.testing.assert_array_equal(a, b)
    # a robot's command does not depend on the rest of the batch
    single = orca_batch(*_crowd(1))
    assert single.v.shape == (1,)


def test_invalid_parameters_and_inputs_are_refused():
    with pytest.raises(ModelError, match=r"orca\.time_horizon_s"):
        OrcaParams(time_horizon_s=0.0)
    with pytest.raises(ModelError, match=r"orca\.obstacle_sectors"):
        OrcaParams(obstacle_sectors=0)
    with pytest.raises(ModelError, match=r"orca\.margin_m"):
        OrcaParams(margin_m=float("nan"))
    args = list(_crowd(3))
    args[9] = args[9][:-1]
    with pytest.raises(ValueError, match="neighbours must be"):
        orca_batch(*args)
    args = list(_crowd(3))
    args[7] = np.array([0, 5, 2, 200])
    with pytest.raises(ValueError, match="hit_start must rise"):
        orca_batch(*args)
