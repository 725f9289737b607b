"""Global planning of every robot: when it plans, on what, and what it does with a path."""

from __future__ import annotations

import itertools
import math
from typing import Any

import numpy as np
import pytest

import cosim
from adapters.navigation.parts import NavigationParts, build_parts
from adapters.navigation.planning import OFF_MAP, GlobalPlanning
from adapters.navigation.topics import plan_topic
from cosim.core.adapter import RunContext
from cosim.core.hosts import HostId
from cosim.core.messages import Path
from cosim.core.timebase import s_to_ns
from cosim.runner.assembly import assemble
from models.navigation.planner import shortest_path_length_m
from models.navigation.traffic import MovingPoints
from tests.conftest import SMALL

BOX = (5.0, 5.0, 7.0, 7.0)
ROOM = {
    **SMALL,
    "robots.driver": "navigation",
    "world.shelf_count": 0,
    "world.obstacles": [list(BOX), [8.0, 8.0, 11.0, 8.3], [8.0, 10.7, 11.0, 11.0],
                        [8.0, 8.0, 8.3, 11.0], [10.7, 8.0, 11.0, 11.0]],
    "robots.placement": "explicit",
    "robots.positions": [[2.0, 2.0, 0.0], [10.0, 2.0, 1.5708], [2.0, 10.0, 0.0]],
}  # fmt: skip


class Planning:
    """A small hall's navigation parts, with every plan published heard."""

    def __init__(self, **overrides: Any) -> None:
        scenario = cosim.load_scenario("warehouse-random", {**ROOM, **overrides})
        self.run: RunContext = assemble(scenario, names=["world", "fleet", "lidar"]).run
        self.parts: NavigationParts = build_parts(self.run)
        self.plans: list[tuple[str, HostId, Path]] = []
        for name in self.parts.names:
            self.run.bus.monitor(plan_topic(name), self._keep)

    def _keep(self, topic: str, message: Any, src: HostId, _t: int) -> None:
        self.plans.append((topic, src, message))

    @property
    def planning(self) -> GlobalPlanning:
        return self.parts.planning

    def aim(self, i: int, x: float, y: float) -> None:
        self.parts.goals.goal[i] = (x, y)

    def rows(self) -> list[dict[str, Any]]:
        table = self.run.recorder.tables["navigation"].columns()
        return [{k: v[j] for k, v in table.items()} for j in range(len(table["event"]))]


@pytest.fixture
def hall() -> Planning:
    return Planning()


def _clear_of_box(waypoints: np.ndarray, margin: float) -> bool:
    """Whether every stretch of the path keeps ``margin`` off the box (sampled every 2 cm)."""
    x0, y0, x1, y1 = BOX
    for a, b in itertools.pairwise(waypoints):
        for t in np.linspace(0.0, 1.0, max(2, int(np.hypot(*(b - a)) / 0.02))):
            x, y = a + t * (b - a)
            dx, dy = max(x0 - x, 0.0, x - x1), max(y0 - y, 0.0, y - y1)
            if math.hypot(dx, dy) < margin:
                return False
    return True


def test_a_route_goes_from_the_robot_to_exactly_its_goal(hall: Planning):
    hall.aim(0, 2.0, 6.0)
    route, detail, points = hall.planning.route(0, 0, replan=False)
    assert route is not None and detail == "" and len(points) == 0
    waypoints, length = route
    assert waypoints[-1].tolist() == [2.0, 6.0]
    assert np.hypot(*(waypoints[0] - (2.0, 2.0))) < 0.15
    assert length == pytest.approx(4.0, abs=0.2)


def test_a_route_keeps_the_robots_footprint_off_the_box_in_its_way(hall: Planning):
    hall.parts.pose[0] = (4.0, 6.0, 0.0)
    hall.aim(0, 8.0, 6.0)
    route, _, _ = hall.planning.route(0, 0, replan=False)
    assert route is not None
    waypoints, length = route
    assert length > 4.5  # round the box, not through it
    assert _clear_of_box(waypoints, hall.parts.radius_m)


def test_a_planned_path_is_followed_and_published_from_the_robots_host(hall: Planning):
    hall.aim(2, 6.0, 10.0)
    assert hall.planning.plan(hall.run, 2, s_to_ns(1.0), replan=False)
    [(topic, src, path)] = hall.plans
    assert (topic, src, path.frame_id) == ("/robot_3/plan", "robot_3", "map")
    np.testing.assert_array_equal(path.xy_m, hall.parts.paths.waypoints(2))
    assert hall.planning.next_plan_ns[2] == s_to_ns(2.0)  # 1 Hz replanning
    [row] = hall.rows()
    assert (row["robot"], row["event"], row["detail"]) == ("robot_3", "plan", "")
    assert row["path_length_m"] == pytest.approx(4.0, abs=0.2)
    assert row["plan_ms"] >= 0 and (row["goal_x_m"], row["goal_y_m"]) == (6.0, 10.0)


