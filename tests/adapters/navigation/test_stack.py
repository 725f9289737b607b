"""Navigation in crafted worlds: unreachable goals, detours, head-on encounters, deadlocks."""

from collections.abc import Mapping
from typing import Any, ClassVar

import numpy as np
import pytest

import cosim
from adapters.naming import topic
from cosim.core.adapter import RunContext
from cosim.core.hosts import HostId
from cosim.core.kernel import Stage
from cosim.core.messages import Message, NavGoal, NavStatus
from cosim.core.registry import AdapterRegistry
from cosim.core.timebase import s_to_ns
from cosim.runner.execute import execute
from models.fleet.kinematics import FleetState
from models.navigation.costmap import StaticCostmap
from models.navigation.planner import shortest_path_length_m
from models.world.obstacles import DynamicObstacles


class GoalScript:
    """Test robot software: sends scripted goals, keeps every status."""

    name: ClassVar[str] = "goal_script"
    requires: ClassVar[tuple[str, ...]] = ("navigation",)
    goals: ClassVar[list[tuple[float, str, float, float]]] = []
    statuses: ClassVar[list[tuple[float, str, str, int]]] = []
    static: ClassVar[StaticCostmap | None] = None

    def __init__(self, run: RunContext) -> None:
        GoalScript.statuses = []
        self.names = run.service(FleetState).names

    def start(self, run: RunContext) -> None:
        GoalScript.static = run.service(StaticCostmap)
        for name in self.names:

            def keep(message: Message, envelope: Any, name: str = name) -> None:
                assert isinstance(message, NavStatus)
                GoalScript.statuses.append(
                    (envelope.t_recv_ns / 1e9, name, message.state, message.goal_id)
                )

            run.bus.subscribe(topic(name, "nav/status"), HostId(name), keep)
        for k, (t_s, robot, x, y) in enumerate(GoalScript.goals):

            def send(robot: str = robot, x: float = x, y: float = y, k: int = k) -> None:
                goal = NavGoal(run.kernel.now_ns, k, x, y)
                run.bus.publish(topic(robot, "nav/goal"), goal, HostId(robot))

            run.kernel.at(s_to_ns(t_s), send)

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        return {}


class Blockers:
    """Test obstacles: discs present during [from_s, to_s)."""

    name: ClassVar[str] = "blockers"
    requires: ClassVar[tuple[str, ...]] = ("world",)
    discs: ClassVar[list[tuple[float, float, float]]] = []
    window: ClassVar[tuple[float, float]] = (0.0, 0.0)

    def __init__(self, run: RunContext) -> None:
        self.dynamic = run.service(DynamicObstacles)

    def start(self, run: RunContext) -> None:
        names = [f"person_{i}" for i in range(len(Blockers.discs))]

        def place(present: bool) -> None:
            discs = np.array(Blockers.discs) if present else np.zeros((0, 3))
            self.dynamic.update("blockers", discs, names if present else [])

        start, end = Blockers.window
        run.kernel.at(s_to_ns(start), lambda: place(True), Stage.PHYSICS)
        run.kernel.at(s_to_ns(end), lambda: place(False), Stage.PHYSICS)

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        return {}


REGISTRY = AdapterRegistry.from_entry_points().with_adapter(GoalScript).with_adapter(Blockers)
NAMES = ["world", "fleet", "network", "collisions", "lidar", "navigation", "poses", "goal_script"]


def _run(overrides: dict[str, Any], goals, *, extra=(), duration_s=40.0):
    GoalScript.goals = goals
    scenario = cosim.load_scenario(
        "warehouse-random",
        {
            "world.shelf_count": 0,
            "robots.placement": "explicit",
            "scenario.duration_s": duration_s,
            **overrides,
        },
    )
    return execute(scenario, names=NAMES + list(extra), registry=REGISTRY)


def _states(robot: str) -> list[str]:
    return [
        state for _, name, state, _ in GoalScript.statuses if name == robot and state != "progress"
    ]


ROOM = {
    "world.size_m": [12.0, 8.0],
    "robots.count": 1,
    "robots.positions": [[1.5, 4.0, 0.0]],
    "world.obstacles": [[5.0, 2.5, 7.0, 5.5]],
}


def test_a_robot_drives_around_a_box_to_its_goal():
    result = _run(ROOM, [(0.0, "robot_1", 10.5, 4.0)])
    assert _states("robot_1") == ["accepted", "arrived"]
    assert result.summary["collisions"] == 0
    assert result.summary["arrivals"] == 1
    assert 1.0 <= result.summary["path_length_ratio"] < 1.3


