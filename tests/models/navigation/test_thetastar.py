"""Theta*: any-angle paths, cost-aware line of sight, lanes, escapes, windowed repairs."""

import itertools
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from models.errors import ModelError
from models.geometry.occupancy import OCCUPIED, OccupancyGrid
from models.navigation.costmap import INSCRIBED, LETHAL, CostmapParams, StaticCostmap
from models.navigation.lanes import EAST, TWO_WAY, WEST
from models.navigation.planner import path_to_world, plan, prune_path
from models.navigation.repair import RepairParams
from models.navigation.thetastar import (
    NO_LANES,
    Terrain,
    _heap_pop_py,
    _heap_push_py,
    _segment_py,
    repair_theta,
    theta_star,
)

RES = 0.1
PARAMS = CostmapParams(robot_radius_m=0.2, inflation_radius_m=0.6)


def _room(width, height, boxes=()):
    """A walled room of width x height cells with '#' boxes (x0, y0, x1, y1) inclusive."""
    data = np.zeros((height, width), dtype=np.int8)
    data[0, :] = data[-1, :] = data[:, 0] = data[:, -1] = OCCUPIED
    for x0, y0, x1, y1 in boxes:
        data[y0 : y1 + 1, x0 : x1 + 1] = OCCUPIED
    return StaticCostmap.from_grid(OccupancyGrid(RES, (0.0, 0.0), data), PARAMS)


def _touched(a, b):
    """Every cell the segment between two cell centres passes through or touches (fine steps)."""
    cells = set()
    for t in np.linspace(0.0, 1.0, 4000):
        x, y = a[0] + t * (b[0] - a[0]) + 0.5, a[1] + t * (b[1] - a[1]) + 0.5
        for ex, ey in itertools.product((-1e-6, 1e-6), repeat=2):
            cells.add((math.floor(x + ex), math.floor(y + ey)))
    return cells


def _polyline_m(cells):
    return float(np.hypot(*np.diff(cells.astype(float), axis=0).T).sum()) * RES


def test_a_goal_in_plain_sight_is_reached_by_one_straight_segment():
    static = _room(60, 40)
    result = theta_star(static.cost, (8, 8), (50, 31), resolution_m=RES)
    assert result.found
    assert result.cells.tolist() == [[8, 8], [50, 31]]
    assert result.length_m == pytest.approx(math.hypot(42, 23) * RES)


def test_the_any_angle_path_round_an_obstacle_is_no_longer_than_astars():
    static = _room(80, 60, boxes=[(30, 15, 45, 45)])
    start, goal = (10, 30), (70, 33)
    theta = theta_star(static.cost, start, goal, cost_weight=0.0, resolution_m=RES)
    astar = plan(static.cost, start, goal, cost_weight=0.0, resolution_m=RES)
    assert theta.found and astar.found
    assert len(theta.cells) == 4  # bends only at the box's two corners
    assert theta.length_m < astar.length_m  # shorter than the 8-connected path ...
    pruned = prune_path(static.cost, astar.cells, keep_clearance=False)
    assert theta.length_m <= _polyline_m(pruned) + 1e-9  # ... and than its shortcuts
    assert theta.length_m > 6.5  # round the box, not through it


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 10_000), st.floats(0.0, 3.0))
def test_no_segment_of_a_path_crosses_or_corner_cuts_a_blocked_cell(seed, weight):
    rng = np.random.default_rng(seed)
    cost = rng.choice(np.array([0, 40, 120, 252, 253, 254], dtype=np.uint8), size=(24, 24))
    cost[rng.random((24, 24)) < 0.5] = 0
    free = np.argwhere(cost < INSCRIBED)
    start, goal = (tuple(int(v) for v in free[i][::-1]) for i in rng.integers(len(free), size=2))
    result = theta_star(cost, start, goal, cost_weight=weight)
    astar = plan(cost, start, goal, cost_weight=weight)
    assert result.found == astar.found  # the same cells are reachable
    for a, b in itertools.pairwise(result.cells.tolist()):
        assert all(cost[y, x] < INSCRIBED for x, y in _touched(a, b))


def _seen(cost, a, b, lanes=NO_LANES, against=1.0, budget=math.inf):
    """Theta*'s cost of the segment from cell a to cell b at cost weight 1 (-1: none)."""
    terrain = Terrain(cost, lanes, 1.0 / 252, INSCRIBED, 0, a[0], a[1], against)
    return _segment_py(terrain, *a, *b, budget)


def test_the_line_of_sight_refuses_a_diagonal_between_two_blocked_cells():
    cost = np.zeros((3, 3), dtype=np.uint8)
    cost[0, 1] = cost[1, 0] = LETHAL
    assert _seen(cost, (0, 0), (1, 1)) == _seen(cost, (0, 0), (2, 2)) == -1.0
    cost[0, 1] = 0  # one open side is still a corner cut, as A*'s diagonal steps forbid
    assert _seen(cost, (0, 0), (1, 1)) == -1.0
    assert theta_star(cost, (0, 0), (1, 1)).cells.tolist() == [[0, 0], [1, 0], [1, 1]]


