"""``navigation.traffic = "pibt"``: the fleet manager moving robots place by place."""

import numpy as np
import pytest

import adapters.navigation.fleet_traffic as fleet_traffic
import cosim
from adapters.navigation.fleet_traffic import FleetTraffic
from adapters.navigation.places import CLEARANCE_M, MOVE, STAND, FleetPlaces
from models.geometry.occupancy import OccupancyGrid
from models.navigation.costmap import CostmapParams, StaticCostmap
from models.navigation.lanes import TWO_WAY
from models.navigation.roadmap import build_roadmap


def _pibt_fleet(count: int, duration_s: float) -> cosim.Scenario:
    return cosim.load_scenario(
        "fleet50",
        {
            "navigation.traffic": "pibt",
            "robots.count": count,
            "scenario.duration_s": duration_s,
            "record.bag": "none",
        },
    )


@pytest.mark.slow
def test_robots_on_places_reach_goals_without_collision_and_never_share_a_place(monkeypatch):
    shared: list[float] = []
    step = FleetTraffic.step

    def checked(self, poses, active, progress_ns, now_ns):
        out = step(self, poses, active, progress_ns, now_ns)
        if len(set(self.places.node.tolist())) < len(self.places.node):
            shared.append(now_ns / 1e9)
        standing = self.places.mode == STAND
        assert (
            np.hypot(*(poses[standing, :2] - self.places.roadmap.xy[self.places.node[standing]]).T)
            <= fleet_traffic.ARRIVE_M + 1e-9
        ).all()
        # a robot on the places keeps every place its body still covers
        for i in np.flatnonzero((self.places.mode == STAND) | (self.places.mode == MOVE)).tolist():
            for u in self.places.roadmap.near(poses[i, :2], fleet_traffic.RELEASE_M - 0.05):
                assert u == self.places.node[i] or u in self.places.held[i], (i, u)
        return out

    monkeypatch.setattr(FleetTraffic, "step", checked)
    result = cosim.run(_pibt_fleet(16, 60.0))
    assert shared == []
    summary = result.summary
    assert summary["collisions"] == 0
    assert summary["arrivals"] >= 10
    assert summary["goals_missed"] == 0
    # no A* on the way: the fleet manager moves them, robots plan nothing themselves
    assert result.tables["navigation"].query("event in ['plan', 'replan']").empty


@pytest.mark.slow
def test_the_same_seed_gives_the_same_tables_with_places():
    first = cosim.run(_pibt_fleet(8, 20.0)).deterministic_tables()
    second = cosim.run(_pibt_fleet(8, 20.0)).deterministic_tables()
    for name, frame in first.items():
        assert second[name].equals(frame), name


@pytest.mark.slow
def test_robots_that_map_drive_on_the_fleet_managers_places_when_motion_capture_tracks_them():
    scenario = cosim.load_scenario(
        "fleet50",
        {
            "robots.count": 12,
            "scenario.duration_s": 40.0,
            "mapping.enabled": True,
            "odometry.drift": 0.02,
            "mocap.source": "simulated",
            "record.bag": "none",
        },
    )
    summary = cosim.run(scenario).summary
    assert summary["collisions"] == 0
    assert summary["arrivals"] >= 5
    assert summary["goals_missed"] == 0


def test_a_robot_waiting_on_its_goals_place_keeps_the_free_places_it_needs():
    occupancy = np.zeros((60, 60), dtype=np.int8)  # 6 m x 6 m
    occupancy[0, :] = occupancy[-1, :] = occupancy[:, 0] = occupancy[:, -1] = 100
    static = StaticCostmap.from_grid(OccupancyGrid(0.1, (0.0, 0.0), occupancy), CostmapParams(0.33))
    lanes = np.full(static.cost.shape, TWO_WAY, dtype=np.uint8)
    traffic = FleetTraffic(
        FleetPlaces(static, lanes, np.array([[1.5, 1.5], [3.0, 3.0], [4.5, 4.5]]), 0.33)
    )
    roadmap = build_roadmap(
        static.distance_m, static.origin_xy_m, 0.1, traffic.places.spacing_m, 0.33 + CLEARANCE_M
    )
    traffic.places.roadmap = roadmap  # two-way everywhere: only the places matter here
    xy = roadmap.xy
    p = int(roadmap.nearest_k(np.array([[2.5, 2.5]]), 1)[0, 0])
    east, north = int(roadmap.neighbours[p, 0]), int(roadmap.neighbours[p, 2])
    corner = int(roadmap.neighbours[east, 2])
    west_of_north = int(roadmap.neighbours[north, 1])
    beyond = int(roadmap.neighbours[corner, 0])
    # robot 0 stands on its goal's place, its goal between four places; robot 1 drives off
    # the corner place (still holding it); robot 2 would step through the north place
    goal = xy[p] + 0.4
    poses = np.zeros((3, 3))
    poses[0, :2] = xy[p]
    poses[1, :2] = xy[corner] + (0.3, 0.0)
    poses[2, :2] = xy[west_of_north]
    traffic.places.node[:] = [p, beyond, west_of_north]
    traffic.places.mode[:] = [STAND, MOVE, STAND]
    traffic.places.came_from[:] = [p, corner, west_of_north]
    traffic.places.held = [[p], [corner], [west_of_north]]
    traffic.places.aim[:] = xy[traffic.places.node]
    assert set(traffic.places.touched(goal, p)) == {p, east, north, corner}
    traffic.places.set_goal(0, goal, p, 0)
    traffic.places.set_goal(2, xy[north] + (1.6, 0.0), int(roadmap.neighbours[beyond, 2]), 0)
    active = np.array([True, False, True])
    traffic.step(poses, active, np.zeros(3, dtype=np.int64), 1)
    assert traffic.places.mode[0] == STAND  # waits for the corner place
    assert traffic.places.node[2] != north  # kept for robot 0's approach


