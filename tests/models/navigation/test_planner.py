import itertools
import math

import numpy as np
import pytest
from scipy.sparse.csgraph import dijkstra

from models.errors import ModelError
from models.geometry.occupancy import OCCUPIED, OccupancyGrid
from models.navigation.costmap import (
    INSCRIBED,
    LETHAL,
    CostmapParams,
    StaticCostmap,
    with_obstacles,
)
from models.navigation.planner import (
    GoalStatus,
    goal_status,
    path_to_world,
    plan,
    prune_path,
    reachable,
    shortest_path_length_m,
)
from models.world.warehouse import WarehouseSpec, generate_warehouse, ground_truth_grid
from tests.models.navigation.grid_graph import planner_graph

RES = 0.1
PARAMS = CostmapParams(robot_radius_m=0.2, inflation_radius_m=0.6)


def _static(rows, res=RES, params=PARAMS):
    """A static costmap from ASCII rows, top row = highest y; '#' occupied."""
    data = np.array([[OCCUPIED if ch == "#" else 0 for ch in row] for row in rows[::-1]])
    grid = OccupancyGrid(resolution_m=res, origin_xy_m=(0.0, 0.0), data=data.astype(np.int8))
    return StaticCostmap.from_grid(grid, params)


def _box_room(width, height, boxes=()):
    """A walled room of width x height cells with extra '#' boxes (x0, y0, x1, y1) inclusive."""
    data = np.zeros((height, width), dtype=np.int8)
    data[0, :] = data[-1, :] = data[:, 0] = data[:, -1] = OCCUPIED
    for x0, y0, x1, y1 in boxes:
        data[y0 : y1 + 1, x0 : x1 + 1] = OCCUPIED
    grid = OccupancyGrid(resolution_m=RES, origin_xy_m=(0.0, 0.0), data=data)
    return StaticCostmap.from_grid(grid, PARAMS)


def _reference_cost(cost, start, goal, weight, lethal=INSCRIBED):
    """Dijkstra (scipy) on the same directed 8-connected graph: cost in cells or inf."""
    w = cost.shape[1]
    graph = planner_graph(cost, weight, lethal=lethal)
    dist = dijkstra(graph, directed=True, indices=start[1] * w + start[0])
    return dist[goal[1] * w + goal[0]]


def _path_cost(cost, cells, weight):
    total = 0.0
    for (x0, y0), (x1, y1) in itertools.pairwise(cells.tolist()):
        step = math.sqrt(2.0) if x0 != x1 and y0 != y1 else 1.0
        total += step * (1.0 + weight * cost[y1, x1] / 252.0)
    return total


def _assert_valid_path(cost, cells, start, goal, lethal=INSCRIBED):
    assert tuple(cells[0]) == tuple(start)
    assert tuple(cells[-1]) == tuple(goal)
    assert (cost[cells[:, 1], cells[:, 0]] < lethal).all()
    if len(cells) == 1:
        return
    steps = np.abs(np.diff(cells, axis=0))
    assert steps.max() == 1
    assert (steps.sum(axis=1) > 0).all()


def test_a_straight_corridor_gives_the_straight_path_of_exactly_n_cells():
    cost = np.full((5, 40), LETHAL, dtype=np.uint8)
    cost[2, :] = 0
    result = plan(cost, (0, 2), (39, 2), resolution_m=RES)
    assert result.found
    assert result.cells.tolist() == [[x, 2] for x in range(40)]
    assert result.length_m == 39 * RES
    assert result.cost_m == pytest.approx(39 * RES)


def test_a_goal_in_the_start_cell_is_a_path_of_one_cell():
    cost = np.zeros((4, 4), dtype=np.uint8)
    result = plan(cost, (1, 2), (1, 2), resolution_m=RES)
    assert result.found
    assert result.cells.tolist() == [[1, 2]]
    assert (result.length_m, result.cost_m, result.expansions) == (0.0, 0.0, 1)


def test_an_l_shaped_corridor_is_followed_round_its_corner():
    cost = np.full((20, 20), LETHAL, dtype=np.uint8)
    cost[2, 2:15] = 0  # along x ...
    cost[2:18, 14] = 0  # ... then up along y
    result = plan(cost, (2, 2), (14, 17), resolution_m=RES)
    assert result.found
    _assert_valid_path(cost, result.cells, (2, 2), (14, 17))
    assert result.length_m == pytest.approx((12 + 15) * RES)
    assert [14, 2] in result.cells.tolist()


