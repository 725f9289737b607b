"""Every robot's goal: taken, driven to, reached or given up, and said on its status topic."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

import cosim
from adapters.navigation.goal_tracking import PROGRESS_M, GoalTracker
from adapters.navigation.parts import NavigationParts, build_parts
from adapters.navigation.topics import status_topic
from cosim.core.adapter import RunContext
from cosim.core.messages import NavGoal, NavStatus
from cosim.core.timebase import s_to_ns
from cosim.runner.assembly import assemble
from tests.conftest import SMALL

# a box in the middle of the hall, and a pen round (9.5, 9.5) that no robot can enter
ROOM = {
    **SMALL,
    "robots.driver": "navigation",
    "world.shelf_count": 0,
    "world.obstacles": [
        [5.0, 5.0, 7.0, 7.0],
        [8.0, 8.0, 11.0, 8.3],
        [8.0, 10.7, 11.0, 11.0],
        [8.0, 8.0, 8.3, 11.0],
        [10.7, 8.0, 11.0, 11.0],
    ],
    "robots.placement": "explicit",
    "robots.positions": [[2.0, 2.0, 0.0], [10.0, 2.0, 1.5708], [2.0, 10.0, 0.0]],
    "navigation.stuck_timeout_s": 2.0,
}


class Goals:
    """The navigation's parts of a small hall, and every status said."""

    def __init__(self, **overrides: Any) -> None:
        scenario = cosim.load_scenario("warehouse-random", {**ROOM, **overrides})
        self.run: RunContext = assemble(scenario, names=["world", "fleet", "lidar"]).run
        self.parts: NavigationParts = build_parts(self.run)
        self.said: list[tuple[str, NavStatus]] = []
        for name in self.parts.names:
            self.run.bus.monitor(status_topic(name), self._keep)

    def _keep(self, topic: str, message: Any, _src: Any, _t: int) -> None:
        self.said.append((topic.split("/")[1], message))

    @property
    def tracker(self) -> GoalTracker:
        return self.parts.goals

    def give(self, i: int, x: float, y: float, goal_id: int = 7) -> None:
        self.tracker.accept(self.run, i, NavGoal(0, goal_id, x, y))

    def states(self) -> list[tuple[str, str]]:
        return [(robot, status.state) for robot, status in self.said]

    def events(self) -> list[tuple[str, str, str]]:
        table = self.run.recorder.tables["navigation"].columns()
        return list(zip(table["robot"], table["event"], table["detail"], strict=True))


@pytest.fixture
def goals() -> Goals:
    return Goals()


def test_a_goal_on_free_floor_is_accepted_planned_and_said_with_the_way_to_go(goals: Goals):
    goals.give(0, 2.0, 6.0)
    [(robot, status)] = goals.said
    assert (robot, status.state, status.goal_id) == ("robot_1", "accepted", 7)
    assert (status.x_m, status.y_m) == (2.0, 2.0)  # where the robot is
    assert status.remaining_m == pytest.approx(4.0, abs=0.3)
    assert goals.tracker.active.tolist() == [True, False, False]
    assert goals.tracker.goal[0].tolist() == [2.0, 6.0]
    assert [e for _, e, _ in goals.events()] == ["goal", "plan"]
    assert goals.parts.paths.lengths[0] >= 2  # the path it now follows


@pytest.mark.parametrize(
    ("goal", "detail"),
    [((6.0, 6.0), "in_obstacle"), ((30.0, 2.0), "outside"), ((9.5, 9.5), "enclosed")],
)
def test_a_goal_that_cannot_be_reached_is_dropped_as_unreachable_saying_why(goals, goal, detail):
    goals.give(1, *goal)
    [(robot, status)] = goals.said
    assert (robot, status.state) == ("robot_2", "unreachable")
    assert math.isnan(status.remaining_m)
    assert not goals.tracker.active.any()
    assert goals.events()[-1] == ("robot_2", "unreachable", detail)
    assert goals.parts.paths.lengths[1] == 0


def test_a_goal_without_a_position_cancels_the_robots_goal(goals: Goals):
    goals.give(0, 2.0, 6.0, goal_id=1)
    goals.give(0, math.nan, math.nan, goal_id=2)
    assert goals.states() == [("robot_1", "accepted"), ("robot_1", "cancelled")]
    assert goals.said[-1][1].goal_id == 2
    assert not goals.tracker.active[0] and goals.parts.paths.lengths[0] == 0
    assert goals.events()[-1][:2] == ("robot_1", "cancelled")


def test_cancelling_when_no_goal_is_active_is_said_but_not_recorded(goals: Goals):
    goals.give(2, math.inf, 1.0)
    assert goals.states() == [("robot_3", "cancelled")]
    assert goals.events() == []