def test_a_robot_that_landed_on_its_next_place_is_driving_off_the_place_it_still_covers(
    monkeypatch,
):
    """Its old place is ``leaving`` for the step: a robot asked to make way whose best place
    it is follows it rather than go round the block (fleet50 seed 36 gave a goal up so)."""
    occupancy = np.zeros((60, 60), dtype=np.int8)  # 6 m x 6 m
    occupancy[0, :] = occupancy[-1, :] = occupancy[:, 0] = occupancy[:, -1] = 100
    static = StaticCostmap.from_grid(OccupancyGrid(0.1, (0.0, 0.0), occupancy), CostmapParams(0.33))
    lanes = np.full(static.cost.shape, TWO_WAY, dtype=np.uint8)
    traffic = FleetTraffic(FleetPlaces(static, lanes, np.array([[1.5, 1.5]]), 0.33))
    roadmap = build_roadmap(
        static.distance_m, static.origin_xy_m, 0.1, traffic.places.spacing_m, 0.33 + CLEARANCE_M
    )
    traffic.places.roadmap = roadmap
    xy = roadmap.xy
    p = int(roadmap.nearest_k(np.array([[2.5, 2.5]]), 1)[0, 0])
    q = int(roadmap.neighbours[p, 0])  # east of p
    seen: list[set[int]] = []

    class Recording(fleet_traffic.Pibt):
        def __init__(self, *args: object) -> None:
            super().__init__(*args)  # type: ignore[arg-type]
            seen.append(set(self.leaving))

    monkeypatch.setattr(fleet_traffic, "Pibt", Recording)
    # the robot drove from p towards q and is within reach of q, its body still over p
    along = (xy[q] - xy[p]) / np.hypot(*(xy[q] - xy[p]))
    poses = np.zeros((1, 3))
    poses[0, :2] = xy[q] - 0.4 * along
    traffic.places.node[:] = [q]
    traffic.places.came_from[:] = [p]
    traffic.places.mode[:] = [MOVE]
    traffic.places.held = [[p]]
    traffic.places.aim[:] = xy[traffic.places.node]
    traffic.step(poses, np.array([False]), np.zeros(1, dtype=np.int64), 1)
    assert traffic.places.mode[0] == STAND and traffic.places.held[0] == [p]
    assert seen == [{p}]


@pytest.mark.parametrize("returning", [True, False])
def test_a_robot_that_let_another_through_off_its_goals_place_keeps_its_places_coming_back(
    returning,
):
    occupancy = np.zeros((60, 60), dtype=np.int8)  # 6 m x 6 m
    occupancy[0, :] = occupancy[-1, :] = occupancy[:, 0] = occupancy[:, -1] = 100
    static = StaticCostmap.from_grid(OccupancyGrid(0.1, (0.0, 0.0), occupancy), CostmapParams(0.33))
    lanes = np.full(static.cost.shape, TWO_WAY, dtype=np.uint8)
    traffic = FleetTraffic(FleetPlaces(static, lanes, np.array([[1.5, 1.5], [4.5, 4.5]]), 0.33))
    roadmap = build_roadmap(
        static.distance_m, static.origin_xy_m, 0.1, traffic.places.spacing_m, 0.33 + CLEARANCE_M
    )
    traffic.places.roadmap = roadmap  # two-way everywhere: only the places matter here
    xy = roadmap.xy
    p = int(roadmap.nearest_k(np.array([[2.5, 2.5]]), 1)[0, 0])
    east, west, north = (int(roadmap.neighbours[p, k]) for k in (0, 1, 2))
    further_east = int(roadmap.neighbours[east, 0])
    # robot 0 made way from its goal's place onto the place north of it; robot 1, east of
    # the place east of it, drives west past the goal
    goal = xy[p] + (0.4, 0.0)
    assert set(traffic.places.touched(goal, p)) == {p, east}
    poses = np.zeros((2, 3))
    poses[0, :2], poses[1, :2] = xy[north], xy[further_east]
    poses[1, 2] = np.pi
    traffic.places.node[:] = [north, further_east]
    traffic.places.came_from[:] = [p, int(roadmap.neighbours[further_east, 0])]
    traffic.places.mode[:] = STAND
    traffic.places.held = [[north], [further_east]]
    traffic.places.aim[:] = xy[traffic.places.node]
    traffic.places.set_goal(0, goal, p, 0)
    traffic.places.set_goal(1, xy[west], west, 0)
    traffic.places.returning[0] = returning
    traffic.step(poses, np.array([True, True]), np.zeros(2, dtype=np.int64), 1)
    assert traffic.places.node[0] == p  # back to its goal's place
    assert (traffic.places.node[1] != east) == returning  # kept for robot 0's approach