def test_the_path_length_ratio_measures_against_the_shortest_way_from_where_each_goal_started():
    # the robot stands exactly where it is at t = 0: its yardstick waits for the arrival,
    # and is the shortest way from where the goal started, not from where it ended
    result = _run(ROOM, [(0.0, "robot_1", 10.5, 4.0)], duration_s=20.0)
    navigation = result.tables["navigation"]
    driven = float(navigation.query("event == 'arrived'")["path_length_m"].iloc[0])
    assert GoalScript.static is not None
    shortest = shortest_path_length_m(GoalScript.static, (1.5, 4.0), (10.5, 4.0))
    assert result.summary["path_length_ratio"] == pytest.approx(driven / shortest, rel=1e-6)
    assert 1.0 <= driven / shortest < 1.3


@pytest.mark.parametrize(
    ("goal", "detail"),
    [((6.0, 4.0), "in_obstacle"), ((20.0, 4.0), "outside"), ((-3.0, 1.0), "outside")],
)
def test_a_goal_inside_an_obstacle_or_outside_the_room_is_reported_unreachable(goal, detail):
    result = _run(ROOM, [(0.0, "robot_1", *goal)], duration_s=2.0)
    assert _states("robot_1") == ["unreachable"]
    navigation = result.tables["navigation"]
    row = navigation[navigation["event"] == "unreachable"]
    assert list(row["detail"]) == [detail]
    assert result.summary["goals_unreachable"] == 1


def test_an_enclosed_goal_is_reported_unreachable():
    walls = [
        [6.0, 2.0, 10.0, 2.3],
        [6.0, 5.7, 10.0, 6.0],
        [6.0, 2.0, 6.3, 6.0],
        [9.7, 2.0, 10.0, 6.0],
    ]
    result = _run({**ROOM, "world.obstacles": walls}, [(0.0, "robot_1", 8.0, 4.0)], duration_s=2.0)
    assert _states("robot_1") == ["unreachable"]
    assert list(result.tables["navigation"].query("event == 'unreachable'")["detail"]) == [
        "enclosed"
    ]


def test_a_suddenly_blocked_aisle_triggers_replanning_and_a_detour():
    # a wall across the room with two gaps: the near one (y 1-2.5) is blocked at t = 2 s
    wall = [[6.0, 0.0, 6.5, 1.0], [6.0, 2.5, 6.5, 5.5], [6.0, 7.0, 6.5, 8.0]]
    Blockers.discs = [(6.25, 1.45, 0.3), (6.25, 2.05, 0.3)]
    Blockers.window = (2.0, 100.0)
    overrides = {
        "world.size_m": [12.0, 8.0],
        "robots.count": 1,
        "robots.positions": [[1.5, 1.75, 0.0]],
        "world.obstacles": wall,
    }
    result = _run(overrides, [(0.0, "robot_1", 10.5, 1.75)], extra=["blockers"], duration_s=40.0)
    assert _states("robot_1") == ["accepted", "arrived"]
    poses = result.tables["poses"]
    crossing = poses[(poses["x_m"] > 6.0) & (poses["x_m"] < 6.5)]
    assert crossing["y_m"].min() > 5.5  # went through the far gap
    navigation = result.tables["navigation"]
    assert (navigation.query("event == 'replan' and t_s >= 2.0")["path_length_m"] > 12.0).any()
    assert result.summary["collisions"] == 0


def test_two_robots_head_on_in_a_corridor_pass_without_collision():
    corridor = [[3.0, 0.0, 9.0, 3.0], [3.0, 5.2, 9.0, 8.0]]  # a 2.2 m wide corridor
    overrides = {
        "world.size_m": [12.0, 8.0],
        "robots.count": 2,
        "robots.positions": [[1.5, 4.1, 0.0], [10.5, 4.1, 3.14159]],
        "world.obstacles": corridor,
    }
    goals = [(0.0, "robot_1", 10.5, 4.1), (0.0, "robot_2", 1.5, 4.1)]
    result = _run(overrides, goals, duration_s=60.0)
    assert result.summary["collisions"] == 0
    assert result.summary["min_clearance_m"] > 0
    assert _states("robot_1")[-1] == "arrived"
    assert _states("robot_2")[-1] == "arrived"


def test_a_boxed_in_robot_reports_stuck_and_recovers_when_the_others_leave():
    # eight people in a ring 0.75 m around the robot: no way out until they leave
    ring = [
        (1.5 + 0.75 * np.cos(a), 4.0 + 0.75 * np.sin(a), 0.3)
        for a in np.linspace(0, 2 * np.pi, 8, endpoint=False)
    ]
    Blockers.discs = ring
    Blockers.window = (0.0, 12.0)
    overrides = {**ROOM, "navigation.stuck_timeout_s": 5.0}
    result = _run(overrides, [(0.0, "robot_1", 10.5, 4.0)], extra=["blockers"], duration_s=40.0)
    states = _states("robot_1")
    assert states[0] == "accepted"
    assert "stuck" in states
    assert states[-1] == "arrived"
    stuck_t = next(t for t, _, s, _ in GoalScript.statuses if s == "stuck")
    arrived_t = next(t for t, _, s, _ in GoalScript.statuses if s == "arrived")
    assert 5.0 <= stuck_t < 12.0 < arrived_t
    assert result.summary["collisions"] == 0
    assert result.summary["deadlocks"] == 1
    # boxed in, it hardly moved: the report says so
    assert (result.summary["stuck_halted"], result.summary["stuck_detoured"]) == (1, 0)
    nav = result.tables["navigation"]
    (detail,) = nav[nav["event"] == "stuck"]["detail"]
    assert detail.startswith("no progress for 5 s: halted (drove 0.")


