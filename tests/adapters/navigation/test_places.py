"""The fleet manager's places: a grid of robot-sized places, who stands on and holds which."""

import math

import numpy as np
import pytest

from adapters.navigation.fleet_traffic import FleetTraffic
from adapters.navigation.places import (
    APPROACH,
    GAP_M,
    GOAL_REACH,
    RELEASE_M,
    SETTLE,
    STAND,
    FleetPlaces,
)
from models.errors import ModelError
from models.fleet.kinematics import DriveLimits
from models.geometry.occupancy import OccupancyGrid
from models.navigation.costmap import CostmapParams, StaticCostmap
from models.navigation.lanes import TWO_WAY

RADIUS_M = 0.33
STARTS = np.array([[1.5, 1.5], [3.0, 3.0], [4.5, 4.5]])


def _static(cells: int = 60) -> StaticCostmap:
    occupancy = np.zeros((cells, cells), dtype=np.int8)  # 6 m x 6 m
    occupancy[0, :] = occupancy[-1, :] = occupancy[:, 0] = occupancy[:, -1] = 100
    return StaticCostmap.from_grid(
        OccupancyGrid(0.1, (0.0, 0.0), occupancy), CostmapParams(RADIUS_M)
    )


def _places(starts: np.ndarray = STARTS) -> FleetPlaces:
    static = _static()
    lanes = np.full(static.cost.shape, TWO_WAY, dtype=np.uint8)
    return FleetPlaces(static, lanes, starts, RADIUS_M)


@pytest.fixture(scope="module")
def shared() -> FleetPlaces:
    """Places to look at, not to change."""
    return _places()


def test_places_are_a_robot_and_a_gap_apart_and_clear_of_the_walls(shared):
    rm = shared.roadmap
    assert shared.spacing_m == rm.spacing_m == pytest.approx(2 * RADIUS_M + GAP_M)
    assert len(rm) >= 25
    east = rm.neighbours[:, 0]
    linked = east >= 0
    gaps = np.hypot(*(rm.xy[east[linked]] - rm.xy[linked]).T)
    assert gaps == pytest.approx(np.full(len(gaps), shared.spacing_m))
    assert rm.xy.min() > RADIUS_M and rm.xy.max() < 6.0 - RADIUS_M


def test_every_robot_starts_on_a_place_of_its_own_near_it_settling_onto_it(shared):
    nodes = shared.node.tolist()
    assert len(set(nodes)) == 3
    gaps = np.hypot(*(shared.roadmap.xy[shared.node] - STARTS).T)
    assert (gaps < shared.spacing_m).all()
    assert shared.settling.tolist() == [True, True, True]
    assert (shared.mode == SETTLE).all()
    assert [held[0] for held in shared.held] == nodes  # each holds its place first
    np.testing.assert_array_equal(shared.aim, shared.roadmap.xy[shared.node])


def test_robots_starting_at_one_point_get_distinct_places():
    places = _places(np.array([[3.0, 3.0], [3.0, 3.0], [3.0, 3.0], [3.0, 3.0]]))
    assert len(set(places.node.tolist())) == 4


def test_a_fleet_with_more_robots_than_places_is_refused_naming_the_key():
    occupancy = np.zeros((30, 30), dtype=np.int8)  # 3 m x 3 m
    occupancy[0, :] = occupancy[-1, :] = occupancy[:, 0] = occupancy[:, -1] = 100
    static = StaticCostmap.from_grid(OccupancyGrid(0.1, (0.0, 0.0), occupancy), CostmapParams(0.33))
    lanes = np.full(static.cost.shape, TWO_WAY, dtype=np.uint8)
    positions = np.full((20, 2), 1.5)
    with pytest.raises(ModelError, match=r"robots\.count"):
        FleetTraffic(FleetPlaces(static, lanes, positions, 0.33))


def test_a_goal_is_reached_from_the_nearest_place_within_two_spacings(shared):
    goal = np.array([2.2, 3.9])
    place = shared.goal_place(0, goal)
    rm = shared.roadmap
    assert place >= 0
    distances = np.hypot(*(rm.xy - goal).T)
    assert distances[place] == distances.min()
    assert distances[place] <= GOAL_REACH * rm.spacing_m