def test_a_segment_costs_the_integral_of_the_cost_factor_along_it():
    cost = np.zeros((1, 5), dtype=np.uint8)
    cost[0, 1:5] = [0, 126, 252, 0]
    seen = _seen(cost, (0, 0), (4, 0))
    assert seen == pytest.approx(0.5 * 1.0 + 1.0 + 1.5 + 2.0 + 0.5 * 1.0)  # half cells at ends
    assert _seen(cost, (0, 0), (2, 0)) + _seen(cost, (2, 0), (4, 0)) == pytest.approx(seen)
    lanes = np.full((1, 5), WEST, dtype=np.uint8)
    assert _seen(cost, (0, 0), (4, 0), lanes, against=5.0) == pytest.approx(5.0 * seen)
    assert _seen(cost, (4, 0), (0, 0), lanes, against=5.0) == pytest.approx(seen)  # with it
    assert _seen(cost, (0, 0), (4, 0), budget=seen - 0.01) == -1.0  # stops past its budget
    assert _seen(cost, (0, 0), (4, 0), budget=seen) == pytest.approx(seen)


def test_the_path_keeps_off_costly_cells_when_the_weight_asks_it():
    cost = np.zeros((30, 60), dtype=np.uint8)
    cost[5:25, 20:40] = 200  # a costly but enterable patch in the way
    plain = theta_star(cost, (5, 15), (55, 15), cost_weight=0.0)
    careful = theta_star(cost, (5, 15), (55, 15), cost_weight=5.0)
    assert plain.cells.tolist() == [[5, 15], [55, 15]]
    assert plain.cost_m == pytest.approx(plain.length_m)
    assert careful.length_m > plain.length_m
    assert not any(20 <= x < 40 and 5 <= y < 25 for x, y in careful.cells.tolist()[1:-1])


def test_an_enclosed_goal_has_no_path_and_a_blocked_one_is_refused_without_searching():
    ring = [(20, 10, 40, 11), (20, 29, 40, 30), (20, 10, 21, 30), (39, 10, 40, 30)]
    static = _room(60, 40, boxes=ring)
    enclosed = theta_star(static.cost, (8, 20), (30, 20))
    assert not enclosed.found and enclosed.length_m == math.inf and enclosed.expansions > 0
    walled = theta_star(static.cost, (8, 20), (30, 10))
    assert not walled.found and walled.expansions == 0


def test_a_robot_in_inscribed_cells_escapes_them_and_plans_on():
    static = _room(60, 40, boxes=[(30, 0, 31, 39)])
    start = (28, 20)  # 0.2 m from the wall: inscribed
    assert static.cost[20, 28] >= INSCRIBED
    result = theta_star(static.cost, start, (5, 20), resolution_m=RES)
    assert result.found
    assert result.cells[0].tolist() == [28, 20] and result.cells[-1].tolist() == [5, 20]


def test_a_lane_against_the_way_is_avoided_when_another_aisle_leads_there():
    static = _room(60, 40, boxes=[(10, 19, 49, 20)])
    lanes = np.full(static.cost.shape, TWO_WAY, dtype=np.uint8)
    lanes[:19, :] = WEST
    lanes[21:, :] = EAST
    plain = theta_star(static.cost, (5, 10), (55, 10))
    laned = theta_star(static.cost, (5, 10), (55, 10), lanes=lanes, against=5.0)
    assert plain.cells[:, 1].max() < 19
    assert laned.cells[:, 1].max() > 20
    with pytest.raises(ModelError, match="lanes"):
        theta_star(static.cost, (5, 10), (55, 10), lanes=lanes[:-1])


def test_the_heap_pops_by_f_then_deepest_first():
    keys, items, size = np.empty(2), np.empty(1, dtype=np.int64), 0
    entries = [(3.0, 1.0, 0), (1.0, 0.5, 1), (2.0, 0.0, 2), (1.0, 0.9, 3), (5.0, 0.0, 4)]
    for f, g, item in entries:
        keys, items, size = _heap_push_py(keys, items, size, f, g, item)
    popped = []
    while size:
        _, _, item, size = _heap_pop_py(keys, items, size)
        popped.append(item)
    assert popped == [3, 1, 2, 0, 4]


def test_a_repair_plans_round_what_blocks_the_stretch_ahead_and_keeps_the_goal():
    static = _room(300, 80)
    waypoints = np.array([[1.0, 4.0], [29.0, 4.0]])
    blocking = np.array([[6.0, y] for y in np.arange(3.0, 5.05, 0.05)])
    repaired = repair_theta(
        static, blocking, None, waypoints, 0, np.array([1.0, 4.0]), RepairParams()
    )
    assert repaired is not None
    assert repaired.waypoints[-1].tolist() == [29.0, 4.0]
    assert repaired.length_m > 28.0  # round, not through
    x0, _, x1, _ = repaired.window
    assert x1 - x0 < 150  # a window round the 8 m ahead, not the hall
    assert np.abs(repaired.waypoints[1:-1, 1] - 4.0).max() > 1.0  # the detour


def test_no_repair_when_the_window_holds_no_way():
    static = _room(300, 80, boxes=[(50, 0, 51, 79)])  # a wall across the whole hall
    waypoints = path_to_world(static, np.array([[10, 40], [290, 40]]))
    assert (
        repair_theta(static, np.zeros((0, 2)), None, waypoints, 0, waypoints[0], RepairParams())
        is None
    )
