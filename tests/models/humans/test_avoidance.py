import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from models.humans.avoidance import (
    MARGIN_M,
    free_distance,
    room,
    safe_step,
    speed_limit,
    step_aside,
)

R = 0.25
ROBOT = np.array([[5.0, 0.0, 0.33]])


def walk_towards(robot, *, steps, dt=0.1, v0=1.2, start=(0.0, 0.0), yaw=0.0):
    """A walker heading ``yaw`` paced by the model, moving straight at the allowed speed."""
    xy = np.array([start], dtype=float)
    heading = np.array([np.cos(yaw), np.sin(yaw)])
    speeds = []
    for _ in range(steps):
        radii = np.array([R])
        limit = speed_limit(
            free_distance(xy, np.array([yaw]), radii, robot),
            np.array([v0]),
            room_m=room(xy, np.array([yaw]), radii, robot),
            step_s=dt,
        )
        speeds.append(float(limit[0]))
        xy = xy + limit[0] * dt * heading
    return xy[0], speeds


def test_a_person_walking_at_a_standing_robot_stops_short_of_it_and_never_touches_it():
    final, speeds = walk_towards(ROBOT, steps=200)
    gap = 5.0 - final[0] - R - 0.33
    assert MARGIN_M <= gap < MARGIN_M + 0.01  # waits at the margin, never closer
    assert speeds[0] == pytest.approx(1.2)  # far away: walks at their own speed
    assert speeds[-1] == pytest.approx(0.0, abs=1e-3)


def test_speed_falls_with_the_free_distance_as_in_the_collision_free_speed_model():
    free = np.array([np.inf, 2.0, 0.6, 0.0, -1.0])
    v = speed_limit(free, np.full(5, 1.3), time_gap_s=1.0)
    assert v.tolist() == pytest.approx([1.3, 1.3, 0.6, 0.0, 0.0])


def test_a_robot_beside_the_corridor_or_behind_leaves_the_walker_free():
    xy = np.array([[0.0, 0.0], [0.0, 0.0]])
    robots = np.array([[3.0, 1.2, 0.33], [-1.0, 0.0, 0.33]])
    free = free_distance(xy, np.array([0.0, 0.0]), np.full(2, R), robots)
    assert np.isinf(free).all()
    # straight at it: the corridor is the person's disc swept ahead, not a centre line
    grazing = free_distance(xy[:1], np.array([0.0]), np.array([R]), np.array([[3.0, 0.6, 0.33]]))
    assert grazing[0] == pytest.approx(3.0 - np.sqrt((R + 0.33 + MARGIN_M) ** 2 - 0.36))


def test_a_walker_next_to_a_robot_may_walk_away_but_not_closer():
    start = np.array([[0.0, 0.0], [0.0, 0.0]])
    robots = np.array([[0.0, 0.6, 0.33]])  # 0.02 m from the person: inside the margin
    proposed = np.array([[0.0, -0.1], [0.0, 0.1]])
    allowed, cut = safe_step(start, proposed, np.full(2, R), robots)
    assert allowed[0].tolist() == pytest.approx([0.0, -0.1])
    assert allowed[1].tolist() == pytest.approx([0.0, 0.0])
    assert cut.tolist() == [False, True]
    facing_away = room(start, np.array([-np.pi / 2]), np.array([R]), robots)
    assert np.isinf(facing_away[0])


@settings(max_examples=200, deadline=None)
@given(
    st.floats(-3.0, 3.0),
    st.floats(-3.0, 3.0),
    st.floats(-0.4, 0.4),
    st.floats(-0.4, 0.4),
    st.floats(0.1, 0.6),
)
def test_a_cut_step_never_ends_within_the_margin_of_a_robot(x, y, dx, dy, robot_r):
    robots = np.array([[0.0, 0.0, robot_r], [1.0, 0.5, 0.33]])
    start = np.array([[x, y]])
    reach = R + robots[:, 2] + MARGIN_M
    before = np.hypot(x - robots[:, 0], y - robots[:, 1]) - reach
    allowed, _ = safe_step(start, start + np.array([[dx, dy]]), np.array([R]), robots)
    after = np.hypot(allowed[0, 0] - robots[:, 0], allowed[0, 1] - robots[:, 1]) - reach
    # clear stays clear (up to rounding); closer than the margin never gets closer
    assert (after >= np.minimum(before, 0.0) - 1e-9).all()


@settings(max_examples=100, deadline=None)
@given(st.floats(0.0, 20.0), st.floats(0.0, 3.0), st.floats(-np.pi, np.pi))
def test_speeds_stay_between_zero_and_the_walkers_own(distance, v0, yaw):
    xy = np.array([[0.0, 0.0]])
    robots = np.array([[distance * np.cos(yaw), distance * np.sin(yaw), 0.33]])
    v = speed_limit(
        free_distance(xy, np.array([0.0]), np.array([R]), robots),
        np.array([v0]),
        room_m=room(xy, np.array([0.0]), np.array([R]), robots),
    )
    assert 0.0 <= v[0] <= v0


def test_someone_appearing_inside_a_robot_steps_out_to_the_margin():
    xy, moved = step_aside(np.array([[5.1, 0.0], [9.0, 0.0]]), np.full(2, R), ROBOT)
    assert moved.tolist() == [True, False]
    assert np.hypot(*(xy[0] - ROBOT[0, :2])) == pytest.approx(R + 0.33 + MARGIN_M)
    assert xy[1].tolist() == [9.0, 0.0]


def test_the_same_inputs_give_the_same_speeds_and_steps():
    rng = np.random.default_rng(4)
    xy = rng.uniform(0, 10, (50, 2))
    yaw = rng.uniform(-np.pi, np.pi, 50)
    robots = np.column_stack([rng.uniform(0, 10, (6, 2)), np.full(6, 0.33)])
    runs = [
        (
            free_distance(xy, yaw, np.full(50, R), robots),
            safe_step(xy, xy + 0.1, np.full(50, R), robots)[0],
        )
        for _ in range(2)
    ]
    assert np.array_equal(runs[0][0], runs[1][0])
    assert np.array_equal(runs[0][1], runs[1][1])