def test_a_diagonal_move_never_cuts_between_two_lethal_cells():
    cost = np.zeros((2, 2), dtype=np.uint8)
    cost[0, 1] = cost[1, 0] = LETHAL
    assert not plan(cost, (0, 0), (1, 1)).found
    # one lethal corner is enough to forbid the diagonal: the path goes round it
    cost = np.zeros((3, 3), dtype=np.uint8)
    cost[1, 2] = LETHAL
    result = plan(cost, (1, 1), (2, 2))
    assert result.cells.tolist() == [[1, 1], [1, 2], [2, 2]]
    assert result.length_m == 2.0


def test_goals_inside_a_box_off_the_map_or_in_the_open_get_their_status():
    static = _box_room(40, 30, boxes=[(15, 10, 25, 20)])
    assert goal_status(static, (2.0, 1.5)) == GoalStatus.IN_OBSTACLE == "in_obstacle"
    assert goal_status(static, (1.45, 1.5)) == "in_obstacle"  # 0.05 m from the box: inscribed
    assert goal_status(static, (0.15, 1.5)) == "in_obstacle"  # touching the wall
    assert goal_status(static, (5.0, 1.5)) == "outside"
    assert goal_status(static, (-0.01, 1.5)) == "outside"
    assert goal_status(static, (0.8, 1.5)) == GoalStatus.OK == "ok"


def test_an_enclosed_goal_is_not_found_and_not_reachable():
    # a closed ring of shelves around (3.05, 2.05) with room inside
    ring = [(20, 10, 40, 11), (20, 29, 40, 30), (20, 10, 21, 30), (39, 10, 40, 30)]
    static = _box_room(60, 40, boxes=ring)
    start, goal = (0.8, 2.0), (3.05, 2.05)
    assert goal_status(static, goal) == "ok"
    result = plan(static.cost, static.world_to_cell(start), static.world_to_cell(goal))
    assert not result.found
    assert result.cells.shape == (0, 2)
    assert result.length_m == math.inf
    assert not reachable(static, start, goal)
    assert shortest_path_length_m(static, start, goal) == math.inf
    assert reachable(static, start, (5.3, 2.0))


def test_lidar_points_blocking_a_corridor_make_the_plan_detour_or_fail():
    # a shelf in the middle of the room leaves a corridor below and one above it
    static = _box_room(80, 40, boxes=[(30, 12, 50, 27)])
    start, goal = static.world_to_cell((1.0, 2.0)), static.world_to_cell((7.0, 2.0))
    lower = [[4.0, y] for y in np.arange(0.0, 1.25, 0.05)]
    upper = [[4.0, y] for y in np.arange(2.75, 4.0, 0.05)]
    free = plan(static.cost, start, goal, resolution_m=RES)
    went_up = free.cells[:, 1].max() > 27
    blocked_one = with_obstacles(static, np.array(upper if went_up else lower))
    detour = plan(blocked_one, start, goal, resolution_m=RES)
    assert free.found and detour.found
    assert (detour.cells[:, 1].max() > 27) != went_up  # the other corridor
    assert detour.length_m >= free.length_m
    blocked = with_obstacles(static, np.array(lower + upper))
    assert not plan(blocked, start, goal).found


def test_a_robot_starting_inside_the_inscribed_zone_still_plans_out():
    static = _box_room(40, 30, boxes=[(15, 10, 25, 20)])
    start = static.world_to_cell((1.42, 1.5))  # 0.07 m from the box: touching it
    goal = static.world_to_cell((0.7, 1.5))
    assert static.cost[start[1], start[0]] == INSCRIBED
    result = plan(static.cost, start, goal, resolution_m=RES)
    assert result.found
    costs = static.cost[result.cells[:, 1], result.cells[:, 0]]
    first_free = int(np.argmax(costs < INSCRIBED))
    assert first_free <= 2  # the way out is the shortest one
    assert (costs[first_free:] < INSCRIBED).all()  # and the path never goes back in


