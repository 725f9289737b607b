import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
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
from models.navigation.landmarks import (
    UNREACHED,
    LandmarkCache,
    Landmarks,
    build_landmarks,
)
from models.navigation.planner import plan, shortest_path_length_m
from models.world.warehouse import WarehouseSpec, generate_warehouse, ground_truth_grid
from tests.models.navigation.grid_graph import planner_graph

RES = 0.1
PARAMS = CostmapParams(robot_radius_m=0.2, inflation_radius_m=0.6)


def _random_static(seed: int, width: int, height: int, density: float) -> StaticCostmap:
    """Walls round a room with random obstacle cells and a few unknown ones, inflated."""
    rng = np.random.default_rng(seed)
    data = np.zeros((height, width), dtype=np.int8)
    data[rng.random((height, width)) < density] = OCCUPIED
    data[rng.random((height, width)) < 0.02] = -1
    data[0, :] = data[-1, :] = data[:, 0] = data[:, -1] = OCCUPIED
    grid = OccupancyGrid(resolution_m=RES, origin_xy_m=(0.0, 0.0), data=data)
    return StaticCostmap.from_grid(grid, PARAMS)


def _bounds_to(landmarks: Landmarks, goal: tuple[int, int]) -> np.ndarray:
    """The planner's heuristic (cells) from every cell to ``goal``: octile or landmarks."""
    h, w = landmarks.cost.shape
    ys, xs = np.divmod(np.arange(h * w), w)
    dx, dy = np.abs(xs - goal[0]), np.abs(ys - goal[1])
    octile = dx + dy + (math.sqrt(2.0) - 2.0) * np.minimum(dx, dy)
    fields = landmarks.fields.astype(np.int64)
    at_goal = fields[goal[1] * w + goal[0]]
    spread = np.abs(fields - at_goal).max(axis=1, initial=0) * landmarks.scale
    reached = fields[:, 0] != UNREACHED if fields.shape[1] else np.zeros(h * w, bool)
    goal_reached = bool(reached[goal[1] * w + goal[0]]) if fields.shape[1] else False
    bound = np.where(reached & goal_reached, spread, 0.0)
    bound[reached != goal_reached] = np.inf
    return np.maximum(octile, bound)


def _free_pair(rng, cost):
    free = np.argwhere(cost < INSCRIBED)
    (sy, sx), (gy, gx) = free[rng.choice(len(free), size=2, replace=len(free) < 2)]
    return (int(sx), int(sy)), (int(gx), int(gy))


rooms = st.tuples(
    st.integers(0, 10**6),  # seed
    st.integers(6, 40),  # width
    st.integers(6, 40),  # height
    st.floats(0.0, 0.12),  # obstacle density
)


@settings(max_examples=40, deadline=None)
@given(room=rooms, weight=st.sampled_from([0.0, 1.0, 3.0]))
def test_alt_a_star_finds_the_least_cost_that_plain_a_star_and_dijkstra_find(room, weight):
    static = _random_static(*room)
    if not (static.cost < INSCRIBED).any():
        return
    marks = build_landmarks(static.cost, count=4, cost_weight=weight)
    rng = np.random.default_rng(room[0])
    graph = planner_graph(static.cost, weight)
    width = static.width
    for _ in range(3):
        start, goal = _free_pair(rng, static.cost)
        alt = plan(static.cost, start, goal, cost_weight=weight, landmarks=marks)
        plain = plan(static.cost, start, goal, cost_weight=weight)
        want = dijkstra(graph, indices=start[1] * width + start[0])[goal[1] * width + goal[0]]
        assert alt.found == plain.found == math.isfinite(want)
        if alt.found:
            assert alt.cost_m == pytest.approx(want, rel=1e-12)
            assert plain.cost_m == pytest.approx(want, rel=1e-12)
            assert alt.cells[0].tolist() == list(start) and alt.cells[-1].tolist() == list(goal)


@settings(max_examples=30, deadline=None)
@given(
    room=rooms,
    points=st.integers(0, 6),
    discs=st.integers(0, 3),
    lanes_on=st.booleans(),
    against=st.floats(1.0, 6.0),
)
def test_alt_a_star_stays_exact_with_obstacles_stamped_and_lanes_laid_after_the_build(
    room, points, discs, lanes_on, against
):
    static = _random_static(*room)
    if not (static.cost < INSCRIBED).any():
        return
    marks = build_landmarks(static.cost, count=4, cost_weight=1.0)
    rng = np.random.default_rng(room[0] + 1)
    size = np.array([static.width, static.height]) * RES
    seen = rng.random((points, 2)) * size
    robots = np.column_stack([rng.random((discs, 2)) * size, np.full(discs, 0.25)])
    cost = with_obstacles(static, seen, discs=robots)
    lanes = rng.integers(0, 5, size=cost.shape).astype(np.uint8) if lanes_on else None
    graph = planner_graph(cost, 1.0, lanes, against)
    for _ in range(3 if (cost < INSCRIBED).any() else 0):
        start, goal = _free_pair(rng, cost)  # enterable despite the stamps
        alt = plan(cost, start, goal, landmarks=marks, lanes=lanes, against=against)
        plain = plan(cost, start, goal, lanes=lanes, against=against)
        want = dijkstra(graph, indices=start[1] * cost.shape[1] + start[0])
        want_goal = want[goal[1] * cost.shape[1] + goal[0]]
        assert alt.found == plain.found == math.isfinite(want_goal)
        if alt.found:
            assert alt.cost_m == pytest.approx(want_goal, rel=1e-12)
            assert plain.cost_m == pytest.approx(alt.cost_m, rel=1e-12)