def test_the_robots_layer_sends_poses_over_the_network_and_keeps_robots_apart():
    corridor = [[3.0, 0.0, 9.0, 3.0], [3.0, 5.2, 9.0, 8.0]]
    overrides = {
        "world.size_m": [12.0, 8.0],
        "robots.count": 2,
        "robots.positions": [[1.5, 4.1, 0.0], [10.5, 4.1, 3.14159]],
        "world.obstacles": corridor,
        "navigation.robots_layer": True,
        "network.latency_ms": 20.0,
    }
    goals = [(0.0, "robot_1", 10.5, 4.1), (0.0, "robot_2", 1.5, 4.1)]
    result = _run(overrides, goals, duration_s=40.0)
    messages = result.tables["messages"]
    states = messages[
        (messages["topic"] == "/fleet/robot_states")
        & (messages["src_host"] != messages["dst_host"])
    ]
    assert len(states) > 0
    assert set(states["status"]) == {"delivered"}
    assert np.allclose(states["t_recv_s"] - states["t_sent_s"], 0.02)
    assert result.summary["collisions"] == 0
    assert _states("robot_1")[-1] == "arrived" and _states("robot_2")[-1] == "arrived"


def test_progress_is_reported_while_driving():
    _run(ROOM, [(0.0, "robot_1", 10.5, 4.0)])
    progress = [t for t, name, state, _ in GoalScript.statuses if state == "progress"]
    assert len(progress) >= 5
    assert np.allclose(np.diff(progress), 1.0)


@pytest.mark.slow
def test_with_one_way_lanes_robots_reach_goals_without_collision_and_repair_their_paths():
    scenario = cosim.load_scenario(
        "fleet50",
        {
            "navigation.traffic": "lanes",
            "robots.count": 12,
            "scenario.duration_s": 40.0,
            "record.bag": "none",
        },
    )
    result = cosim.run(scenario)
    assert result.summary["collisions"] == 0
    assert result.summary["arrivals"] > 0
    details = set(result.tables["navigation"].query("event == 'replan'")["detail"])
    assert "repaired" in details


def test_an_unknown_traffic_policy_is_refused_naming_the_key_and_the_choices():
    expected = r"\[navigation\] traffic = 'roundabouts': expected a registered traffic policy"
    with pytest.raises(cosim.ConfigError, match=expected) as refused:
        cosim.load_scenario("fleet50", {"navigation.traffic": "roundabouts"})
    assert "(registered: lanes, none, pibt)" in str(refused.value)


def test_robots_that_map_drive_on_the_buildings_lanes_laid_into_their_wider_maps():
    from adapters.navigation.layers import lanes_on
    from adapters.navigation.traffic_policies import LANE_WIDTH_M
    from adapters.world.warehouse import scenario_warehouse
    from models.geometry.occupancy import OCCUPIED, OccupancyGrid
    from models.navigation.costmap import CostmapParams, StaticCostmap
    from models.navigation.lanes import TWO_WAY, aisle_lanes
    from models.world.warehouse import ground_truth_grid

    scenario = cosim.load_scenario("warehouse-mapping", {"navigation.traffic": "lanes"})
    truth = ground_truth_grid(scenario_warehouse(scenario), 0.1)
    margin = np.zeros((truth.data.shape[0] + 20, truth.data.shape[1] + 20), dtype=np.int8)
    wider = OccupancyGrid(0.1, (truth.origin_xy_m[0] - 1.0, truth.origin_xy_m[1] - 1.0), margin)
    layer = StaticCostmap.from_grid(wider, CostmapParams(0.3))
    placed = lanes_on(layer, truth, LANE_WIDTH_M)
    assert placed.shape == layer.cost.shape
    assert np.array_equal(placed[10:-10, 10:-10], aisle_lanes(truth.data >= OCCUPIED, 0.1, 2.5))
    assert (placed[:10] == TWO_WAY).all() and (placed[:, -10:] == TWO_WAY).all()
    result = cosim.run(scenario.with_duration(20.0))
    assert result.summary["collisions"] == 0
