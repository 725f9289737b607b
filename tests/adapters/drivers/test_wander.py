import math
from dataclasses import dataclass

import numpy as np
import pytest

import cosim
from adapters.drivers.wander import WanderAdapter
from adapters.fleet.topics import cmd_vel_topic
from adapters.sensing.topics import scan_topic
from cosim.core.hosts import HostId
from cosim.core.messages import LaserScan, Twist
from cosim.core.timebase import s_to_ns
from cosim.runner.assembly import Assembly, assemble
from cosim.scenario.sections import LidarConfig, RobotsConfig
from tests.conftest import SMALL

NAMES = ["robot_1", "robot_2", "robot_3"]
WANDER = {**SMALL, "robots.driver": "wander"}


@dataclass
class Wandering:
    """The wander driver alone: scans only when a test sends them."""

    assembly: Assembly
    driver: WanderAdapter
    commands: list[tuple[int, str, str, Twist]]

    def angles(self) -> np.ndarray:
        """The beams' angles in the sensor frame (rad, 0 ahead, counter-clockwise)."""
        lidar = self.assembly.run.settings(LidarConfig)
        fov = math.radians(lidar.fov_deg)
        return -fov / 2 + fov / (lidar.beams - 1) * np.arange(lidar.beams)

    def scan(self, robot: int, ranges: np.ndarray) -> None:
        run, name = self.assembly.run, NAMES[robot]
        lidar = run.settings(LidarConfig)
        angles = self.angles()
        message = LaserScan(
            run.kernel.now_ns,
            f"{name}/laser",
            float(angles[0]),
            float(angles[1] - angles[0]),
            lidar.range_min_m,
            lidar.range_max_m,
            0.1,
            ranges.astype(np.float32),
        )
        run.bus.publish(scan_topic(name), message, HostId(name))

    def open_ranges(self) -> np.ndarray:
        lidar = self.assembly.run.settings(LidarConfig)
        return np.full(lidar.beams, np.inf)

    def last(self) -> dict[str, Twist]:
        """Each robot's latest command."""
        return {topic.split("/")[1]: twist for _, topic, _, twist in self.commands}


def wandering() -> Wandering:
    assembly = assemble(cosim.load_scenario("warehouse-random", WANDER))
    driver = dict(assembly.adapters)["wander"]
    assert isinstance(driver, WanderAdapter)
    commands: list[tuple[int, str, str, Twist]] = []
    for name in NAMES:
        assembly.run.bus.monitor(
            cmd_vel_topic(name), lambda t, m, src, now: commands.append((now, t, src, m))
        )
    driver.start(assembly.run)
    return Wandering(assembly, driver, commands)


def test_before_any_scan_no_robot_is_commanded():
    w = wandering()
    w.assembly.run.kernel.run(s_to_ns(1.0))
    assert w.commands == []


def test_a_robot_with_open_space_ahead_cruises_and_one_without_a_scan_stands_still():
    w = wandering()
    w.scan(0, w.open_ranges())
    w.assembly.run.kernel.run(s_to_ns(0.06))
    robots = w.assembly.run.settings(RobotsConfig)
    last = w.last()
    assert last["robot_1"] == Twist(robots.max_speed_mps, 0.0)
    assert last["robot_2"] == Twist(0.0, 0.0) and last["robot_3"] == Twist(0.0, 0.0)


@pytest.mark.parametrize(("open_side", "turn"), [("left", 1.0), ("right", -1.0)])
def test_a_robot_blocked_ahead_turns_on_the_spot_towards_the_open_side(open_side, turn):
    w = wandering()
    ranges, angles = w.open_ranges(), w.angles()
    ranges[np.abs(angles) <= 0.6] = 0.5  # a wall 0.5 m ahead
    closed = angles < 0 if open_side == "left" else angles > 0
    ranges[closed & (np.abs(angles) > 0.6)] = 0.7
    w.scan(1, ranges)
    w.assembly.run.kernel.run(s_to_ns(0.06))
    robots = w.assembly.run.settings(RobotsConfig)
    assert w.last()["robot_2"] == Twist(0.0, turn * robots.max_yaw_rate_radps)


def test_a_robot_slows_as_the_way_ahead_narrows():
    speeds = []
    for ahead_m in (3.0, 1.8, 1.2, 0.9):
        w = wandering()
        w.scan(2, np.full(len(w.open_ranges()), ahead_m))
        w.assembly.run.kernel.run(s_to_ns(0.06))
        speeds.append(w.last()["robot_3"].linear_x_mps)
    assert speeds == sorted(speeds, reverse=True) and speeds[0] > speeds[-1] > 0.0


def test_commands_go_out_from_each_robots_own_host_at_the_control_rate():
    w = wandering()
    for robot in range(3):
        w.scan(robot, w.open_ranges())
    w.assembly.run.kernel.run(s_to_ns(0.5))
    robots = w.assembly.run.settings(RobotsConfig)
    times = sorted({now for now, _, _, _ in w.commands})
    assert np.allclose(np.diff(times), 1e9 / robots.control_hz)
    assert all(topic == cmd_vel_topic(src) for _, topic, src, _ in w.commands)
    assert w.driver.finish(w.assembly.run) == {}


def test_in_a_whole_run_every_robot_roams_within_its_limits():
    scenario = cosim.load_scenario("warehouse-random", WANDER)
    result = cosim.run(scenario)
    robots = scenario.section(RobotsConfig)
    poses = result.tables["poses"]
    moved = poses.groupby("robot", observed=True).apply(
        lambda p: math.dist((p.x_m.iloc[0], p.y_m.iloc[0]), (p.x_m.iloc[-1], p.y_m.iloc[-1]))
    )
    assert (moved > 0.3).all()
    assert result.summary["distance_m"] <= 3 * robots.max_speed_mps * 3.0 + 1e-9
