"""cosim's own traffic policies: none, one-way lanes, and the fleet manager's places."""

import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import cosim
from adapters.navigation.contract import TRAFFIC_POLICIES, TrafficContext
from adapters.navigation.layers import StaticLayers
from adapters.navigation.traffic_policies import (
    LANE_WIDTH_M,
    LaneTraffic,
    NoTraffic,
    PibtTraffic,
    check_localization,
)
from cosim.core.adapter import RunContext
from cosim.runner.assembly import assemble, check_scenario
from models.navigation.costmap import CostmapParams, StaticCostmap
from models.navigation.lanes import EAST, NORTH, SOUTH, TWO_WAY, WEST
from models.world.warehouse import Warehouse, ground_truth_grid
from tests.conftest import SMALL

RESOLUTION_M = 0.1
ROWS = {
    **SMALL,
    "world.size_m": [16.0, 14.0],
    "world.layout": "all_rows",
    "world.shelf_count": 12,
    "robots.driver": "navigation",
}


def _context(**overrides: object) -> tuple[RunContext, TrafficContext]:
    scenario = cosim.load_scenario("warehouse-random", {**ROWS, **overrides})
    run = assemble(scenario, names=["world", "fleet"]).run
    truth = ground_truth_grid(run.service(Warehouse), RESOLUTION_M)
    static = StaticCostmap.from_grid(truth, CostmapParams(0.33))
    starts = run.service(Warehouse).starts[:, :2]
    layers = StaticLayers.shared(static, len(starts))
    return run, TrafficContext(run, static, layers, starts, 0.33, RESOLUTION_M)


@pytest.fixture(scope="module")
def rows() -> TrafficContext:
    return _context()[1]


def test_the_three_policies_are_registered_by_their_names():
    loaded = TRAFFIC_POLICIES.installed().load_all()
    assert (loaded["none"], loaded["lanes"], loaded["pibt"]) == (
        NoTraffic,
        LaneTraffic,
        PibtTraffic,
    )


def test_without_a_policy_every_robot_plans_for_itself_two_way(rows):
    policy = NoTraffic(rows)
    assert policy.lanes is None and policy.manager is None


def test_lanes_make_the_narrow_aisles_one_way_and_leave_the_open_floor_two_way(rows):
    policy = LaneTraffic(rows)
    assert policy.manager is None and policy.lanes is not None
    lanes = policy.lanes
    assert lanes.shape == rows.static.cost.shape
    one_way = np.isin(lanes, (EAST, WEST, NORTH, SOUTH))
    assert one_way.any() and (lanes == TWO_WAY).any()
    # the rows' aisles flow both ways between them: some east, some west
    assert (lanes == EAST).any() and (lanes == WEST).any()
    truth = rows.truth()
    assert not one_way[truth.data > 0].any()  # lanes only on free cells
    assert LANE_WIDTH_M == 2.5


def test_the_fleet_manager_moves_the_robots_on_places_and_no_robot_plans(rows):
    policy = PibtTraffic(rows)
    assert policy.lanes is None and policy.manager is not None
    places = policy.manager.places
    assert len(set(places.node.tolist())) == len(rows.starts_m)
    assert places.radius_m == 0.33


def test_the_truth_is_the_buildings_occupancy_at_the_costmaps_resolution(rows):
    truth = rows.truth()
    assert truth == ground_truth_grid(rows.run.service(Warehouse), RESOLUTION_M)
    assert truth.resolution_m == RESOLUTION_M


@pytest.mark.parametrize(
    ("override", "named"),
    [
        ({"mapping.enabled": True}, r"\[mapping\] enabled = true"),
        ({"odometry.drift": 0.02}, r"\[odometry\] drift = 0.02"),
        (
            {"mapping.enabled": True, "mocap.source": "simulated", "mocap.robots": ["robot_1"]},
            "3 of 4",
        ),
    ],
)
def test_the_fleet_manager_refuses_robots_that_cannot_localize_to_within_its_gap(override, named):
    scenario = cosim.load_scenario("fleet50", {**override, "robots.count": 4})
    with pytest.raises(cosim.ConfigError) as refused:
        cosim.run(scenario.with_duration(1.0))
    message = str(refused.value)
    assert "preset fleet50: [navigation] traffic = 'pibt'" in message
    assert re.search(named, message), message
    assert "navigation.traffic = 'none'" in message and "mocap.source = 'simulated'" in message


def test_robots_localized_by_motion_capture_or_true_odometry_are_accepted():
    scenario = cosim.load_scenario("fleet50", {"robots.count": 4, "navigation.traffic": "pibt"})
    check_localization(scenario, np.zeros(4, dtype=bool))  # odometry without drift
    drifting = cosim.load_scenario("fleet50", {"robots.count": 4, "odometry.drift": 0.1})
    check_localization(drifting, np.ones(4, dtype=bool))  # every robot tracked
    PibtTraffic.check_scenario(scenario)


def test_the_refusal_names_how_many_robots_are_not_tracked_and_the_gap():
    scenario = cosim.load_scenario(
        "fleet50", {"robots.count": 4, "navigation.traffic": "pibt", "odometry.drift": 0.05}
    )
    with pytest.raises(cosim.ConfigError) as refused:
        check_localization(scenario, np.array([True, False, True, False]))
    message = str(refused.value)
    assert "(2 of 4 are not tracked)" in message
    assert re.search(r"keeps robots 0.14 m apart", message)
    assert "[odometry] drift = 0.05 (robots localize by odometry alone" in message


@settings(max_examples=60, deadline=None)
@given(
    traffic=st.sampled_from(["none", "lanes", "pibt"]),
    mapping=st.booleans(),
    drift=st.one_of(st.just(0.0), st.floats(0.0, 1.0)),
    tracked=st.one_of(st.none(), st.lists(st.integers(1, 4), unique=True)),
)
def test_the_fleet_manager_is_refused_exactly_when_an_untracked_robot_localizes_badly(
    traffic, mapping, drift, tracked
):
    overrides = {
        "navigation.traffic": traffic,
        "mapping.enabled": mapping,
        "odometry.drift": drift,
        "robots.count": 4,
    }
    if tracked is not None:  # tracked by simulated motion capture ([] = every robot)
        overrides |= {"mocap.source": "simulated", "mocap.robots": [f"robot_{i}" for i in tracked]}
    scenario = cosim.load_scenario("fleet50", overrides)
    everyone = tracked is not None and len(tracked) in (0, 4)
    refused = traffic == "pibt" and not everyone and (mapping or drift > 0)
    if not refused:
        check_scenario(scenario)
        return
    with pytest.raises(cosim.ConfigError, match=r"\[navigation\] traffic = 'pibt' with \["):
        check_scenario(scenario)
