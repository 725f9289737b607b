import math
from dataclasses import dataclass

import numpy as np
import pytest

import cosim
from adapters.drivers.topics import waypoint_topic
from adapters.drivers.waypoints import (
    GOAL_TIMEOUT_S,
    SIGHT_MARGIN_M,
    STALL_S,
    WaypointsAdapter,
)
from adapters.fleet.topics import cmd_vel_topic, odom_topic
from cosim.core.hosts import HostId
from cosim.core.kernel import Stage
from cosim.core.messages import Goal, Odometry, Twist
from cosim.core.timebase import s_to_ns
from cosim.recording.dataframes import table_frame
from cosim.runner.assembly import Assembly, assemble
from cosim.scenario.sections import RobotsConfig
from tests.conftest import SMALL

NAMES = ["robot_1", "robot_2", "robot_3"]


@dataclass
class Driven:
    """The waypoints driver alone (no motion: odometry only when a test sends it)."""

    assembly: Assembly
    driver: WaypointsAdapter
    goals: list[tuple[int, str, Goal]]
    commands: list[tuple[int, str, Twist]]

    def events(self, kind: str) -> list[tuple[float, str, str]]:
        frame = table_frame(self.assembly.run.recorder.events)
        rows = frame[frame.kind == kind]
        return list(zip(rows.t_ns / 1e9, rows.source, rows.detail, strict=True))

    def odometry(self, robot: int, x: float, y: float, yaw: float = 0.0) -> None:
        run, name = self.assembly.run, NAMES[robot]
        odom = Odometry(run.kernel.now_ns, "odom", "base_link", x, y, yaw, 0.0, 0.0)
        run.bus.publish(odom_topic(name), odom, HostId(name))

    def run(self, t_s: float) -> None:
        self.assembly.run.kernel.run(s_to_ns(t_s))


def driven(**overrides: object) -> Driven:
    scenario = cosim.load_scenario("warehouse-random", {**SMALL, **overrides})
    assembly = assemble(scenario)
    driver = dict(assembly.adapters)["waypoints"]
    assert isinstance(driver, WaypointsAdapter)
    goals: list[tuple[int, str, Goal]] = []
    commands: list[tuple[int, str, Twist]] = []
    bus = assembly.run.bus
    for name in NAMES:
        bus.monitor(waypoint_topic(name), lambda t, m, src, now: goals.append((now, src, m)))
        bus.monitor(cmd_vel_topic(name), lambda t, m, src, now: commands.append((now, src, m)))
    driver.start(assembly.run)
    return Driven(assembly, driver, goals, commands)


def distance_to_shelves(points: np.ndarray, shelves: np.ndarray) -> np.ndarray:
    """Distance of each point (k, 2) to the nearest shelf box (m)."""
    px, py = points[:, :1], points[:, 1:]
    x0, y0, x1, y1 = shelves.T
    dx = np.maximum(np.maximum(x0 - px, 0.0), px - x1)
    dy = np.maximum(np.maximum(y0 - py, 0.0), py - y1)
    return np.hypot(dx, dy).min(axis=1)


def test_every_robot_gets_a_free_waypoint_in_sight_at_the_start():
    d = driven()
    world, starts = d.driver.world, d.driver.pose.copy()
    clearance = d.driver.radius_m + SIGHT_MARGIN_M
    assert [(now, src) for now, src, _ in d.goals] == [(0, name) for name in NAMES]
    for (_, _, goal), start in zip(d.goals, starts, strict=True):
        end = np.array([goal.x_m, goal.y_m])
        assert world.is_free(end[None, :], clearance)[0]
        assert math.dist(start, end) >= 1.0
        path = start + np.linspace(0.0, 1.0, 200)[:, None] * (end - start)
        assert distance_to_shelves(path, world.shelves).min() >= clearance - 1e-9
    assert [(t, src) for t, src, _ in d.events("goal")] == [(0.0, n) for n in NAMES]
    goal = d.goals[0][2]
    assert d.events("goal")[0][2] == f"x_m={goal.x_m:.3f} y_m={goal.y_m:.3f}"


