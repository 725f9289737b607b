"""A physical robot in a run, over DDS: a real second process plays it (cosim standin)."""

import math
import random
import threading
import time
from dataclasses import dataclass

import pytest
from cyclonedds.idl import IdlStruct
from cyclonedds.idl.annotations import final

import cosim
from adapters.physical.launcher import Standins
from adapters.ros2dds.participant import RosParticipant
from adapters.ros2dds.qos import QosKind
from adapters.ros2dds.types import Header, Odometry, Point, Pose, PoseWithCovariance, Quaternion
from adapters.ros2dds.types import stamp as ros_stamp
from cosim.core.errors import ConfigError
from cosim.runner.execute import execute

pytestmark = pytest.mark.slow


@final
@dataclass
class String(IdlStruct, typename="std_msgs::msg::dds_::String_"):
    data: str = ""


def domain() -> int:
    """A domain of its own, so that concurrent test runs on this machine never meet."""
    return random.SystemRandom().randint(1, 200)


@pytest.mark.slow
def test_a_standin_robot_follows_the_navigation_and_stops_when_its_poses_stop():
    s = cosim.load_scenario(
        "lab-real-in-virtual",
        {"scenario.duration_s": 8.0, "physical.dds_domain": domain()},
    )
    standins = Standins(s)
    standins.start()
    # the robot (and its motion capture) goes silent after 5 s of wall clock: its twin stops
    killer = threading.Timer(5.0, standins.stop)
    killer.start()
    try:
        result = execute(s)
    finally:
        killer.cancel()
        standins.stop()
    summary = result.summary
    assert summary["physical_scans_sent"] >= 70  # 10 Hz virtual lidar to the real robot
    assert summary["physical_commands_sent"] >= 70  # 10 Hz cmd_vel from the navigation
    assert summary["mocap_poses"] > 250  # ~100 Hz from the stand-in for 3-5 s
    assert summary["distance_m"] > 1.0  # the twin moved with the robot
    rows = result.tables["mocap"]
    stale = rows[rows.event == "stale"]
    assert len(stale) == 1 and 3.0 < stale.t_s.iloc[0] < 6.0
    poses = result.tables["poses"]
    after = poses[poses.t_s >= stale.t_s.iloc[0]]
    assert after.x_m.max() - after.x_m.min() < 1e-9  # nothing moves the twin any more
    realtime = result.tables["realtime"]
    assert len(realtime) > 100 and realtime.lateness_ms.min() >= 0
    assert summary["p99_lateness_ms"] is not None


def _odometry(x: float, y: float, *, nan: bool = False) -> Odometry:
    value = math.nan if nan else x
    return Odometry(
        header=Header(stamp=ros_stamp(time.time_ns()), frame_id="odom"),
        child_frame_id="base_link",
        pose=PoseWithCovariance(pose=Pose(position=Point(x=value, y=y), orientation=Quaternion())),
    )


@pytest.mark.slow
def test_samples_that_are_not_poses_jumps_and_foreign_writers_are_counted_not_used():
    d = domain()
    s = cosim.load_scenario(
        "lab-room",
        {
            "scenario.duration_s": 3.0,
            "robots.driver": "waypoints",
            "physical.robots": ["robot_1"],
            "physical.pose": "odom",
            "physical.dds_domain": d,
        },
    )
    stop = threading.Event()

    def robot() -> None:
        with RosParticipant(d) as ros:
            odom = ros.publisher("/robot_1/odom", Odometry, QosKind.SENSOR_DATA)
            foreign = ros.publisher("/robot_1/odom", String, QosKind.SENSOR_DATA)
            k = 0
            while not stop.is_set():
                if k % 10 == 3:
                    odom.publish(_odometry(1.0, 1.0, nan=True))  # not a pose
                elif k % 10 == 6:
                    odom.publish(_odometry(3.5, 7.0))  # 6 m away in 20 ms: a jump
                else:
                    odom.publish(_odometry(1.0 + 0.002 * k, 1.0))  # 0.1 m/s along x
                foreign.publish(String(data="hello"))
                k += 1
                time.sleep(0.02)

    thread = threading.Thread(target=robot)
    thread.start()
    try:
        result = execute(s)
    finally:
        stop.set()
        thread.join()
    summary = result.summary
    assert summary["physical_invalid_samples"] >= 5
    assert summary["mocap_rejected_jumps"] >= 5
    assert summary["physical_foreign_writers"] == 1
    poses = result.tables["poses"]
    twin = poses[poses.robot == "robot_1"]
    assert twin.y_m.max() < 1.01  # no jump ever reached the twin
    assert twin.x_m.iloc[-1] > 1.0 + 0.002 * 50  # it followed the good samples


def test_standins_need_a_physical_robot_in_the_scenario():
    with pytest.raises(ConfigError, match="no physical robot"):
        Standins(cosim.load_scenario("lab-room"))
