"""Every robot's navigation on the bus: topics advertised, goals, scans and maps handed on."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import numpy as np

from adapters.navigation.wiring import NavWiring
from cosim.core.bus import Bus
from cosim.core.hosts import HostId
from cosim.core.kernel import Kernel
from cosim.core.messages import LaserScan, Message, NavGoal, NavStatus, Path, Twist
from cosim.core.messages import OccupancyGrid as GridMessage
from cosim.core.workers import Workers

NAMES = ["robot_1", "robot_2"]
HOSTS = [HostId(n) for n in NAMES]


class Heard:
    """Stands in for the goal tracker, the scan memory and the layers: keeps what it is given."""

    def __init__(self) -> None:
        self.calls: list[tuple[Any, ...]] = []

    def accept(self, run: Any, i: int, goal: NavGoal) -> None:
        self.calls.append(("goal", i, goal))

    def add(self, i: int, pose: np.ndarray, ranges: np.ndarray) -> None:
        self.calls.append(("scan", i, pose, ranges))

    def build(self, i: int, message: GridMessage) -> tuple[int, GridMessage]:
        return (i, message)  # what the layer would be built from

    def set(self, i: int, built: tuple[int, GridMessage]) -> None:
        self.calls.append(("map", i, built[1]))


def _wired(*, mapping: bool) -> tuple[Bus, Any, NavWiring, Heard, np.ndarray]:
    kernel = Kernel()
    bus = Bus(kernel)
    run: Any = SimpleNamespace(bus=bus, kernel=kernel, workers=Workers(1))
    interface = NavWiring.of(NAMES, HOSTS)
    heard: Any = Heard()
    pose = np.array([[1.0, 2.0, 0.0], [3.0, 4.0, 0.5]])
    interface.subscribe(run, heard, heard, pose, heard, mapping=mapping)
    return bus, run, interface, heard, pose


def _scan() -> LaserScan:
    return LaserScan(7, "robot_2/laser", -0.5, 0.5, 0.1, 10.0, 0.1, np.full(3, 2.0, np.float32))


def test_each_robots_status_command_and_plan_topics_are_advertised_robot_by_robot():
    bus = Bus(Kernel())
    NavWiring.of(NAMES, HOSTS).advertise(bus)
    advertised = [(topic, ad.message_type) for topic, ad in bus.advertised().items()]
    assert advertised == [
        ("/robot_1/nav/status", NavStatus),
        ("/robot_1/cmd_vel", Twist),
        ("/robot_1/plan", Path),
        ("/robot_2/nav/status", NavStatus),
        ("/robot_2/cmd_vel", Twist),
        ("/robot_2/plan", Path),
    ]


def test_a_goal_on_a_robots_goal_topic_is_handed_to_the_goals_with_the_robots_index():
    bus, _, _, heard, _ = _wired(mapping=False)
    goal = NavGoal(5, 1, 6.0, 7.0)
    bus.publish("/robot_2/nav/goal", goal, HOSTS[1])
    assert heard.calls == [("goal", 1, goal)]


def test_a_scan_is_remembered_at_the_pose_the_robot_believed_it_had_when_it_came():
    bus, _, _, heard, pose = _wired(mapping=False)
    scan = _scan()
    bus.publish("/robot_2/scan", scan, HOSTS[1])
    pose[1] = (9.0, 9.0, 9.0)  # the robot moves on: the scan stays where it was taken
    [(kind, i, at, ranges)] = heard.calls
    assert (kind, i) == ("scan", 1) and ranges is scan.ranges_m
    assert at.tolist() == [3.0, 4.0, 0.5]


def test_maps_are_heard_only_when_robots_build_their_own():
    grid = GridMessage(3, "map", 0.1, 2, 1, 0.0, 0.0, bytes([0, 100]))
    bus, _, _, heard, _ = _wired(mapping=False)
    bus.publish("/robot_1/map", grid, HOSTS[0])
    assert heard.calls == []
    bus, run, _, heard, _ = _wired(mapping=True)
    bus.publish("/robot_1/map", grid, HOSTS[0])
    assert heard.calls == []  # built with the instant's other maps, at the stage's end
    run.kernel.run(1)
    assert heard.calls == [("map", 0, grid)]


def test_every_robots_command_goes_out_on_its_cmd_vel_from_its_host():
    bus, run, interface, _, _ = _wired(mapping=False)
    sent: list[tuple[str, Message, HostId]] = []
    for topic in interface.cmd:
        bus.monitor(topic, lambda topic, message, src, _t: sent.append((topic, message, src)))
    interface.publish_commands(run, np.array([0.5, 0.0]), np.array([0.1, -0.2]))
    assert sent == [
        ("/robot_1/cmd_vel", Twist(0.5, 0.1), HOSTS[0]),
        ("/robot_2/cmd_vel", Twist(0.0, -0.2), HOSTS[1]),
    ]
