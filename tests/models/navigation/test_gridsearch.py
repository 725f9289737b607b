"""The planner's kernels: A* on the 8-connected cost grid, the escape disc, line of sight."""

import itertools
import math
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.sparse.csgraph import dijkstra

from models.navigation.costmap import INSCRIBED, LETHAL
from models.navigation.gridsearch import (
    DX,
    DY,
    SQRT2,
    UNREACHED,
    _landmark_bound_py,
    _line_ok_py,
    astar,
    escape_r2,
    prune,
    readonly,
)
from tests.models.navigation.grid_graph import planner_graph

NO_LANES = readonly(np.zeros((0, 0), dtype=np.uint8))
NO_FIELDS = readonly(np.zeros((0, 0), dtype=np.int32))
NO_FLOOR = readonly(np.zeros((0, 0), dtype=np.uint8))


def _astar(cost, start, goal, weight=0.0, lethal=INSCRIBED, escape=0, lanes=NO_LANES, against=1.0):
    grid = readonly(np.ascontiguousarray(cost, dtype=np.uint8))
    fields, floor = NO_FIELDS, NO_FLOOR
    return astar(
        grid, *start, *goal, weight, lethal, escape, DX, DY, lanes, against, fields, 0.0, floor
    )


def _reference(cost, start, goal, weight, lanes=None, against=1.0, lethal=INSCRIBED) -> float:
    graph = planner_graph(cost, weight, lanes, against, lethal)
    w = cost.shape[1]
    return float(dijkstra(graph, indices=start[1] * w + start[0])[goal[1] * w + goal[0]])


def _random_grid(rng, h=14, w=14):
    cost = rng.integers(0, 253, size=(h, w)).astype(np.uint8)
    cost[rng.random((h, w)) < 0.2] = LETHAL
    return cost


def test_a_read_only_view_shares_the_data_and_leaves_the_array_writable():
    array = np.arange(4)
    view = readonly(array)
    assert not view.flags.writeable and array.flags.writeable
    array[0] = 9
    assert view[0] == 9


def test_the_moves_are_four_straight_then_four_diagonal():
    moves = list(zip(DX.tolist(), DY.tolist(), strict=True))
    assert sorted(moves[:4]) == [(-1, 0), (0, -1), (0, 1), (1, 0)]
    assert sorted(moves[4:]) == [(-1, -1), (-1, 1), (1, -1), (1, 1)]
    assert math.sqrt(2.0) == SQRT2


@pytest.mark.parametrize("seed", range(4))
def test_a_star_returns_a_path_its_step_counts_and_the_least_cost(seed):
    rng = np.random.default_rng(seed)
    cost = _random_grid(rng)
    free = np.argwhere(cost < INSCRIBED)
    for weight in (0.0, 2.0):
        for _ in range(5):
            (sy, sx), (gy, gx) = free[rng.choice(len(free), size=2, replace=False)]
            found, cells, straight, diagonal, cost_cells, expansions, below = _astar(
                cost, (sx, sy), (gx, gy), weight
            )
            want = _reference(cost, (sx, sy), (gx, gy), weight)
            assert found == math.isfinite(want) and below == -1 and expansions >= 1
            if not found:
                assert cells.shape == (0, 2) and cost_cells == math.inf
                continue
            assert cost_cells == pytest.approx(want, rel=1e-12)
            assert cells[0].tolist() == [sx, sy] and cells[-1].tolist() == [gx, gy]
            steps = np.abs(np.diff(cells, axis=0))
            assert steps.max() == 1 and (steps.sum(axis=1) > 0).all()
            assert (straight, diagonal) == (
                int((steps.sum(axis=1) == 1).sum()),
                int((steps.sum(axis=1) == 2).sum()),
            )
            if weight == 0.0:
                assert cost_cells == pytest.approx(straight + SQRT2 * diagonal, rel=1e-12)


def test_a_search_of_a_large_open_floor_grows_its_heap_and_stays_optimal():
    rng = np.random.default_rng(3)
    cost = rng.integers(0, 200, size=(70, 70)).astype(np.uint8)
    found, _, _, _, cost_cells, expansions, _ = _astar(cost, (0, 0), (69, 69), weight=4.0)
    assert found and expansions > 1024
    assert cost_cells == pytest.approx(_reference(cost, (0, 0), (69, 69), 4.0), rel=1e-12)