@settings(max_examples=30, deadline=None)
@given(room=rooms, weight=st.sampled_from([0.0, 1.0, 2.5]))
def test_the_heuristic_never_exceeds_the_cost_to_go_and_is_consistent(room, weight):
    static = _random_static(*room)
    if not (static.cost < INSCRIBED).any():
        return
    marks = build_landmarks(static.cost, count=6, cost_weight=weight)
    rng = np.random.default_rng(room[0] + 2)
    _, goal = _free_pair(rng, static.cost)
    graph = planner_graph(static.cost, weight)
    width = static.width
    to_goal = dijkstra(graph.T.tocsr(), indices=goal[1] * width + goal[0])  # cost-to-go
    h = _bounds_to(marks, goal)
    enterable = (static.cost < INSCRIBED).ravel()
    assert (h[enterable] <= to_goal[enterable] + 1e-9).all()
    # an infinite bound only where the goal cannot be reached, and then for every cell
    assert (np.isinf(h[enterable]) <= np.isinf(to_goal[enterable])).all()
    edges = graph.tocoo()
    finite = np.isfinite(h[edges.row]) & np.isfinite(h[edges.col])
    assert (h[edges.row] <= edges.data + h[edges.col] + 1e-9)[finite].all()
    assert h[goal[1] * width + goal[0]] == 0.0


def _warehouse() -> StaticCostmap:
    spec = WarehouseSpec(layout="all_rows", shelf_count=72, robot_count=10)
    world = generate_warehouse(spec, np.random.default_rng(3))
    return StaticCostmap.from_grid(ground_truth_grid(world, RES), CostmapParams(0.33))


def test_landmarks_make_a_star_expand_far_fewer_cells_on_a_warehouse_floor():
    static = _warehouse()
    rng = np.random.default_rng(5)
    for weight in (0.0, 1.0):
        marks = build_landmarks(static.cost, cost_weight=weight)
        with_marks = without = 0
        for _ in range(20):
            start, goal = _free_pair(rng, static.cost)
            alt = plan(static.cost, start, goal, cost_weight=weight, landmarks=marks)
            plain = plan(static.cost, start, goal, cost_weight=weight)
            assert alt.found and plain.found
            assert alt.cost_m == pytest.approx(plain.cost_m, rel=1e-12)
            with_marks += alt.expansions
            without += plain.expansions
        assert with_marks < 0.7 * without


def test_the_yardstick_with_landmarks_prunes_a_grid_path_of_the_same_length():
    static = _warehouse()
    marks = build_landmarks(static.cost, cost_weight=0.0)
    rng = np.random.default_rng(8)
    for _ in range(10):
        cells = _free_pair(rng, static.cost)
        start, goal = (static.cell_to_world(c) for c in cells)
        grid = plan(static.cost, *cells, cost_weight=0.0, resolution_m=RES)
        fast = shortest_path_length_m(static, start, goal, landmarks=marks)
        slow = shortest_path_length_m(static, start, goal)
        # another grid path of the same length may prune to another length, never beyond
        # the grid path's or below the straight line
        straight = math.dist(start, goal)
        for length in (fast, slow):
            assert straight - 1e-9 <= length <= grid.length_m + 1e-9


def test_a_goal_walled_off_from_the_start_is_found_unreachable_without_a_search():
    data = np.zeros((40, 60), dtype=np.int8)
    data[0, :] = data[-1, :] = data[:, 0] = data[:, -1] = OCCUPIED
    data[10:30, 20] = data[10:30, 40] = data[10, 20:41] = data[29, 20:41] = OCCUPIED  # a box
    static = StaticCostmap.from_grid(OccupancyGrid(RES, (0.0, 0.0), data), PARAMS)
    marks = build_landmarks(static.cost, count=4)
    start, inside = (5, 5), (30, 20)
    assert static.cost[20, 30] < INSCRIBED
    assert math.isinf(marks.lower_bound(start, inside))
    alt = plan(static.cost, start, inside, landmarks=marks)
    plain = plan(static.cost, start, inside)
    assert not alt.found and not plain.found
    assert alt.expansions == 1  # the start: every neighbour is cut off from the goal
    assert plain.expansions > 1000  # the whole outer room
    # and the other way round, from inside the box, where no landmark reaches
    back = plan(static.cost, inside, start, landmarks=marks)
    assert not back.found and back.expansions == 1


