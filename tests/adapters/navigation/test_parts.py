"""The navigation's parts, built from a run's settings and services in the run's order."""

from __future__ import annotations

from typing import Any

import pytest

import cosim
from adapters.fleet.robots_layer import RobotsLayer
from adapters.fleet.topics import ROBOT_STATES
from adapters.navigation.parts import NavigationParts, build_parts
from cosim.core.adapter import RunContext
from cosim.core.errors import ConfigError
from cosim.runner.assembly import assemble
from models.navigation.costmap import StaticCostmap
from models.navigation.dwa import DwaParams
from tests.conftest import SMALL


def _run(names: tuple[str, ...] = ("world", "fleet", "lidar"), **overrides: Any) -> RunContext:
    """A small warehouse's run with the adapters navigation requires built, not navigation."""
    settings = {**SMALL, "robots.driver": "navigation", **overrides}
    scenario = cosim.load_scenario("warehouse-random", settings)
    return assemble(scenario, names=list(names)).run


def _parts(**overrides: Any) -> tuple[RunContext, NavigationParts]:
    run = _run(**overrides)
    return run, build_parts(run)


def test_robots_without_a_lidar_are_refused():
    run = _run(("world", "fleet"), **{"lidar.beams": 0})
    with pytest.raises(ConfigError, match=r"expected lidar.beams > 0"):
        build_parts(run)


def test_every_part_reads_the_pose_estimates_localization_keeps():
    _, parts = _parts()
    pose = parts.localization.pose
    assert parts.pose is pose
    assert parts.goals.pose is pose and parts.planning.pose is pose and parts.off_map.pose is pose
    assert parts.planning.goal is parts.goals.goal  # goals are planned to as they are set
    assert pose.shape == (3, 3) and parts.names == ["robot_1", "robot_2", "robot_3"]


def test_the_goal_tracker_drives_robots_with_the_parts_built():
    _, parts = _parts()
    drivers = parts.goals.drivers
    assert drivers is not None
    assert drivers.planning is parts.planning and drivers.paths is parts.paths
    assert drivers.recovery is parts.recovery and drivers.stalls is parts.stalls
    assert drivers.static is parts.static and drivers.places is None


def test_the_static_costmap_is_offered_to_the_run_and_the_robots_layer_only_when_asked_for():
    run, parts = _parts()
    assert run.service(StaticCostmap) is parts.static
    assert parts.robots_layer is None and not run.has_service(RobotsLayer)
    run, parts = _parts(**{"navigation.robots_layer": True})
    assert parts.robots_layer is not None and run.service(RobotsLayer) is parts.robots_layer


def test_robots_that_map_get_the_robots_layer_unless_it_is_turned_off():
    run, parts = _parts(**{"mapping.enabled": True})
    assert parts.robots_layer is not None and run.service(RobotsLayer) is parts.robots_layer
    run, parts = _parts(**{"mapping.enabled": True, "navigation.robots_layer": False})
    assert parts.robots_layer is None and not run.has_service(RobotsLayer)


def test_each_robots_topics_are_advertised_robot_by_robot_and_the_robots_layer_after_them():
    run, parts = _parts(**{"navigation.robots_layer": True})
    advertised = list(run.bus.advertised())
    ours = advertised[advertised.index("/robot_1/nav/status") :]
    assert ours == [
        *(
            f"/{robot}/{leaf}"
            for robot in parts.names
            for leaf in ("nav/status", "cmd_vel", "plan")
        ),
        ROBOT_STATES,
    ]
    assert parts.interface.status == [
        "/robot_1/nav/status",
        "/robot_2/nav/status",
        "/robot_3/nav/status",
    ]


def test_plans_keep_the_controllers_margin_from_walls():
    _, parts = _parts()
    margin = DwaParams(control_period_s=0.1).safety_margin_m
    assert parts.planning.padding_m == margin > 0
    assert parts.planning.plan_layers is not parts.layers


def test_robots_that_map_plan_on_their_own_maps_as_they_come():
    _, parts = _parts(**{"mapping.enabled": True})
    assert parts.mapping and parts.planning.mapping
    assert parts.planning.plan_layers is parts.layers


def test_a_fleet_manager_moves_the_robots_to_its_places_and_nothing_replans():
    _, parts = _parts(**{"navigation.traffic": "pibt"})
    assert parts.manager is not None
    assert parts.goals.drivers is not None and parts.goals.drivers.places is parts.manager.places
    assert not parts.off_map.replan


def test_lidar_hits_matter_as_far_as_a_robot_drives_in_a_dwa_horizon_and_a_metre_beyond_it():
    _, parts = _parts()
    horizon_m = parts.limits.max_speed_mps * DwaParams().sim_time_s
    assert parts.near_m == pytest.approx(horizon_m + parts.radius_m + 1.0)