def test_a_step_against_a_lane_costs_the_against_factor_more():
    cost = np.zeros((5, 9), dtype=np.uint8)
    lanes = np.zeros((5, 9), dtype=np.uint8)
    lanes[2, :] = 1  # row 2 runs towards +x: entering it moving -x is against
    ro = readonly(lanes)
    for start, goal in (((8, 2), (0, 2)), ((0, 2), (8, 2)), ((8, 0), (0, 4))):
        got = _astar(cost, start, goal, lanes=ro, against=3.0)[4]
        assert got == pytest.approx(_reference(cost, start, goal, 0.0, lanes, 3.0), rel=1e-12)
    # with the lane the way back along row 2 is a detour round it
    assert _astar(cost, (8, 2), (0, 2), lanes=ro, against=3.0)[4] > 8.0


def test_no_path_to_an_enclosed_goal_is_reported_with_no_cells_and_infinite_cost():
    cost = np.zeros((7, 7), dtype=np.uint8)
    cost[2:5, 2:5] = LETHAL
    cost[3, 3] = 0
    found, cells, straight, diagonal, cost_cells, expansions, _ = _astar(cost, (0, 0), (3, 3))
    assert not found and cells.shape == (0, 2) and (straight, diagonal) == (0, 0)
    assert cost_cells == math.inf and expansions == 7 * 7 - 9


def test_a_diagonal_step_never_passes_between_two_cells_it_may_not_enter():
    cost = np.zeros((2, 2), dtype=np.uint8)
    cost[0, 1] = cost[1, 0] = LETHAL
    assert not _astar(cost, (0, 0), (1, 1))[0]
    cost[1, 0] = 0
    found, cells, *_ = _astar(cost, (0, 0), (1, 1))
    assert found and cells.tolist() == [[0, 0], [0, 1], [1, 1]]


def test_a_blocked_start_plans_out_through_its_escape_disc_only():
    cost = np.zeros((9, 9), dtype=np.uint8)
    cost[2:7, 2:7] = LETHAL  # the robot stands in the middle of an obstacle blob
    start = (4, 4)
    r2 = int(escape_r2(readonly(cost), *start, INSCRIBED))
    assert r2 == 9  # the nearest free cell is 3 cells away, straight
    found, cells, *_ = _astar(cost, start, (0, 0), escape=r2)
    assert found
    blocked = [(x, y) for x, y in cells.tolist() if cost[y, x] >= INSCRIBED]
    assert all((x - 4) ** 2 + (y - 4) ** 2 <= r2 for x, y in blocked)
    assert not _astar(cost, start, (0, 0), escape=0)[0]


def _escape_reference(cost, sx, sy, lethal) -> int:
    free = np.argwhere(cost < lethal)
    if not len(free):
        return -1
    return int(((free[:, 1] - sx) ** 2 + (free[:, 0] - sy) ** 2).min())


@settings(max_examples=60, deadline=None)
@given(
    shape=st.tuples(st.integers(1, 9), st.integers(1, 9)),
    density=st.floats(0.0, 1.0),
    seed=st.integers(0, 2**16),
)
def test_the_escape_is_the_squared_distance_to_the_nearest_enterable_cell(shape, density, seed):
    rng = np.random.default_rng(seed)
    cost = np.where(rng.random(shape) < density, LETHAL, 0).astype(np.uint8)
    sy, sx = int(rng.integers(shape[0])), int(rng.integers(shape[1]))
    got = int(escape_r2(readonly(cost), sx, sy, INSCRIBED))
    assert got == _escape_reference(cost, sx, sy, INSCRIBED)


def _touched(ax, ay, bx, by, h, w) -> set[tuple[int, int]]:
    """Cells whose closed square the segment between two centres meets (exact)."""
    cells = set()
    for y in range(h):
        for x in range(w):
            lo, hi = Fraction(0), Fraction(1)  # Liang-Barsky on the square around (x, y)
            inside = True
            for p, q in (
                (ax - bx, ax - (x - Fraction(1, 2))),
                (bx - ax, (x + Fraction(1, 2)) - ax),
                (ay - by, ay - (y - Fraction(1, 2))),
                (by - ay, (y + Fraction(1, 2)) - ay),
            ):
                if p == 0:
                    inside = inside and q >= 0
                elif p < 0:
                    lo = max(lo, Fraction(q) / p)
                else:
                    hi = min(hi, Fraction(q) / p)
            if inside and lo <= hi:
                cells.add((x, y))
    return cells


