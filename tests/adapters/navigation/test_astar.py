"""The ``astar`` global planner: full plans pruned to corners, lanes, landmarks, repairs."""

from __future__ import annotations

import itertools
from typing import Any

import numpy as np
import pytest

import adapters.navigation.astar as astar
from adapters.navigation.astar import LANE_AGAINST, AStar
from adapters.navigation.contract import PlannerContext, PlanRequest, RepairRequest
from models.geometry.occupancy import OccupancyGrid
from models.navigation.costmap import CostmapParams, StaticCostmap, with_obstacles
from models.navigation.lanes import EAST, TWO_WAY, WEST
from models.navigation.planner import shortest_path_length_m

RADIUS_M = 0.33


def _room(width_cells: int = 60, height_cells: int = 40, wall: bool = True) -> StaticCostmap:
    """A 6 m x 4 m room; with ``wall``, a wall along y = 2 m from x = 1 m to 5 m."""
    occupancy = np.zeros((height_cells, width_cells), dtype=np.int8)
    occupancy[0, :] = occupancy[-1, :] = occupancy[:, 0] = occupancy[:, -1] = 100
    if wall:
        occupancy[19:21, 10:50] = 100
    return StaticCostmap.from_grid(
        OccupancyGrid(0.1, (0.0, 0.0), occupancy), CostmapParams(RADIUS_M)
    )


def _planner(static: StaticCostmap) -> AStar:
    return AStar(PlannerContext(None, static))  # type: ignore[arg-type]  # no run needed


def _request(static: StaticCostmap, start: Any, goal: Any, lanes: Any = None) -> PlanRequest:
    cost = with_obstacles(static, np.zeros((0, 2)))
    return PlanRequest(static, cost, np.array(start, float), np.array(goal, float), lanes)


def _lethal_free(static: StaticCostmap, waypoints: np.ndarray) -> bool:
    """Whether the path, sampled every 2 cm, never touches a wall with the footprint."""
    for a, b in itertools.pairwise(waypoints):
        for t in np.linspace(0.0, 1.0, max(2, int(np.hypot(*(b - a)) / 0.02))):
            cx, cy = static.world_to_cell(a + t * (b - a))
            if static.distance_m[cy, cx] < RADIUS_M:
                return False
    return True


def test_across_an_open_room_the_plan_is_one_straight_stretch_to_exactly_the_goal():
    static = _room(wall=False)
    route = _planner(static).plan(_request(static, (1.0, 1.0), (5.0, 3.0)))
    assert route is not None
    waypoints, length = route
    assert len(waypoints) == 2  # pruned to its corners: none
    assert waypoints[-1].tolist() == [5.0, 3.0]
    assert np.hypot(*(waypoints[0] - (1.0, 1.0))) < 0.1
    # the length is the searched 8-connected path's: 2 m straight and 2 m diagonally
    assert length == pytest.approx(2.0 + 2.0 * np.sqrt(2.0), abs=0.15)


def test_a_plan_round_a_wall_bends_at_few_corners_and_keeps_the_footprint_off_it():
    static = _room()
    route = _planner(static).plan(_request(static, (3.0, 1.0), (3.0, 3.0)))
    assert route is not None
    waypoints, length = route
    assert 3 <= len(waypoints) <= 6
    assert _lethal_free(static, waypoints)
    assert length > 4.0  # round an end of the wall, not 2 m through it
    assert length == pytest.approx(shortest_path_length_m(static, (3.0, 1.0), (3.0, 3.0)), rel=0.1)


def test_a_goal_walled_off_has_no_plan():
    occupancy = np.zeros((40, 60), dtype=np.int8)
    occupancy[0, :] = occupancy[-1, :] = occupancy[:, 0] = occupancy[:, -1] = 100
    occupancy[19:21, :] = 100  # the wall across the whole room
    static = StaticCostmap.from_grid(OccupancyGrid(0.1, (0.0, 0.0), occupancy), CostmapParams(0.33))
    assert _planner(static).plan(_request(static, (3.0, 1.0), (3.0, 3.0))) is None


def test_a_lane_against_the_way_is_avoided_when_another_aisle_leads_there():
    static = _room()
    lanes = np.full(static.cost.shape, TWO_WAY, dtype=np.uint8)
    lanes[:19, :] = WEST  # the lower aisle is driven towards -x
    lanes[21:, :] = EAST
    planner = _planner(static)
    plain = planner.plan(_request(static, (0.5, 1.0), (5.5, 1.0)))
    laned = planner.plan(_request(static, (0.5, 1.0), (5.5, 1.0), lanes))
    assert plain is not None and laned is not None
    assert plain[0][:, 1].max() < 2.0  # straight along the lower aisle
    assert laned[0][:, 1].max() > 2.0  # round by the upper one, with its lane
    assert LANE_AGAINST == 5.0


def test_landmark_bounds_are_used_only_on_the_shared_static_map_of_a_large_floor(monkeypatch):
    calls: list[Any] = []
    plan = astar.plan

    def spy(*args: Any, **kwargs: Any) -> Any:
        calls.append(kwargs["landmarks"])
        return plan(*args, **kwargs)

    monkeypatch.setattr(astar, "plan", spy)
    static = _room()
    assert _planner(static).landmarks is None  # 2,400 cells: too small to pay
    monkeypatch.setattr(astar, "ALT_MIN_CELLS", 0)
    planner = _planner(static)
    with_marks = planner.plan(_request(static, (3.0, 1.0), (3.0, 3.0)))
    own_map = _room()  # a map of the robot's own, not the building's
    without = planner.plan(_request(own_map, (3.0, 1.0), (3.0, 3.0)))
    assert calls[0] is not None and calls[0].cost_weight == 1.0 and calls[1] is None
    assert with_marks is not None and without is not None
    assert with_marks[1] == pytest.approx(without[1])  # the bounds change no plan's cost


def test_a_repair_plans_the_stretch_ahead_round_what_blocks_it_and_keeps_the_goal():
    static = _room(wall=False)
    planner = _planner(static)
    waypoints = np.array([[0.6, 2.0], [5.4, 2.0]])
    blocking = np.array([[3.0, y] for y in np.arange(1.5, 2.6, 0.05)])  # across the path
    request = RepairRequest(static, blocking, None, waypoints, 0, np.array([0.6, 2.0]), None)
    repaired = planner.repair(request)
    assert repaired is not None
    path, length = repaired
    assert path[-1].tolist() == [5.4, 2.0]
    assert length > 4.8  # round, not through
    cost = with_obstacles(static, blocking)
    for x, y in path:
        cx, cy = static.world_to_cell((x, y))
        assert cost[cy, cx] < 253
