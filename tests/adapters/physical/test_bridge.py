"""A physical robot in a run, over DDS: a real second process plays it (cosim standin)."""

import json
import math
import threading
import time
from dataclasses import dataclass

import pandas as pd
import pytest
from cyclonedds.idl import IdlStruct
from cyclonedds.idl.annotations import final

import cosim
from adapters.physical.bridge import SilentRobotError
from adapters.physical.domain import claim_run_domain
from adapters.physical.launcher import Standins
from adapters.ros2dds.participant import RosParticipant
from adapters.ros2dds.qos import QosKind
from adapters.ros2dds.types import Header, Odometry, Point, Pose, PoseWithCovariance, Quaternion
from adapters.ros2dds.types import stamp as ros_stamp
from cosim.runner.execute import execute
from tests.conftest import cosim_main

pytestmark = pytest.mark.slow


@final
@dataclass
class String(IdlStruct, typename="std_msgs::msg::dds_::String_"):
    data: str = ""


@pytest.mark.slow
def test_a_standin_robot_follows_the_navigation_and_stops_when_its_poses_stop():
    # the run's domain is chosen for it ("auto"): the stand-ins and the run share it
    standins = Standins(cosim.load_scenario("lab-real-in-virtual", {"scenario.duration_s": 8.0}))
    s = standins.scenario
    assert isinstance(s.physical.dds_domain, int)
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
    run_domain = claim_run_domain(
        cosim.load_scenario(
            "lab-room",
            {
                "scenario.duration_s": 3.0,
                "robots.driver": "waypoints",
                "physical.robots": ["robot_1"],
                "physical.pose": "odom",
            },
        )
    )
    assert run_domain is not None
    s, d = run_domain.scenario, run_domain.claim.domain
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
        run_domain.close()
    summary = result.summary
    assert summary["physical_dds_domain"] == d
    assert summary["physical_invalid_samples"] >= 5
    assert summary["mocap_rejected_jumps"] >= 5
    assert summary["physical_foreign_writers"] == 1
    poses = result.tables["poses"]
    twin = poses[poses.robot == "robot_1"]
    assert twin.y_m.max() < 1.01  # no jump ever reached the twin
    assert twin.x_m.iloc[-1] > 1.0 + 0.002 * 50  # it followed the good samples


@pytest.mark.slow
def test_a_physical_robot_that_sends_no_pose_ends_the_run_naming_it_and_where_it_was_heard_for():
    s = cosim.load_scenario(
        "lab-real-in-virtual", {"scenario.duration_s": 5.0, "physical.pose_timeout_s": 0.5}
    )
    started = time.monotonic()
    with pytest.raises(SilentRobotError) as caught:
        execute(s)
    assert time.monotonic() - started < 3.0  # not the whole 5 s
    message = str(caught.value)
    assert message.startswith(
        "physical robot robot_1 sent no pose for 0.5 s (since the run started): listened for "
        "geometry_msgs/PoseStamped on /robot_1/pose on DDS domain "
    )
    assert message.endswith(
        "on loopback (mocap.source = 'ros2'); expected the robot (or its stand-in, cosim run "
        "--standin) publishing there (physical.pose_timeout_s = 0.5)"
    )
    assert "\n" not in message


@pytest.mark.slow
def test_a_run_whose_robot_never_speaks_ends_in_one_line_and_keeps_what_ran(tmp_path):
    out = tmp_path / "run"
    done = cosim_main(
        "run",
        "lab-real-in-virtual",
        "--duration-s",
        "5",
        "--set",
        "physical.pose_timeout_s=0.5",
        "--out",
        str(out),
    )
    assert done.returncode == 2
    assert done.stderr.count("\n") == 1
    assert done.stderr.startswith("cosim: error: physical robot robot_1 sent no pose for 0.5 s")
    assert f'are in {out}/ (summary.json says "failed")' in done.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["failed"].startswith("physical robot robot_1 sent no pose")
    assert 0.5 <= summary["sim_time_s"] < 5.0
    poses = pd.read_parquet(out / "tables" / "poses.parquet")
    assert len(poses) and poses.t_s.max() <= summary["sim_time_s"]
    assert (out / "bag" / "metadata.yaml").is_file()