@settings(max_examples=80, deadline=None)
@given(
    a=st.tuples(st.integers(0, 7), st.integers(0, 7)),
    b=st.tuples(st.integers(0, 7), st.integers(0, 7)),
    blocked=st.sets(st.tuples(st.integers(0, 7), st.integers(0, 7)), max_size=6),
)
def test_line_of_sight_fails_exactly_when_the_segment_touches_a_dear_cell_beyond_its_start(
    a, b, blocked
):
    cost = np.zeros((8, 8), dtype=np.uint8)
    for x, y in blocked - {a}:
        cost[y, x] = 200
    touched = _touched(*a, *b, 8, 8) - {a}
    assert _line_ok_py(cost, *a, *b, 100) == all(cost[y, x] <= 100 for x, y in touched)


def test_a_line_through_a_corner_touches_both_cells_beside_it():
    cost = np.zeros((3, 3), dtype=np.uint8)
    cost[0, 1] = 200  # beside the corner the diagonal from (0, 0) to (1, 1) passes
    assert not _line_ok_py(cost, 0, 0, 1, 1, 100)
    assert _line_ok_py(cost, 0, 0, 0, 2, 100)


def test_a_landmark_bound_is_the_largest_difference_and_minus_one_when_cut_off():
    fields = np.array([[0, 5, 2], [3, 1, 9], [UNREACHED] * 3], dtype=np.int32)
    goal = np.array([4, 4, 4], dtype=np.int32)
    assert _landmark_bound_py(fields, 0, goal) == 4  # |4 - 0|, |4 - 5|, |4 - 2|
    assert _landmark_bound_py(fields, 1, goal) == 5
    assert _landmark_bound_py(fields, 2, goal) == -1  # the goal is reached, the cell not
    unreached_goal = np.full(3, UNREACHED, dtype=np.int32)
    assert _landmark_bound_py(fields, 2, unreached_goal) == 0
    assert _landmark_bound_py(fields, 0, unreached_goal) == -1


def _prune(cost, cells, keep_clearance=False):
    return prune(
        readonly(np.ascontiguousarray(cost, dtype=np.uint8)),
        readonly(np.asarray(cells, dtype=np.int64)),
        INSCRIBED,
        keep_clearance,
    )


def test_pruning_keeps_the_ends_drops_collinear_cells_and_shortcuts_only_in_sight():
    cost = np.zeros((6, 6), dtype=np.uint8)
    cost[1:5, 2] = LETHAL  # a wall between x = 1 and x = 3
    cells = [(0, 0), (1, 0), (2, 0), (3, 0), (3, 1), (3, 2), (3, 3), (3, 4), (3, 5)]
    pruned = _prune(cost, cells).tolist()
    assert pruned[0] == [0, 0] and pruned[-1] == [3, 5]
    assert [tuple(c) for c in pruned] == [c for c in cells if list(c) in pruned]  # in order
    for (ax, ay), (bx, by) in itertools.pairwise(pruned):
        assert _line_ok_py(cost, ax, ay, bx, by, INSCRIBED - 1)
    straight = [(x, 0) for x in range(6)]
    assert _prune(cost, straight).tolist() == [[0, 0], [5, 0]]


def test_pruning_with_clearance_never_shortcuts_through_dearer_cells_than_the_path():
    cost = np.full((3, 5), 50, dtype=np.uint8)
    cost[0, :] = 0  # the path runs along the free bottom row, dear cells above it
    cost[1, 1:4] = 150
    cells = [(0, 0), (1, 0), (2, 0), (3, 0), (4, 0), (4, 1), (4, 2)]
    careful = _prune(cost, cells, keep_clearance=True).tolist()
    loose = _prune(cost, cells, keep_clearance=False).tolist()
    assert loose == [[0, 0], [4, 2]]
    assert [0, 0] in careful and len(careful) > 2
    for (ax, ay), (bx, by) in itertools.pairwise(careful):
        assert _line_ok_py(cost, ax, ay, bx, by, 50)