def test_a_robot_off_its_costmap_gets_no_plan_and_drops_its_path(hall: Planning):
    hall.aim(0, 2.0, 6.0)
    hall.planning.plan(hall.run, 0, 0, replan=False)
    hall.parts.pose[0] = (-5.0, 2.0, 0.0)
    assert hall.planning.off_map(0)
    route, detail, _ = hall.planning.route(0, s_to_ns(1.0), replan=True)
    assert (route, detail) == (None, OFF_MAP)
    assert not hall.planning.plan(hall.run, 0, s_to_ns(1.0), replan=True)
    assert hall.parts.paths.lengths[0] == 0
    last = hall.rows()[-1]
    assert (last["event"], last["detail"]) == ("replan", "off the map")
    assert math.isnan(last["path_length_m"])


def test_a_goal_without_a_way_is_planned_again_at_the_next_replan(hall: Planning):
    hall.aim(1, 9.5, 9.5)  # in the pen
    assert not hall.planning.plan(hall.run, 1, s_to_ns(3.0), replan=False)
    last = hall.rows()[-1]
    assert (last["event"], last["detail"]) == ("plan", "no path")
    assert hall.planning.next_plan_ns[1] == s_to_ns(4.0)
    assert hall.plans == []


def test_what_moves_across_the_way_is_planned_round_and_a_wall_of_it_is_cleared(hall: Planning):
    hall.aim(0, 2.0, 6.0)
    wall = np.stack([np.arange(0.0, 12.0, 0.05), np.full(240, 4.0)], axis=1)
    hall.parts.moving.remember(0, np.zeros(len(wall), dtype=np.int64), wall)
    route, detail, points = hall.planning.route(0, 0, replan=False)
    assert len(points) > 0  # what it planned round
    assert route is not None and detail == "cleared"  # as Nav2's clear-costmap recovery
    assert route[1] == pytest.approx(4.0, abs=0.2)


def test_a_replan_first_repairs_the_stretch_ahead(hall: Planning):
    hall.aim(0, 2.0, 6.0)
    hall.planning.plan(hall.run, 0, 0, replan=False)
    route, detail, _ = hall.planning.route(0, s_to_ns(1.0), replan=True)
    assert route is not None and detail == "repaired"
    assert route[0][-1].tolist() == [2.0, 6.0]


def test_the_yardstick_is_the_shortest_way_on_the_true_map(hall: Planning):
    start, goal = np.array([4.0, 6.0]), np.array([8.0, 6.0])
    expected = shortest_path_length_m(hall.parts.static, start, goal)
    assert hall.planning.yardstick(start, goal) == expected > 4.0
    assert hall.planning.yardstick(np.array([2.0, 2.0]), np.array([9.5, 9.5])) == math.inf


def _nothing_moving() -> MovingPoints:
    empty = np.zeros(0)
    return MovingPoints(empty.astype(np.int64), np.zeros((0, 2)), empty, empty)


def test_a_due_replan_happens_only_when_something_moving_may_change_the_path(hall: Planning):
    hall.aim(0, 2.0, 6.0)
    hall.aim(2, 6.0, 10.0)
    for i in (0, 2):
        hall.planning.plan(hall.run, i, 0, replan=False)
    hall.planning.planned_around[2] = True  # its last plan bent round something moving
    active = np.array([True, False, True])
    hall.planning.replan_due(hall.run, s_to_ns(0.5), active, _nothing_moving())
    assert [r["event"] for r in hall.rows()] == ["plan", "plan"]  # none due yet
    hall.planning.replan_due(hall.run, s_to_ns(1.0), active, _nothing_moving())
    assert [(r["robot"], r["event"]) for r in hall.rows()][2:] == [("robot_3", "replan")]
    assert hall.planning.next_plan_ns[0] == s_to_ns(2.0)  # looked again in a second


def test_something_moving_on_the_path_ahead_calls_for_a_replan(hall: Planning):
    hall.aim(0, 2.0, 6.0)
    hall.planning.plan(hall.run, 0, 0, replan=False)
    seen = MovingPoints(np.array([0]), np.array([[2.0, 4.0]]), np.zeros(1), np.zeros(1))
    hall.planning.replan_due(hall.run, s_to_ns(1.0), np.array([True, False, False]), seen)
    assert [(r["robot"], r["event"]) for r in hall.rows()] == [
        ("robot_1", "plan"),
        ("robot_1", "replan"),
    ]
