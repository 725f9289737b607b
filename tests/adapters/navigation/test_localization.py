"""Where each robot's software believes it is: odometry, its map's correction, measured poses."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

import cosim
from adapters.fleet.topics import odom_topic
from adapters.mapping.topics import correction_topic
from adapters.mocap.topics import pose_topic
from adapters.navigation.localization import Localization
from cosim.core.adapter import RunContext
from cosim.core.hosts import HostId
from cosim.core.messages import Odometry, PoseStamped, TFMessage, Transform
from cosim.core.timebase import s_to_ns
from cosim.runner.assembly import assemble
from models.fleet.kinematics import FleetState
from models.geometry.se2 import compose
from tests.conftest import SMALL

ROBOTS = ["robot_1", "robot_2", "robot_3"]
HOSTS = [HostId(r) for r in ROBOTS]


def _localized(*, mapping: bool = False, **overrides: Any) -> tuple[RunContext, Localization]:
    scenario = cosim.load_scenario("warehouse-random", {**SMALL, **overrides})
    run = assemble(scenario, names=["world", "fleet"]).run
    localization = Localization(run, run.service(FleetState), mapping=mapping)
    localization.subscribe(run, HOSTS)
    return run, localization


def _odom(run: RunContext, i: int, x: float, y: float, yaw: float, v: float = 0.4) -> None:
    name = ROBOTS[i]
    message = Odometry(0, f"{name}/odom", f"{name}/base_link", x, y, yaw, v, -0.1)
    run.bus.publish(odom_topic(name), message, HOSTS[i])


def _pose(run: RunContext, i: int, stamp_s: float, x: float, y: float, yaw: float) -> None:
    message = PoseStamped(s_to_ns(stamp_s), "map", x, y, yaw)
    run.bus.publish(pose_topic(ROBOTS[i]), message, HOSTS[i])


def test_every_robot_starts_where_the_fleet_starts_and_at_rest():
    run, localization = _localized()
    fleet = run.service(FleetState)
    np.testing.assert_array_equal(localization.pose, np.stack([fleet.x, fleet.y, fleet.yaw], 1))
    assert localization.vel.tolist() == [[0.0, 0.0]] * 3
    assert localization.correction == [(0.0, 0.0, 0.0)] * 3
    assert not localization.measured.tracked.any()


def test_without_mapping_a_robot_is_where_its_odometry_says_and_moves_as_it_says():
    run, localization = _localized()
    _odom(run, 1, 4.0, 5.0, 0.5)
    assert localization.pose[1].tolist() == [4.0, 5.0, 0.5]
    assert localization.vel[1].tolist() == [0.4, -0.1]
    assert localization.pose[0].tolist() != [4.0, 5.0, 0.5]  # its own robot only


def test_with_mapping_the_odometry_is_corrected_by_the_maps_map_to_odom():
    run, localization = _localized(mapping=True)
    correction = (0.5, -0.25, 0.1)
    tf = TFMessage(0, (Transform("map", "robot_3/odom", *correction),))
    run.bus.publish(correction_topic("robot_3"), tf, HOSTS[2])
    _odom(run, 2, 2.0, 1.0, 0.3)
    assert localization.correction[2] == correction
    assert tuple(localization.pose[2]) == pytest.approx(compose(correction, (2.0, 1.0, 0.3)))


def test_transforms_not_from_map_are_no_correction():
    run, localization = _localized(mapping=True)
    tf = TFMessage(0, (Transform("robot_1/odom", "robot_1/base_link", 1.0, 1.0, 1.0),))
    run.bus.publish(correction_topic("robot_1"), tf, HOSTS[0])
    assert localization.correction[0] == (0.0, 0.0, 0.0)


def test_without_mapping_corrections_are_not_listened_to():
    run, localization = _localized(mapping=False)
    tf = TFMessage(0, (Transform("map", "robot_1/odom", 1.0, 1.0, 1.0),))
    run.bus.publish(correction_topic("robot_1"), tf, HOSTS[0])
    _odom(run, 0, 2.0, 2.0, 0.0)
    assert localization.pose[0].tolist() == [2.0, 2.0, 0.0]


def test_a_tracked_robot_is_where_its_measured_poses_say_and_only_its_speed_comes_from_odom():
    run, localization = _localized(**{"mocap.source": "simulated", "mocap.robots": ["robot_2"]})
    assert localization.measured.tracked.tolist() == [False, True, False]
    _pose(run, 1, 0.1, 3.0, 4.0, 1.0)
    _odom(run, 1, 9.0, 9.0, 0.0, v=0.7)
    assert localization.pose[1].tolist() == [3.0, 4.0, 1.0]
    assert localization.vel[1, 0] == 0.7


def test_a_measured_pose_older_than_the_newest_is_ignored():
    run, localization = _localized(**{"mocap.source": "simulated"})
    _pose(run, 0, 0.5, 3.0, 4.0, 1.0)
    _pose(run, 0, 0.4, 1.0, 1.0, 0.0)  # out of order
    assert localization.pose[0].tolist() == [3.0, 4.0, 1.0]
    _pose(run, 0, 0.5, 3.5, 4.0, 1.0)  # the same stamp: taken
    assert localization.pose[0, 0] == 3.5


def test_a_robot_whose_pose_is_older_than_max_age_must_stop_until_a_fresh_one_comes():
    run, localization = _localized(**{"mocap.source": "simulated", "mocap.max_age_ms": 100.0})
    measured = localization.measured
    assert not measured.check(s_to_ns(0.1)).any()  # the start pose, stamped at 0
    _pose(run, 1, 0.15, 3.0, 4.0, 1.0)
    assert measured.check(s_to_ns(0.2)).tolist() == [True, False, True]
    assert measured.check(s_to_ns(0.3)).tolist() == [True, True, True]
    _pose(run, 1, 0.3, 3.0, 4.0, 1.0)
    assert measured.check(s_to_ns(0.35)).tolist() == [True, False, True]
    table = run.recorder.tables["mocap"].columns()
    rows = list(zip(table["t_s"], table["robot"], table["event"], strict=True))
    assert rows == [
        (0.2, "robot_1", "stale"),
        (0.2, "robot_3", "stale"),
        (0.3, "robot_2", "stale"),
        (0.35, "robot_2", "fresh"),
    ]
    assert table["detail"][0] == "pose age 0.200 s"


def test_robots_not_tracked_never_go_stale_and_keep_no_mocap_table():
    run, localization = _localized()
    assert not localization.measured.check(s_to_ns(1000.0)).any()
    assert localization.measured.records is None and "mocap" not in run.recorder.tables


def test_a_measured_pose_of_a_robot_not_tracked_is_not_listened_to():
    run, localization = _localized()
    _pose(run, 0, 0.1, 3.0, 4.0, 1.0)
    assert not math.isclose(localization.pose[0, 0], 3.0)
