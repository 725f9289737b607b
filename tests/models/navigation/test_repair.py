import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from models.errors import ModelError
from models.geometry.occupancy import OCCUPIED, OccupancyGrid
from models.navigation.costmap import INSCRIBED, CostmapParams, StaticCostmap, with_obstacles
from models.navigation.planner import path_to_world, plan, prune_path
from models.navigation.repair import RepairParams, repair_path, split_ahead

RES = 0.1
PARAMS = CostmapParams(robot_radius_m=0.2, inflation_radius_m=0.6)


def _hall(width_cells=300, height_cells=80, boxes=()):
    data = np.zeros((height_cells, width_cells), dtype=np.int8)
    data[0, :] = data[-1, :] = data[:, 0] = data[:, -1] = OCCUPIED
    for x0, y0, x1, y1 in boxes:
        data[y0 : y1 + 1, x0 : x1 + 1] = OCCUPIED
    return StaticCostmap.from_grid(OccupancyGrid(RES, (0.0, 0.0), data), PARAMS)


def _straight_path(static, start, goal):
    result = plan(static.cost, static.world_to_cell(start), static.world_to_cell(goal))
    waypoints = path_to_world(static, prune_path(static.cost, result.cells))
    waypoints[-1] = goal
    return waypoints


def _clear_of(cost, static, waypoints):
    """Whether every cell along the waypoints' segments is below the inscribed cost."""
    for a, b in itertools.pairwise(waypoints):
        for f in np.linspace(0.0, 1.0, 200):
            ix, iy = static.world_to_cell(a + f * (b - a))
            if cost[iy, ix] >= INSCRIBED:
                return False
    return True


@settings(max_examples=60, deadline=None)
@given(
    st.integers(0, 250),
    st.integers(0, 60),
    st.integers(1, 50),
    st.integers(1, 20),
    st.lists(st.tuples(st.floats(-1, 31), st.floats(-1, 9)), max_size=12),
    st.lists(st.tuples(st.floats(0, 30), st.floats(0, 8), st.floats(0.05, 0.5)), max_size=4),
)
def test_a_window_of_the_stamped_costs_equals_the_same_part_of_the_whole_grid(
    ix0, iy0, w, h, points, discs
):
    static = _hall()
    window = (ix0, iy0, min(ix0 + w, static.width), min(iy0 + h, static.height))
    pts = np.array(points, dtype=float).reshape(-1, 2)
    dsc = np.array(discs, dtype=float).reshape(-1, 3)
    whole = with_obstacles(static, pts, discs=dsc)
    part = with_obstacles(static, pts, discs=dsc, window=window)
    assert np.array_equal(part, whole[window[1] : window[3], window[0] : window[2]])


def test_a_window_outside_the_grid_is_refused_naming_it():
    static = _hall()
    with pytest.raises(ModelError, match="window"):
        with_obstacles(static, np.zeros((0, 2)), window=(0, 0, static.width + 1, 10))


def test_a_path_is_cut_the_given_distance_along_from_the_robots_projection():
    waypoints = np.array([[0.0, 0.0], [4.0, 0.0], [4.0, 10.0]])
    stretch, rest = split_ahead(waypoints, 0, np.array([1.0, 0.5]), 5.0)
    assert np.allclose(stretch, [[1.0, 0.0], [4.0, 0.0], [4.0, 2.0]])
    assert np.allclose(rest, [[4.0, 2.0], [4.0, 10.0]])
    _, tail = split_ahead(waypoints, 1, np.array([4.0, 9.0]), 5.0)
    assert np.allclose(tail, [[4.0, 10.0]])  # the path ends within reach: its end


def test_a_repair_goes_round_a_robot_on_the_path_and_keeps_the_rest_of_the_path():
    static = _hall()
    old = _straight_path(static, (2.0, 4.0), (28.0, 4.0))
    robot_ahead = np.array([[5.0, 4.0, 0.35]])
    repaired = repair_path(
        static, np.zeros((0, 2)), robot_ahead, old, 0, np.array([2.0, 4.0]), RepairParams()
    )
    assert repaired is not None
    cost = with_obstacles(static, np.zeros((0, 2)), discs=robot_ahead)
    assert _clear_of(cost, static, repaired.waypoints)
    # the stretch beyond the cut (8 m along) is the old path's
    assert np.allclose(repaired.waypoints[-1], old[-1])
    assert repaired.waypoints[:, 0].max() <= 28.0
    ix0, _, ix1, _ = repaired.window
    assert (ix1 - ix0) * RES < 8.0 + 2 * 3.0 + 0.2  # only the stretch ahead was searched
    segments = np.diff(repaired.waypoints, axis=0)
    assert (np.hypot(*segments.T) > 0).all()  # no repeated points
    expected = np.hypot(*segments.T).sum()
    assert repaired.length_m == pytest.approx(expected)


def test_a_repair_from_where_the_robot_stands_adds_no_repeated_points():
    static = _hall()
    path = _straight_path(static, (2.0, 4.0), (28.0, 4.0))
    for _ in range(5):
        repaired = repair_path(
            static, np.zeros((0, 2)), None, path, 0, np.array([2.0, 4.0]), RepairParams()
        )
        assert repaired is not None
        path = repaired.waypoints
    assert (np.hypot(*np.diff(path, axis=0).T) > 0).all()
    assert len(path) <= 4


def test_no_repair_when_the_way_ahead_is_closed_within_the_window():
    # a wall across the hall 5 m ahead, open only at y > 6 m, 3.5 m beyond the window
    static = _hall(boxes=[(70, 0, 72, 60)])
    old = np.array([[2.0, 2.0], [28.0, 2.0]])  # the path before the wall was there
    params = RepairParams(ahead_m=8.0, margin_m=0.5)
    start = np.array([2.0, 2.0])
    assert repair_path(static, np.zeros((0, 2)), None, old, 0, start, params) is None
    cells = (static.world_to_cell(start), static.world_to_cell((28.0, 2.0)))
    assert plan(static.cost, *cells).found  # a full replan finds the way round


def test_repair_params_refuse_a_reach_that_is_not_a_positive_distance():
    with pytest.raises(ModelError, match=r"repair\.ahead_m"):
        RepairParams(ahead_m=0.0)
    with pytest.raises(ModelError, match=r"repair\.margin_m"):
        RepairParams(margin_m=float("nan"))


def test_a_plan_to_a_blocked_goal_fails_without_searching():
    static = _hall()
    cost = with_obstacles(static, np.array([[25.0, 4.0]]))
    result = plan(cost, static.world_to_cell((2.0, 4.0)), static.world_to_cell((25.0, 4.0)))
    assert not result.found
    assert result.expansions == 0