def test_the_escape_from_a_blocked_start_never_crosses_an_obstacle():
    # a one-cell wall across the room with a gap at the top; start touching it on the left
    static = _box_room(41, 40, boxes=[(20, 0, 20, 30)])
    start, goal = (18, 10), (23, 10)
    assert static.cost[10, 18] == INSCRIBED
    assert static.cost[10, 23] < INSCRIBED
    result = plan(static.cost, start, goal, cost_weight=0.0, resolution_m=RES)
    assert result.found
    assert result.cells[:, 1].max() >= 31  # round the top of the wall
    assert (result.cells[result.cells[:, 0] == 20, 1] > 30).all()


def test_a_robot_whose_cell_holds_a_lidar_point_still_plans_out():
    static = _box_room(40, 30)
    cost = with_obstacles(static, np.array([[2.05, 1.55]]))  # in the robot's own cell
    start = static.world_to_cell((2.05, 1.55))
    assert cost[start[1], start[0]] == LETHAL
    result = plan(cost, start, (35, 15), resolution_m=RES)
    assert result.found
    assert (cost[result.cells[3:, 1], result.cells[3:, 0]] < INSCRIBED).all()


def test_a_start_in_an_obstacle_cell_with_nothing_free_is_not_found():
    cost = np.full((5, 5), LETHAL, dtype=np.uint8)
    result = plan(cost, (2, 2), (0, 0))
    assert not result.found
    assert result.expansions == 0


def test_the_cost_weight_keeps_the_path_away_from_walls_when_there_is_room():
    # a 4 m x 3 m room with a shelf in the middle; the shortest way grazes its corner
    static = _box_room(40, 30, boxes=[(15, 8, 25, 21)])
    start, goal = (5, 5), (35, 25)
    shortest = plan(static.cost, start, goal, cost_weight=0.0, resolution_m=RES)
    careful = plan(static.cost, start, goal, cost_weight=3.0, resolution_m=RES)
    clearance = static.distance_m
    near = clearance[shortest.cells[:, 1], shortest.cells[:, 0]].min()
    far = clearance[careful.cells[:, 1], careful.cells[:, 0]].min()
    assert far > near + 0.1
    assert careful.length_m > shortest.length_m
    # each is optimal for its own weight
    assert _path_cost(static.cost, careful.cells, 3.0) < _path_cost(
        static.cost, shortest.cells, 3.0
    )


@pytest.mark.parametrize("seed", range(6))
def test_a_star_finds_the_least_cost_of_a_reference_dijkstra_on_random_grids(seed):
    rng = np.random.default_rng(seed)
    h, w = int(rng.integers(8, 20)), int(rng.integers(8, 20))
    cost = rng.integers(0, 253, size=(h, w)).astype(np.uint8)
    cost[rng.random((h, w)) < 0.25] = LETHAL
    cost[rng.random((h, w)) < 0.05] = INSCRIBED
    free = np.argwhere(cost < INSCRIBED)
    for weight in (0.0, 1.0, 4.0):
        for _ in range(4):
            (sy, sx), (gy, gx) = free[rng.choice(len(free), size=2, replace=False)]
            result = plan(cost, (sx, sy), (gx, gy), cost_weight=weight)
            want = _reference_cost(cost, (sx, sy), (gx, gy), weight)
            assert result.found == math.isfinite(want)
            if result.found:
                _assert_valid_path(cost, result.cells, (sx, sy), (gx, gy))
                assert result.cost_m == pytest.approx(want, rel=1e-12)
                assert _path_cost(cost, result.cells, weight) == pytest.approx(want, rel=1e-12)


def test_a_star_across_an_open_floor_closes_only_the_cells_of_its_path():
    # octile is exact here, and thousands of paths tie; the deepest entry must win the tie
    # (it did not while the last bits of differently summed equal costs ordered the heap)
    cost = np.zeros((150, 200), dtype=np.uint8)
    for weight in (0.0, 1.0):
        result = plan(cost, (3, 4), (190, 120), cost_weight=weight)
        assert result.expansions == len(result.cells) == 188


def test_the_same_input_gives_the_same_path():
    rng = np.random.default_rng(11)
    cost = rng.integers(0, 200, size=(60, 60)).astype(np.uint8)
    cost[rng.random((60, 60)) < 0.2] = LETHAL
    cost[0, 0] = cost[59, 59] = 0
    first = plan(cost, (0, 0), (59, 59), resolution_m=0.05)
    plan(cost, (59, 0), (0, 59))  # an unrelated plan in between leaves no trace
    again = plan(cost.copy(), (0, 0), (59, 59), resolution_m=0.05)
    assert np.array_equal(first.cells, again.cells)
    assert (first.length_m, first.cost_m, first.expansions) == (
        again.length_m,
        again.cost_m,
        again.expansions,
    )


