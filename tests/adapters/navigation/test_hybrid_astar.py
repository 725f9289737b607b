"""The ``hybrid_astar`` global planner: settings, feasible plans to the goal, real runs."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

from adapters.navigation.contract import PLANNERS, PlannerContext, PlanRequest, RepairRequest
from adapters.navigation.hybrid_astar import HybridAStar, HybridAStarSettings
from cosim.core.errors import ConfigError
from cosim.scenario import load_scenario
from cosim.scenario.model import section_registry
from cosim.testing import SMALL_WAREHOUSE, assert_no_collisions, assert_same_run, run_scenario
from models.geometry.occupancy import OccupancyGrid
from models.navigation.costmap import CostmapParams, StaticCostmap, with_obstacles
from models.navigation.hybrid_astar import HybridParams

HYBRID = {"navigation.planner": "hybrid_astar"}


def _room() -> StaticCostmap:
    """A 6 m x 4 m room with a wall along y = 2 m from x = 1 m to 5 m."""
    occupancy = np.zeros((40, 60), dtype=np.int8)
    occupancy[0, :] = occupancy[-1, :] = occupancy[:, 0] = occupancy[:, -1] = 100
    occupancy[19:21, 10:50] = 100
    return StaticCostmap.from_grid(OccupancyGrid(0.1, (0.0, 0.0), occupancy), CostmapParams(0.33))


def _planner(static: StaticCostmap, settings: HybridAStarSettings | None = None) -> HybridAStar:
    run: Any = SimpleNamespace(settings=lambda kind: settings or kind())
    return HybridAStar(PlannerContext(run, static))


def test_hybrid_astar_is_registered_with_its_settings_section():
    assert PLANNERS.installed().get("hybrid_astar") is HybridAStar
    assert section_registry().get("hybrid_astar") is HybridAStarSettings
    assert HybridAStar.concurrent


def test_the_settings_reach_the_search():
    settings = HybridAStarSettings(turning_radius_m=0.8, heading_bins=36, turn_in_place=False)
    params = _planner(_room(), settings).params
    assert params == HybridParams(turning_radius_m=0.8, heading_bins=36, turn_in_place=False)
    assert _planner(_room()).params == HybridParams()  # the defaults agree


def test_a_plan_leaves_from_the_robot_and_ends_exactly_at_the_goal_round_the_wall():
    static = _room()
    cost = with_obstacles(static, np.zeros((0, 2)))
    start, goal = np.array([3.02, 1.01]), np.array([3.0, 3.0])
    route = _planner(static).plan(PlanRequest(static, cost, start, goal, None))
    assert route is not None
    waypoints, length = route
    assert waypoints[0].tolist() == start.tolist() and waypoints[-1].tolist() == goal.tolist()
    assert length == pytest.approx(np.hypot(*np.diff(waypoints, axis=0).T).sum())
    assert length > 4.0  # round an end of the wall


def test_a_repair_is_left_to_a_full_plan():
    static = _room()
    request = RepairRequest(
        static, np.zeros((0, 2)), None, np.array([[0.6, 1.0], [5.4, 1.0]]), 0, np.array([0.6, 1.0]),
        None,
    )  # fmt: skip
    assert _planner(static).repair(request) is None


@pytest.mark.parametrize(
    ("key", "value"), [("turning_radius_m", 0), ("heading_bins", 3), ("arc_penalty", 0.9)]
)
def test_a_bad_setting_is_refused_naming_it(key, value):
    with pytest.raises(ConfigError, match=f"hybrid_astar.*{key}"):
        load_scenario("warehouse-random", {**HYBRID, f"hybrid_astar.{key}": value})


@pytest.fixture(scope="module")
def warehouse_run() -> Any:
    return run_scenario("warehouse-random", HYBRID, duration_s=60)


def test_robots_reach_their_goals_in_the_warehouse_without_touching_anything(warehouse_run):
    assert_no_collisions(warehouse_run)
    assert warehouse_run.summary["arrivals"] >= 7
    plans = warehouse_run.tables["navigation"]
    replans = plans[plans["event"] == "replan"]
    assert len(replans) and (replans["detail"] != "repaired").all()  # full plans


def test_the_warehouse_run_repeats_exactly_with_the_same_seed(warehouse_run):
    assert_same_run(warehouse_run, run_scenario("warehouse-random", HYBRID, duration_s=60))


def test_robots_plan_along_one_way_lanes_and_without_turning_on_the_spot():
    overrides = {
        **SMALL_WAREHOUSE,
        **HYBRID,
        "robots.driver": "navigation",
        "navigation.traffic": "lanes",
        "hybrid_astar.turn_in_place": False,
    }
    result = run_scenario("warehouse-random", overrides, duration_s=30, seed=4)
    assert_no_collisions(result)
    assert result.summary["arrivals"] >= 2
