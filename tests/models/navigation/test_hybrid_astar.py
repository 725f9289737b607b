"""Hybrid-A*: arcs of the turning radius, clear of obstacles, to the goal, or None."""

import itertools
import math
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from models.errors import ModelError
from models.geometry.occupancy import OCCUPIED, OccupancyGrid
from models.navigation.costmap import INSCRIBED, CostmapParams, StaticCostmap
from models.navigation.hybrid_astar import (
    HybridParams,
    _blocks_py,
    _lower_py,
    hybrid_astar,
    primitives,
)
from models.navigation.lanes import EAST, TWO_WAY, WEST

RES = 0.1
RADIUS_M = 0.2
PARAMS = CostmapParams(robot_radius_m=RADIUS_M, inflation_radius_m=0.6)
DEFAULT = HybridParams()
NO_TURNS = HybridParams(turn_in_place=False)


def _room(width, height, boxes=()):
    """A walled room of width x height cells with '#' boxes (x0, y0, x1, y1) inclusive."""
    data = np.zeros((height, width), dtype=np.int8)
    data[0, :] = data[-1, :] = data[:, 0] = data[:, -1] = OCCUPIED
    for x0, y0, x1, y1 in boxes:
        data[y0 : y1 + 1, x0 : x1 + 1] = OCCUPIED
    return StaticCostmap.from_grid(OccupancyGrid(RES, (0.0, 0.0), data), PARAMS)


def _plan(static, start, goal, params=DEFAULT, lanes=None):
    return hybrid_astar(
        static.cost,
        np.array(start, float),
        np.array(goal, float),
        origin_xy_m=static.origin_xy_m,
        resolution_m=RES,
        params=params,
        lanes=lanes,
        against=5.0,
    )


def _circumradius(a, b, c):
    ab, bc, ca = np.hypot(*(b - a)), np.hypot(*(c - b)), np.hypot(*(a - c))
    cross = abs((b - a)[0] * (c - a)[1] - (b - a)[1] * (c - a)[0])
    return math.inf if cross < 1e-12 else ab * bc * ca / (2.0 * cross)


def _clearance_m(static, waypoints):
    """The least distance (m) from the path, sampled every cm, to an obstacle cell centre."""
    least = math.inf
    for a, b in itertools.pairwise(waypoints):
        for t in np.linspace(0.0, 1.0, max(2, int(np.hypot(*(b - a)) / 0.01))):
            cx, cy = static.world_to_cell(a + t * (b - a))
            least = min(least, float(static.distance_m[cy, cx]))
    return least


def test_in_the_open_the_robot_turns_on_the_spot_and_drives_straight_to_the_goal():
    static = _room(60, 40)
    result = _plan(static, (1.03, 1.07), (5.0, 3.0))
    assert result.found
    assert result.waypoints.tolist() == [[1.03, 1.07], [5.0, 3.0]]
    assert result.length_m == pytest.approx(math.hypot(3.97, 1.93))
    assert result.expansions == 0  # nothing beats the straight shot from the start


def test_without_turns_on_the_spot_the_path_bends_no_tighter_than_the_turning_radius():
    static = _room(100, 60, boxes=[(40, 0, 45, 38)])
    result = _plan(static, (1.5, 1.0), (8.5, 1.0), NO_TURNS)
    assert result.found
    path = result.waypoints
    assert path[0].tolist() == [1.5, 1.0] and path[-1].tolist() == [8.5, 1.0]
    assert path[:, 1].max() > 4.2  # round the end of the wall
    radii = [_circumradius(*path[i : i + 3]) for i in range(len(path) - 2)]
    assert min(radii) >= NO_TURNS.turning_radius_m * (1 - 1e-6)
    assert _clearance_m(static, path) >= RADIUS_M - 0.01


def test_a_larger_turning_radius_gives_wider_turns():
    static = _room(100, 60, boxes=[(40, 0, 45, 38)])
    wide = replace(NO_TURNS, turning_radius_m=0.8)
    path = _plan(static, (1.5, 1.0), (8.5, 1.0), wide).waypoints
    radii = [_circumradius(*path[i : i + 3]) for i in range(len(path) - 2)]
    assert min(radii) >= 0.8 * (1 - 1e-6)