def test_a_start_touching_a_shelf_still_plans_its_least_cost_way_out():
    data = np.zeros((30, 40), dtype=np.int8)
    data[0, :] = data[-1, :] = data[:, 0] = data[:, -1] = OCCUPIED
    data[10:21, 15:26] = OCCUPIED
    static = StaticCostmap.from_grid(OccupancyGrid(RES, (0.0, 0.0), data), PARAMS)
    marks = build_landmarks(static.cost, count=4)
    start = static.world_to_cell((1.42, 1.5))  # inscribed: the escape rule applies
    assert static.cost[start[1], start[0]] == INSCRIBED
    # and one in the open with a lidar point in its own cell: blocked by that alone
    seen = with_obstacles(static, np.array([[3.05, 0.85]]))
    in_open = static.world_to_cell((3.05, 0.85))
    assert seen[in_open[1], in_open[0]] == LETHAL
    for cost, begin in ((static.cost, start), (seen, in_open)):
        for goal in [(5, 5), (35, 25), (20, 25)]:
            alt = plan(cost, begin, goal, landmarks=marks)
            plain = plan(cost, begin, goal)
            assert alt.found and plain.found
            assert alt.cost_m == pytest.approx(plain.cost_m, rel=1e-12)


def test_landmarks_are_built_the_same_every_time_and_lie_on_the_largest_free_region():
    static = _warehouse()
    first = build_landmarks(static.cost, count=6)
    again = build_landmarks(static.cost.copy(), count=6)
    assert np.array_equal(first.cells, again.cells)
    assert np.array_equal(first.fields, again.fields)
    assert first.shift == again.shift
    assert first.fields.shape == (static.cost.size, 6)
    assert first.nbytes == static.cost.size * 6 * 4
    for ix, iy in first.cells.tolist():
        assert static.cost[iy, ix] < INSCRIBED
    assert len({tuple(c) for c in first.cells.tolist()}) == 6
    # the farthest-point choice puts the first landmarks at the ends of the floor
    corner_gap = np.abs(first.cells[:2] - first.cells[:2][::-1]).max()
    assert corner_gap > 0.8 * max(static.width, static.height)


def test_a_map_without_free_cells_gives_no_landmarks_and_plans_as_without():
    cost = np.full((5, 5), LETHAL, dtype=np.uint8)
    marks = build_landmarks(cost)
    assert marks.fields.shape == (25, 0) and len(marks.cells) == 0
    assert not plan(cost, (2, 2), (0, 0), landmarks=marks).found


def test_the_cache_builds_each_weight_once_on_first_use():
    static = _warehouse()
    cache = LandmarkCache(static, count=3)
    first = cache.get(1.0)
    assert cache.get(1.0) is first
    assert cache.get(0.0) is not first and cache.get(0.0).cost_weight == 0.0
    assert first.fields.shape[1] == 3


def _refused(call, *args, **kwargs) -> ModelError:
    with pytest.raises(ModelError) as err:
        call(*args, **kwargs)
    return err.value


def test_bad_landmark_requests_are_refused_naming_the_value():
    cost = np.zeros((8, 8), dtype=np.uint8)
    error = _refused(build_landmarks, cost, count=0)
    assert (error.key, error.value) == ("count", 0)
    assert "from 1 to 16" in error.expected
    assert _refused(build_landmarks, cost, count=17).value == 17
    error = _refused(build_landmarks, cost, cost_weight=-1.0)
    assert (error.key, error.value) == ("cost_weight", -1.0)
    assert _refused(build_landmarks, cost, lethal=0).key == "lethal"
    assert _refused(build_landmarks, np.zeros(8, dtype=np.uint8)).value == (8,)


def test_plans_refuse_landmarks_that_do_not_bound_their_costs():
    static = _warehouse()
    marks = build_landmarks(static.cost, count=2, cost_weight=1.0)
    start, goal = (10, 10), (static.width - 10, static.height - 10)
    error = _refused(plan, static.cost[:-1], start, goal, landmarks=marks)
    assert (error.key, error.value) == ("landmarks", static.cost.shape)
    error = _refused(plan, static.cost, start, goal, lethal=LETHAL, landmarks=marks)
    assert (error.key, error.value) == ("lethal", LETHAL)
    error = _refused(plan, static.cost, start, goal, cost_weight=0.0, landmarks=marks)
    assert (error.key, error.value) == ("cost_weight", 0.0)
    assert "at least the landmarks' weight 1" in str(error)
    # a heavier weight only raises every step: allowed, and still the least cost
    heavy = plan(static.cost, start, goal, cost_weight=2.0, landmarks=marks)
    assert heavy.cost_m == pytest.approx(plan(static.cost, start, goal, cost_weight=2.0).cost_m)
    # costs below the layer's (here: the inflated band cleared) are not bounded by it
    lowered = static.cost.copy()
    lowered[(lowered > 0) & (lowered < INSCRIBED)] = 0
    error = _refused(plan, lowered, start, goal, landmarks=marks)
    assert error.key == "cost"
    ix, iy = (int(v) for v in error.value.split("at cell (")[1].rstrip(")").split(", "))
    assert lowered[iy, ix] < static.cost[iy, ix] < INSCRIBED