def test_the_same_seed_draws_the_same_waypoints_and_another_seed_others():
    first = [g for _, _, g in driven().goals]
    again = [g for _, _, g in driven().goals]
    other = [g for _, _, g in driven(**{"scenario.seed": 2}).goals]
    assert first == again
    assert first != other


def test_commands_go_to_every_robots_base_from_its_own_host_at_the_control_rate():
    d = driven()
    d.run(0.5)
    robots = d.assembly.run.settings(RobotsConfig)
    times = sorted({now for now, _, _ in d.commands})
    assert np.allclose(np.diff(times), 1e9 / robots.control_hz)
    assert {src for _, src, _ in d.commands} == set(NAMES)
    for _, _, twist in d.commands:
        assert 0.0 <= twist.linear_x_mps <= robots.max_speed_mps


def test_a_robot_at_its_waypoint_has_arrived_and_gets_the_next():
    d = driven()
    goal = d.goals[1][2]
    d.run(1.0)
    d.odometry(1, goal.x_m + 0.1, goal.y_m)
    d.run(1.2)
    assert [(src, detail) for _, src, detail in d.events("arrived")] == [("robot_2", "")]
    assert [src for now, src, _ in d.goals if now > 0] == ["robot_2"]
    assert d.driver.finish(d.assembly.run) == {"waypoints_reached": 1, "waypoints_abandoned": 0}


def test_a_robot_that_does_not_move_abandons_its_waypoint_as_blocked():
    d = driven()
    d.run(STALL_S + 0.01)
    abandoned = d.events("abandoned")
    assert [(t, src, why) for t, src, why in abandoned] == [(STALL_S, n, "blocked") for n in NAMES]
    assert [now for now, _, _ in d.goals] == [0, 0, 0] + [s_to_ns(STALL_S)] * 3
    assert d.driver.finish(d.assembly.run)["waypoints_abandoned"] == 3


def test_a_robot_that_moves_but_never_arrives_gives_up_after_the_goal_timeout():
    d = driven()
    run = d.assembly.run

    def wiggle(now_ns: int) -> None:  # 0.2 m back and forth every second: never stalled
        x = 3.0 + 0.2 * ((now_ns // 1_000_000_000) % 2)
        for robot in range(3):
            d.odometry(robot, x, 5.5 + robot * 0.01)

    run.kernel.every(s_to_ns(1.0), wiggle, stage=Stage.SENSING)
    d.run(GOAL_TIMEOUT_S + 0.01)
    reasons = {why for _, _, why in d.events("abandoned")}
    assert reasons == {"goal timeout"}
    assert [t for t, _, _ in d.events("abandoned")] == [GOAL_TIMEOUT_S] * 3


def test_a_robot_boxed_in_stays_put_until_the_next_attempt():
    d = driven()

    class Walled:
        size_m = d.driver.world.size_m

        def is_free(self, points: np.ndarray, radius_m: float) -> np.ndarray:
            return np.zeros(len(points), dtype=bool)

    d.driver.world = Walled()  # type: ignore[assignment]
    d.odometry(0, 2.5, 3.5)
    d.run(STALL_S + 0.01)
    later = [g for now, src, g in d.goals if now > 0 and src == "robot_1"]
    assert [(g.x_m, g.y_m) for g in later] == [(2.5, 3.5)]


@pytest.mark.parametrize("seed", [1, 2])
def test_in_a_whole_run_robots_reach_waypoints_and_never_touch_a_shelf_or_wall(seed):
    # the driver avoids nothing: robots may meet each other, never what lies in sight
    overrides = {**SMALL, "scenario.duration_s": 20.0, "scenario.seed": seed}
    result = cosim.run(cosim.load_scenario("warehouse-random", overrides))
    assert result.summary["waypoints_reached"] >= 3
    assert set(result.tables["collisions"].kind) <= {"robot"}
