"""The ``thetastar`` global planner: settings, plans to the goal, repairs, real runs."""

from __future__ import annotations

import itertools
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

from adapters.navigation.contract import PLANNERS, PlannerContext, PlanRequest, RepairRequest
from adapters.navigation.thetastar import ThetaStar, ThetaStarSettings
from cosim.core.errors import ConfigError
from cosim.scenario import load_scenario
from cosim.scenario.model import section_registry
from cosim.testing import SMALL_WAREHOUSE, assert_no_collisions, assert_same_run, run_scenario
from models.geometry.occupancy import OccupancyGrid
from models.navigation.costmap import CostmapParams, StaticCostmap, with_obstacles

THETA = {"navigation.planner": "thetastar"}


def _room(wall: bool = True) -> StaticCostmap:
    """A 6 m x 4 m room; with ``wall``, a wall along y = 2 m from x = 1 m to 5 m."""
    occupancy = np.zeros((40, 60), dtype=np.int8)
    occupancy[0, :] = occupancy[-1, :] = occupancy[:, 0] = occupancy[:, -1] = 100
    if wall:
        occupancy[19:21, 10:50] = 100
    return StaticCostmap.from_grid(OccupancyGrid(0.1, (0.0, 0.0), occupancy), CostmapParams(0.33))


def _planner(static: StaticCostmap, settings: ThetaStarSettings | None = None) -> ThetaStar:
    run: Any = SimpleNamespace(settings=lambda kind: settings or kind())
    return ThetaStar(PlannerContext(run, static))


def _request(static: StaticCostmap, start: Any, goal: Any) -> PlanRequest:
    cost = with_obstacles(static, np.zeros((0, 2)))
    return PlanRequest(static, cost, np.array(start, float), np.array(goal, float), None)


def test_thetastar_is_registered_with_its_settings_section():
    assert PLANNERS.installed().get("thetastar") is ThetaStar
    assert section_registry().get("thetastar") is ThetaStarSettings
    assert ThetaStar.concurrent


def test_across_an_open_room_the_plan_is_one_segment_to_exactly_the_goal():
    static = _room(wall=False)
    route = _planner(static).plan(_request(static, (1.5, 1.5), (4.5, 2.5)))
    assert route is not None
    waypoints, length = route
    assert len(waypoints) == 2 and waypoints[-1].tolist() == [4.5, 2.5]
    assert length == pytest.approx(np.hypot(*(waypoints[1] - waypoints[0])))
    assert length < 2.0 + np.sqrt(2.0) - 0.2  # shorter than the 8-connected path


def test_a_plan_round_a_wall_keeps_the_footprint_off_it_and_a_walled_off_goal_has_none():
    static = _room()
    route = _planner(static).plan(_request(static, (3.0, 1.0), (3.0, 3.0)))
    assert route is not None
    waypoints, length = route
    assert length > 4.0  # round an end of the wall, not 2 m through it
    for a, b in itertools.pairwise(waypoints):
        for t in np.linspace(0.0, 1.0, 100):
            cx, cy = static.world_to_cell(a + t * (b - a))
            assert static.distance_m[cy, cx] >= 0.33
    occupancy = np.zeros((40, 60), dtype=np.int8)
    occupancy[0, :] = occupancy[-1, :] = occupancy[:, 0] = occupancy[:, -1] = 100
    occupancy[19:21, :] = 100  # the wall across the whole room
    closed = StaticCostmap.from_grid(OccupancyGrid(0.1, (0.0, 0.0), occupancy), CostmapParams(0.33))
    assert _planner(closed).plan(_request(closed, (3.0, 1.0), (3.0, 3.0))) is None


def test_a_repair_plans_round_what_blocks_the_stretch_ahead_within_its_reach():
    static = _room(wall=False)
    planner = _planner(static, ThetaStarSettings(repair_ahead_m=4.0, repair_margin_m=1.0))
    waypoints = np.array([[0.6, 2.0], [5.4, 2.0]])
    blocking = np.array([[3.0, y] for y in np.arange(1.5, 2.6, 0.05)])
    request = RepairRequest(static, blocking, None, waypoints, 0, np.array([0.6, 2.0]), None)
    repaired = planner.repair(request)
    assert repaired is not None
    path, length = repaired
    assert path[-1].tolist() == [5.4, 2.0]
    assert length > 4.8 and np.abs(path[:, 1] - 2.0).max() > 0.3  # round, not through
    cost = with_obstacles(static, blocking)
    for x, y in path:
        cx, cy = static.world_to_cell((x, y))
        assert cost[cy, cx] < 253


@pytest.mark.parametrize(("key", "value"), [("cost_weight", -1), ("repair_ahead_m", 0)])
def test_a_bad_setting_is_refused_naming_it(key, value):
    with pytest.raises(ConfigError, match=f"thetastar.*{key}"):
        load_scenario("warehouse-random", {**THETA, f"thetastar.{key}": value})


@pytest.fixture(scope="module")
def warehouse_run() -> Any:
    return run_scenario("warehouse-random", THETA, duration_s=60)


def test_robots_reach_their_goals_in_the_warehouse_without_touching_anything(warehouse_run):
    assert_no_collisions(warehouse_run)
    assert warehouse_run.summary["arrivals"] >= 8
    plans = warehouse_run.tables["navigation"]
    assert (plans["detail"] == "repaired").any()  # replans are windowed repairs


def test_the_warehouse_run_repeats_exactly_with_the_same_seed(warehouse_run):
    assert_same_run(warehouse_run, run_scenario("warehouse-random", THETA, duration_s=60))


def test_robots_plan_along_one_way_lanes_without_touching_anything():
    overrides = {
        **SMALL_WAREHOUSE,
        **THETA,
        "robots.driver": "navigation",
        "navigation.traffic": "lanes",
    }
    result = run_scenario("warehouse-random", overrides, duration_s=30, seed=4)
    assert_no_collisions(result)
    assert result.summary["arrivals"] >= 2