def test_cells_off_the_grid_and_negative_weights_are_rejected():
    cost = np.zeros((4, 4), dtype=np.uint8)
    with pytest.raises(ModelError) as err:
        plan(cost, (4, 0), (0, 0))
    assert err.value.key == "start_cell"
    with pytest.raises(ModelError):
        plan(cost, (0, 0), (0, -1))
    with pytest.raises(ModelError):
        plan(cost, (0, 0), (1, 1), cost_weight=-1.0)


def test_pruning_keeps_the_ends_and_only_clear_straight_segments():
    static = _box_room(40, 30, boxes=[(15, 8, 25, 21)])
    result = plan(static.cost, (5, 5), (35, 25), resolution_m=RES)
    waypoints = prune_path(static.cost, result.cells)
    assert 2 < len(waypoints) < len(result.cells) / 4
    assert waypoints[0].tolist() == [5, 5] and waypoints[-1].tolist() == [35, 25]
    index = {tuple(c): i for i, c in enumerate(result.cells.tolist())}
    order = [index[tuple(c)] for c in waypoints.tolist()]
    assert order == sorted(order)  # a subsequence of the path
    for (ax, ay), (bx, by), i, j in zip(
        waypoints[:-1], waypoints[1:], order[:-1], order[1:], strict=True
    ):
        worst = static.cost[result.cells[i : j + 1, 1], result.cells[i : j + 1, 0]].max()
        for t in np.linspace(0.0, 1.0, 200):
            x, y = ax + 0.5 + t * (bx - ax), ay + 0.5 + t * (by - ay)
            assert static.cost[int(y), int(x)] <= worst


def test_pruning_a_straight_path_leaves_its_two_ends():
    cost = np.zeros((10, 10), dtype=np.uint8)
    cells = np.array([[i, i] for i in range(10)])
    assert prune_path(cost, cells).tolist() == [[0, 0], [9, 9]]
    assert prune_path(cost, cells[:2]).tolist() == [[0, 0], [1, 1]]


def test_path_cells_become_cell_centres_in_the_map_frame():
    static = _static(["....", "...."])
    points = path_to_world(static, np.array([[0, 0], [3, 1]]))
    assert points == pytest.approx(np.array([[0.05, 0.05], [0.35, 0.15]]))


def test_the_shortest_path_length_in_open_space_is_the_straight_distance():
    static = _box_room(60, 40)
    assert shortest_path_length_m(static, (1.0, 1.0), (4.03, 2.52)) == pytest.approx(
        math.hypot(3.03, 1.52)
    )


def test_the_shortest_path_length_around_a_shelf_is_close_to_the_true_one():
    static = _box_room(60, 40, boxes=[(29, 0, 31, 30)])  # a wall with a gap at the top
    start, goal = (1.0, 1.0), (5.0, 1.0)
    length = shortest_path_length_m(static, start, goal)
    # the centre must pass above y = 3.1 + 0.2 (wall top + robot radius) at x = 3.0
    corner = (3.0, 3.1 + 0.2)
    true = 2 * math.hypot(corner[0] - 1.0, corner[1] - 1.0)
    assert true <= length <= true * 1.05
    grid_length = plan(
        static.cost,
        static.world_to_cell(start),
        static.world_to_cell(goal),
        cost_weight=0.0,
        resolution_m=RES,
    ).length_m
    assert length < grid_length


def test_every_robot_start_of_a_generated_warehouse_reaches_every_other():
    spec = WarehouseSpec(
        size_m=(12.0, 12.0), layout="all_rows", shelf_count=6, robot_count=4, placement="random"
    )
    world = generate_warehouse(spec, np.random.default_rng(3))
    static = StaticCostmap.from_grid(
        ground_truth_grid(world, RES), CostmapParams(robot_radius_m=spec.robot_radius_m)
    )
    starts = world.starts[:, :2]
    for a in starts:
        for b in starts:
            assert goal_status(static, b) == "ok"
            assert reachable(static, a, b)
            length = shortest_path_length_m(static, a, b)
            assert math.hypot(*(b - a)) - 1e-9 <= length < 3 * math.hypot(*(b - a)) + 1e-9