@pytest.mark.parametrize("goal", [(0.05, 3.0), (30.0, 30.0)])
def test_a_goal_in_a_wall_or_far_outside_is_reached_from_no_place(shared, goal):
    assert shared.goal_place(0, np.array(goal)) == -1


def test_a_goal_set_is_driven_to_by_way_of_its_place_and_ended_settles_the_robot():
    places = _places()
    goal = np.array([4.6, 1.4])
    place = places.goal_place(1, goal)
    places.set_goal(1, goal, place, 5)
    assert (places.goal_node[1], places.since_ns[1]) == (place, 5)
    way = places.way_left(1, places.roadmap.xy[places.node[1]])
    hops = int(places.hops_to(place)[places.node[1]])
    straight = float(np.hypot(*(places.roadmap.xy[place] - goal)))
    assert way == pytest.approx(hops * places.spacing_m + straight)
    assert math.isfinite(way) and way >= float(np.hypot(*(goal - (3.0, 3.0)))) - 0.5
    remaining = places.remaining(STARTS, np.array([True, True, True]))
    assert remaining[0] == remaining[2] == 0.0 and remaining[1] > 0  # only robot 1 has one
    places.mode[1] = APPROACH
    places.end_goal(1)
    assert places.goal_node[1] == -1 and np.isnan(places.goal[1]).all()
    assert places.mode[1] == SETTLE
    np.testing.assert_array_equal(places.aim[1], places.roadmap.xy[places.node[1]])


def test_while_approaching_its_goal_the_way_left_is_straight_to_it():
    places = _places()
    goal = np.array([4.6, 1.4])
    places.set_goal(1, goal, places.goal_place(1, goal), 0)
    places.mode[1] = APPROACH
    assert places.way_left(1, np.array([4.0, 1.4])) == pytest.approx(0.6)


def _a_neighbour(places: FleetPlaces, node: int) -> int:
    return next(int(u) for u in places.roadmap.neighbours[node] if u >= 0)


def test_hops_to_a_place_are_worked_out_once(shared):
    first = shared.hops_to(0)
    assert shared.hops_to(0) is first
    assert first[0] == 0 and first[_a_neighbour(shared, 0)] == 1


def test_a_robot_lets_go_of_the_places_its_body_has_left_but_never_its_own():
    places = _places()
    rm = places.roadmap
    node = int(places.node[0])
    next_one = _a_neighbour(places, node)
    far = int(rm.nearest_k(np.array([[5.0, 5.0]]), 1)[0, 0])
    places.mode[0] = STAND
    places.held[0] = [node, next_one, far]
    others = [[3.0, 3.0], [4.5, 4.5]]
    places.release(np.array([rm.xy[next_one], *others]))  # on the next place
    assert places.held[0] == [node, next_one]  # far is more than RELEASE_M away
    away = rm.xy[node] + 3 * (rm.xy[node] - rm.xy[next_one])  # off the other way
    assert np.hypot(*(away - rm.xy[next_one])) > RELEASE_M
    places.release(np.array([away, *others]))
    assert places.held[0] == [node]


def test_places_touched_on_the_way_to_a_point_start_with_the_place_itself(shared):
    node = int(shared.node[1])
    assert shared.touched(shared.roadmap.xy[node], node) == [node]
    next_one = _a_neighbour(shared, node)
    touched = shared.touched(shared.roadmap.xy[next_one], node)
    assert touched[0] == node and next_one in touched


def test_settling_robots_take_the_local_controllers_commands_the_others_drive_place_to_place():
    places = _places()
    places.mode[:] = [SETTLE, STAND, STAND]
    limits = DriveLimits(1.0, 0.3, 2.0, 2.0, 3.0)
    poses = np.array([[1.5, 1.5, 0.0], [3.0, 3.0, 0.0], [4.5, 4.5, 0.0]])
    settle = (np.full(3, 0.77), np.full(3, -0.55), np.zeros(3, dtype=bool))
    ahead = poses[:, :2] + (1.0, 0.0)  # each robot's next place, 1 m along +x
    v, w = places.commands(poses, ahead, settle, np.full(3, 5.0), limits)
    assert (v[0], w[0]) == (0.77, -0.55)
    assert 0 < v[1] <= 1.0 and 0 < v[2] <= 1.0 and w[1] == w[2] == pytest.approx(0.0)
    assert places.commands(poses, ahead, None, np.full(3, 5.0), limits)[0][0] > 0
