"""Topics of the robots' sensors."""

from __future__ import annotations

import cosim
from adapters.sensing.topics import scan_topic
from cosim.core.bus import TopicQos
from cosim.core.messages import LaserScan
from cosim.runner.assembly import assemble
from tests.conftest import SMALL


def test_a_robots_scans_are_on_its_scan_topic():
    assert scan_topic("robot_1") == "/robot_1/scan"
    assert scan_topic("robot_10") == "/robot_10/scan"
    assert len({scan_topic(f"robot_{i}") for i in range(1, 20)}) == 19


def test_the_lidar_advertises_every_robots_scan_topic_with_the_sensor_profile():
    run = assemble(cosim.load_scenario("warehouse-random", SMALL), names=["lidar"]).run
    advertised = run.bus.advertised()
    for robot in ("robot_1", "robot_2", "robot_3"):
        assert advertised[scan_topic(robot)].message_type is LaserScan
        assert advertised[scan_topic(robot)].qos is TopicQos.SENSOR