def test_a_robot_within_the_tolerance_has_arrived_and_its_way_is_measured(goals: Goals):
    goals.give(0, 2.0, 6.0)
    goals.tracker.arrivals(goals.run, s_to_ns(1.0))
    assert goals.states() == [("robot_1", "accepted")]  # 4 m away
    goals.parts.pose[0, :2] = (2.1, 5.85)  # within 0.25 m
    goals.tracker.arrivals(goals.run, s_to_ns(8.0))
    assert goals.states()[-1] == ("robot_1", "arrived")
    assert goals.said[-1][1].remaining_m == 0.0
    assert not goals.tracker.active[0] and goals.parts.paths.lengths[0] == 0
    assert goals.parts.records.shortest_m[0] == pytest.approx(4.0, abs=0.3)
    assert goals.parts.records.times_s == [8.0]
    assert goals.events()[-1][:2] == ("robot_1", "arrived")


def test_no_progress_for_the_stuck_timeout_is_said_once_per_stall(goals: Goals):
    goals.give(0, 2.0, 6.0)
    way = np.array([4.0, 0.0, 0.0])
    for t_s in (0.5, 1.0, 1.5):
        goals.tracker.track(goals.run, s_to_ns(t_s), way)
    assert goals.states() == [("robot_1", "accepted")]
    for t_s in (2.0, 2.5, 3.0):  # 2 s without the way shrinking
        goals.tracker.track(goals.run, s_to_ns(t_s), way)
    assert goals.states() == [("robot_1", "accepted"), ("robot_1", "stuck")]
    assert goals.said[-1][1].remaining_m == 4.0
    robot, event, detail = goals.events()[-1]
    assert (robot, event) == ("robot_1", "stuck")
    assert detail.startswith("no progress for 2 s: halted (drove 0.0 m")
    assert goals.parts.records.stuck_kinds == {"halted": 1}


def test_progress_ends_a_stall_and_a_new_stall_is_said_again(goals: Goals):
    goals.give(0, 2.0, 6.0)
    goals.tracker.track(goals.run, s_to_ns(0.1), np.array([4.0, 0.0, 0.0]))
    goals.tracker.track(goals.run, s_to_ns(2.2), np.array([4.0, 0.0, 0.0]))
    shrunk = 4.0 - PROGRESS_M - 0.01
    goals.tracker.track(goals.run, s_to_ns(2.5), np.array([shrunk, 0.0, 0.0]))
    assert not goals.tracker.stuck[0]
    goals.tracker.track(goals.run, s_to_ns(4.0), np.array([shrunk, 0.0, 0.0]))
    goals.tracker.track(goals.run, s_to_ns(4.6), np.array([shrunk, 0.0, 0.0]))
    assert [s for _, s in goals.states()].count("stuck") == 2


def test_time_stuck_runs_from_the_last_progress_to_the_next_or_to_the_end(goals: Goals):
    goals.give(0, 2.0, 6.0)
    goals.tracker.track(goals.run, s_to_ns(0.1), np.array([4.0, 0.0, 0.0]))  # progress
    goals.tracker.track(goals.run, s_to_ns(2.2), np.array([4.0, 0.0, 0.0]))  # stuck
    goals.tracker.track(goals.run, s_to_ns(2.5), np.array([3.5, 0.0, 0.0]))  # progress
    assert goals.parts.records.stuck_s == pytest.approx(2.4)  # the whole stall, 0.1-2.5 s
    goals.tracker.track(goals.run, s_to_ns(4.6), np.array([3.5, 0.0, 0.0]))  # stuck again
    goals.tracker.close(s_to_ns(6.0))  # the run ends in the stall
    assert goals.parts.records.stuck_s == pytest.approx(2.4 + 3.5)
    goals.tracker.close(s_to_ns(9.0))  # counted once
    assert goals.parts.records.stuck_s == pytest.approx(5.9)


def test_a_stall_without_a_stuck_report_is_not_time_stuck(goals: Goals):
    goals.give(0, 2.0, 6.0)
    goals.tracker.track(goals.run, s_to_ns(0.1), np.array([4.0, 0.0, 0.0]))
    goals.tracker.track(goals.run, s_to_ns(1.5), np.array([4.0, 0.0, 0.0]))  # under 2 s
    goals.tracker.track(goals.run, s_to_ns(1.8), np.array([3.5, 0.0, 0.0]))
    goals.tracker.close(s_to_ns(3.0))
    assert goals.parts.records.stuck_s == 0.0


def test_a_way_shrinking_by_less_than_the_progress_step_is_no_progress(goals: Goals):
    goals.give(0, 2.0, 6.0)
    goals.tracker.track(goals.run, 0, np.array([4.0, 0.0, 0.0]))
    for k, t_s in enumerate((0.5, 1.0, 1.5, 2.0)):
        way = 4.0 - (k + 1) * PROGRESS_M / 5  # creeping
        goals.tracker.track(goals.run, s_to_ns(t_s), np.array([way, 0.0, 0.0]))
    assert goals.states()[-1] == ("robot_1", "stuck")


def test_progress_is_reported_for_robots_with_a_goal_only(goals: Goals):
    goals.give(0, 2.0, 6.0)
    goals.give(2, 2.0, 7.0)
    goals.said.clear()
    goals.tracker.report(goals.run, np.array([3.5, 9.0, 2.5]))
    assert [(r, s.state, s.remaining_m) for r, s in goals.said] == [
        ("robot_1", "progress", 3.5),
        ("robot_3", "progress", 2.5),
    ]