@settings(max_examples=15, deadline=None)
@given(st.integers(0, 10_000), st.booleans())
def test_paths_keep_the_footprint_off_every_obstacle(seed, turn_in_place):
    rng = np.random.default_rng(seed)
    boxes = [
        (int(x), int(y), int(x) + int(w), int(y) + int(h))
        for x, y, w, h in zip(
            rng.integers(5, 70, 6), rng.integers(5, 40, 6), rng.integers(1, 12, 6),
            rng.integers(1, 12, 6), strict=True,
        )
    ]  # fmt: skip
    static = _room(80, 50, boxes)
    free = np.argwhere(static.cost < 100)
    start, goal = ((free[i][::-1] + rng.random(2)) * RES for i in rng.integers(len(free), size=2))
    result = _plan(static, start, goal, HybridParams(turn_in_place=turn_in_place))
    if result.found:
        assert np.allclose(result.waypoints[[0, -1]], [start, goal])
        assert _clearance_m(static, result.waypoints) >= RADIUS_M - 0.01


def test_an_enclosed_goal_has_no_path_and_the_2d_search_tells_before_any_expansion():
    ring = [(20, 10, 40, 11), (20, 29, 40, 30), (20, 10, 21, 30), (39, 10, 40, 30)]
    static = _room(60, 40, boxes=ring)
    result = _plan(static, (0.8, 2.0), (3.05, 2.05))
    assert not result.found
    assert result.waypoints.shape == (0, 2) and result.length_m == math.inf
    assert result.expansions == 0


def test_the_search_gives_up_after_its_expansions():
    static = _room(100, 60, boxes=[(40, 0, 45, 38)])
    capped = replace(NO_TURNS, max_expansions=20, analytic_expansion=False)
    result = _plan(static, (1.5, 1.0), (8.5, 1.0), capped)
    assert not result.found and result.expansions == 20


def test_a_robot_in_inscribed_cells_escapes_them():
    static = _room(60, 40, boxes=[(30, 0, 31, 39)])
    assert static.cost[20, 28] >= INSCRIBED
    result = _plan(static, (2.85, 2.05), (0.5, 2.0))
    assert result.found and result.waypoints[-1].tolist() == [0.5, 2.0]


def test_a_lane_against_the_way_is_avoided_when_another_aisle_leads_there():
    static = _room(60, 40, boxes=[(10, 19, 49, 20)])
    lanes = np.full(static.cost.shape, TWO_WAY, dtype=np.uint8)
    lanes[:19, :] = WEST
    lanes[21:, :] = EAST
    plain = _plan(static, (0.5, 1.0), (5.5, 1.0))
    laned = _plan(static, (0.5, 1.0), (5.5, 1.0), lanes=lanes)
    assert plain.waypoints[:, 1].max() < 2.0
    assert laned.waypoints[:, 1].max() > 2.0


def test_arcs_turn_by_whole_heading_bins_and_every_motion_leaves_its_bin():
    params = HybridParams(turning_radius_m=0.4, cell_m=0.2, heading_bins=72)
    prims = primitives(params, RES)
    assert prims.step == pytest.approx(math.sqrt(2) * 2.0)
    assert prims.arc_bins == 9  # 45 degrees: the least whole bins whose arc outlasts a step
    ends = np.array([[np.hypot(prims.dx[h, m, n - 1], prims.dy[h, m, n - 1])
                      for m, n in enumerate(prims.samples[:3])] for h in range(72)])  # fmt: skip
    assert ends[:, 0] == pytest.approx(prims.step)
    chord = 2 * prims.radius * math.sin(prims.arc_bins * math.pi / 72)
    assert ends[:, 1:] == pytest.approx(chord)
    assert prims.turn.tolist() == [0, 9, -9, 9, -9]


@pytest.mark.parametrize("k", [1, 2, 3])
def test_the_heuristics_blocks_hold_the_least_cost_of_their_cells(k):
    cost = np.random.default_rng(k).integers(0, 256, size=(31, 44)).astype(np.uint8)
    blocks = _blocks_py(cost, k)
    assert blocks.shape == (-(-31 // k), -(-44 // k))
    for by, bx in itertools.product(range(blocks.shape[0]), range(blocks.shape[1])):
        assert blocks[by, bx] == cost[by * k : (by + 1) * k, bx * k : (bx + 1) * k].min()
    h2d = np.arange(blocks.size, dtype=float).reshape(blocks.shape)
    assert _lower_py(h2d, k, 4.5, 7.5, 4.5, 7.5) == k * h2d[7 // k, 4 // k]  # the 2-D field
    assert _lower_py(np.zeros_like(h2d), k, 0.5, 0.5, 30.5, 40.5) == 50.0  # the distance


def test_parameters_out_of_range_are_refused_by_name():
    with pytest.raises(ModelError, match="turning_radius_m"):
        HybridParams(turning_radius_m=0.0)
    with pytest.raises(ModelError, match="heading_bins"):
        HybridParams(heading_bins=2)
    with pytest.raises(ModelError, match="arc_penalty"):
        HybridParams(arc_penalty=0.5)
