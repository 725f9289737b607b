"""A measured pose off the map: the robot stops, the navigation records it, nothing raises."""

from collections.abc import Mapping
from types import SimpleNamespace
from typing import Any, ClassVar

import numpy as np
import pytest

import cosim
from adapters.mocap.intake import pose_topic
from adapters.navigation.off_map import OffMapWatch
from cosim.core.adapter import RunContext
from cosim.core.hosts import HostId
from cosim.core.kernel import Stage
from cosim.core.messages import PoseStamped
from cosim.core.registry import AdapterRegistry
from cosim.core.timebase import ms_to_ns, s_to_ns
from cosim.runner.execute import execute
from tests.adapters.navigation.test_stack import NAMES, GoalScript

OFF_FROM_S, OFF_TO_S = 2.0, 3.0
"""When the bogus poses come (s)."""


class BogusPoses:
    """Sends robot_1's software a pose 30 m off the map every 5 ms for a second."""

    name: ClassVar[str] = "bogus_poses"
    requires: ClassVar[tuple[str, ...]] = ("mocap",)

    def __init__(self, run: RunContext) -> None:
        pass

    def start(self, run: RunContext) -> None:
        kernel = run.kernel
        for k in range(round((OFF_TO_S - OFF_FROM_S) / 0.005)):
            t_ns = s_to_ns(OFF_FROM_S) + k * ms_to_ns(5.0)

            def send(t_ns: int = t_ns) -> None:
                pose = PoseStamped(t_ns + 1, "map", -30.0, 40.0, 0.0)
                run.bus.publish(pose_topic("robot_1"), pose, HostId("mocap"))

            kernel.at(t_ns, send, Stage.SENSING)

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        return {}


@pytest.mark.slow
def test_a_robot_whose_pose_is_off_the_map_stops_records_it_and_drives_on_when_it_is_back():
    GoalScript.goals = [(0.0, "robot_1", 10.5, 4.0), (2.5, "robot_1", 10.5, 2.0)]
    scenario = cosim.load_scenario(
        "warehouse-random",
        {
            "world.shelf_count": 0,
            "world.size_m": [12.0, 8.0],
            "robots.placement": "explicit",
            "robots.count": 1,
            "robots.positions": [[1.5, 4.0, 0.0]],
            "mocap.source": "simulated",
            "mocap.max_age_ms": 10000.0,  # off the map, not stale, is what stops it
            "scenario.duration_s": 30.0,
        },
    )
    registry = AdapterRegistry.from_entry_points().with_adapter(GoalScript)
    registry = registry.with_adapter(BogusPoses)
    result = execute(scenario, names=[*NAMES, "mocap", "bogus_poses"], registry=registry)
    nav = result.tables["navigation"]
    rows = [(row.t_s, row.event, row.detail) for row in nav.itertuples() if row.t_s >= OFF_FROM_S]
    assert rows[:4] == [
        (2.0, "off_map", "pose (-30.00, 40.00) m outside the 124x84 costmap: stopped"),
        (2.5, "goal", ""),
        (2.5, "plan", "off the map"),  # the goal given while off the map: no plan, no error
        (3.1, "on_map", "pose (3.40, 4.04) m: back on the costmap"),
    ]
    assert rows[4][:2] == (3.1, "replan")  # back on the map: a fresh plan at once
    assert rows[-1][1] == "arrived" and result.summary["arrivals"] == 1
    events = result.tables["events"]
    assert list(events[events.source == "robot_1"].kind) == ["off_map", "on_map", "arrived"]
    # the robot braked and stood while its software believed it off the map
    poses = result.tables["poses"]
    standing = poses[(poses.t_s >= OFF_FROM_S + 0.5) & (poses.t_s <= OFF_TO_S)]
    assert standing.v_mps.abs().max() == 0.0


RUN: Any = SimpleNamespace()
"""The run: only the planner, a stand-in here, would read it."""


class Kept:
    """Stands in for the navigation table and the planner: keeps rows and plans asked for."""

    def __init__(self) -> None:
        self.rows: list[tuple[Any, ...]] = []
        self.plans: list[tuple[int, int, bool]] = []

    def row(self, now_ns: int, i: int, event: str, x: float, y: float, *, detail: str) -> None:
        self.rows.append((now_ns, i, event, x, y, detail))

    def plan(self, run: Any, i: int, now_ns: int, *, replan: bool) -> None:
        self.plans.append((i, now_ns, replan))


def _watch(pose: np.ndarray, *, replan: bool = True) -> tuple[OffMapWatch, Kept]:
    """A watch over a 10 m x 5 m costmap of 0.1 m cells from (-1, -1); both robots have goals."""
    static: Any = SimpleNamespace(origin_xy_m=(-1.0, -1.0), resolution_m=0.1, width=100, height=50)
    goals: Any = SimpleNamespace(
        goal=np.array([[2.0, 3.0], [4.0, 1.0]]), active=np.array([True, True])
    )
    kept: Any = Kept()
    watch = OffMapWatch(static, pose, goals, kept, kept, replan=replan)
    return watch, kept


def test_a_robot_leaving_the_costmap_is_off_and_recorded_once():
    pose = np.array([[0.0, 0.0, 0.0], [8.0, 3.0, 0.0]])
    watch, kept = _watch(pose)
    assert watch.check(RUN, 1).tolist() == [False, False]
    pose[1] = (9.05, 3.0, 0.0)  # beyond the last cell (x < 9 m)
    assert watch.check(RUN, 2).tolist() == [False, True]
    assert watch.check(RUN, 3).tolist() == [False, True]
    assert kept.rows == [
        (2, 1, "off_map", 4.0, 1.0, "pose (9.05, 3.00) m outside the 100x50 costmap: stopped")
    ]
    assert kept.plans == []


def test_a_robot_whose_pose_is_not_a_number_is_off_the_costmap():
    watch, _ = _watch(np.array([[np.nan, 0.0, 0.0], [0.0, -1.01, 0.0]]))
    assert watch.check(RUN, 1).tolist() == [True, True]


def test_a_robot_back_on_the_costmap_with_a_goal_plans_again_at_once():
    pose = np.array([[-30.0, 40.0, 0.0], [0.0, 0.0, 0.0]])
    watch, kept = _watch(pose)
    watch.check(RUN, 1)
    pose[0] = (0.5, 0.5, 0.0)
    assert not watch.check(RUN, 2).any()
    assert kept.rows[-1] == (2, 0, "on_map", 2.0, 3.0, "pose (0.50, 0.50) m: back on the costmap")
    assert kept.plans == [(0, 2, True)]


def test_a_robot_back_on_the_costmap_plans_nothing_when_a_fleet_manager_moves_it():
    pose = np.array([[-30.0, 40.0, 0.0], [0.0, 0.0, 0.0]])
    watch, kept = _watch(pose, replan=False)
    watch.check(RUN, 1)
    pose[0] = (0.5, 0.5, 0.0)
    watch.check(RUN, 2)
    assert [row[2] for row in kept.rows] == ["off_map", "on_map"] and kept.plans == []
