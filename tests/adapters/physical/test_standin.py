"""The stand-in robot: driven over ROS 2 DDS from another process, as a real robot would be."""

import math
import random
import signal
import subprocess
import sys
import threading
import time

import pytest

from adapters.physical.standin import main, run_standin
from adapters.physical.standin_options import StandinOptions
from adapters.ros2dds.participant import RosParticipant
from adapters.ros2dds.qos import QosKind
from adapters.ros2dds.types import (
    Odometry,
    PoseStamped,
    Twist,
    Vector3,
    quaternion_to_yaw,
    stamp_ns,
)
from tests.conftest import REPO


@pytest.fixture
def domain() -> int:
    """A domain of its own, so that concurrent test runs on this machine never meet."""
    return random.SystemRandom().randint(1, 200)


def _yaw(pose: PoseStamped) -> float:
    q = pose.pose.orientation
    return quaternion_to_yaw(q.x, q.y, q.z, q.w)


def _drive(ros, name, watch, *, seconds, speed_mps=0.5):
    """Command a twist at 20 Hz for ``seconds`` as a teleop node does; return what ``watch`` got.

    ``watch`` is taken every 10 ms: a sensor-data reader keeps only its last 5 samples.
    """
    cmd_vel = ros.publisher(f"/{name}/cmd_vel", Twist, QosKind.DEFAULT)
    twist = Twist(linear=Vector3(x=speed_mps))
    received = []
    end, tick = time.monotonic() + seconds, 0
    while time.monotonic() < end:
        if tick % 5 == 0:
            cmd_vel.publish(twist)
        received.extend(watch.take())
        time.sleep(0.01)
        tick += 1
    return received


def _first(subscription, timeout_s=5.0):
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        samples = subscription.take()
        if samples:
            return samples[-1]
        time.sleep(0.02)
    raise AssertionError(f"nothing on {subscription.ros_topic} within {timeout_s} s")


@pytest.mark.slow
def test_a_standin_in_another_process_drives_as_commanded_and_stops_without_commands(domain):
    command = [sys.executable, "-m", "adapters.physical.standin", "--name", "robot_7"]
    command += ["--domain", str(domain), "--duration-s", "20"]
    process = subprocess.Popen(command, cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        with RosParticipant(domain) as ros:
            poses = ros.subscription("/robot_7/pose", PoseStamped, QosKind.SENSOR_DATA)
            start = _first(poses, timeout_s=8.0)
            assert start.header.frame_id == "map"
            moving = _drive(ros, "robot_7", poses, seconds=1.5)
            assert moving, "no poses while driving"
            end = moving[-1]
            dx = end.pose.position.x - start.pose.position.x
            # 0.5 m/s over at most 1.5 s, less the ramp (0.25 s at 2 m/s^2) and discovery
            assert 0.5 < dx < 0.5 * 1.5 + 0.05
            moved = [p for p in moving if p.pose.position.x > start.pose.position.x + 0.05]
            cruise = [p for p in moved if p.pose.position.x > moved[0].pose.position.x + 0.1]
            dt_s = (stamp_ns(cruise[-1].header.stamp) - stamp_ns(cruise[0].header.stamp)) / 1e9
            speed = (cruise[-1].pose.position.x - cruise[0].pose.position.x) / dt_s
            assert speed == pytest.approx(0.5, rel=0.05)
            assert abs(end.pose.position.y) < 1e-9
            assert abs(_yaw(end)) < 1e-9
            time.sleep(0.5 + 0.25 + 0.3)  # the watchdog's 0.5 s, braking, margin
            poses.take()
            halted = _first(poses).pose.position.x
            time.sleep(0.3)
            assert _first(poses).pose.position.x == halted
            assert halted > end.pose.position.x  # it coasted only as the watchdog allows
            assert halted - end.pose.position.x < 0.5 * 0.5 + 0.0625 + 0.05
    finally:
        process.terminate()
        out, err = process.communicate(timeout=5.0)
    assert process.returncode == 0, err.decode()
    summary = out.decode().strip().splitlines()[-1]
    assert summary.startswith("robot_7: ") and "poses published" in summary


@pytest.mark.slow
def test_odometry_starts_at_the_start_pose_and_the_pose_is_in_map(domain):
    options = StandinOptions(name="robot_2", domain=domain, x_m=1.0, y_m=2.0, yaw_rad=math.pi / 2)
    stop = threading.Event()
    reports = []
    robot = threading.Thread(target=lambda: reports.append(run_standin(options, stop=stop)))
    robot.start()
    try:
        with RosParticipant(domain) as ros:
            poses = ros.subscription("/robot_2/pose", PoseStamped, QosKind.SENSOR_DATA)
            odom = ros.subscription("/robot_2/odom", Odometry, QosKind.SENSOR_DATA)
            _first(poses)
            _drive(ros, "robot_2", poses, seconds=0.8)
            pose, odometry = _first(poses), _first(odom)
    finally:
        stop.set()
        robot.join(timeout=5.0)
    assert odometry.header.frame_id == "robot_2/odom"
    assert odometry.child_frame_id == "robot_2/base_link"
    # facing +y in map: driving forward moves it along map y and along odom x
    assert pose.pose.position.y - 2.0 == pytest.approx(odometry.pose.pose.position.x, abs=0.05)
    assert pose.pose.position.x == pytest.approx(1.0, abs=1e-9)
    assert odometry.pose.pose.position.y == pytest.approx(0.0, abs=1e-9)
    assert _yaw(pose) == pytest.approx(math.pi / 2)
    assert odometry.twist.twist.linear.x == pytest.approx(0.5)
    assert reports[0].cmd_vel_received > 0
    assert reports[0].distance_m == pytest.approx(pose.pose.position.y - 2.0, abs=0.05)


@pytest.mark.slow
def test_poses_wait_out_the_latency_before_they_are_published(domain):
    options = StandinOptions(name="robot_1", domain=domain, latency_ms=300.0, duration_s=0.5)
    report = run_standin(options)
    # 100 Hz over 0.5 s, but each pose leaves 0.3 s after it is taken
    assert 0 < report.poses_published <= 21


def test_a_run_reports_through_its_status_callback(domain):
    lines = []
    run_standin(StandinOptions(name="robot_1", domain=domain, duration_s=0.1), status=lines.append)
    assert lines == [f"robot_1: on DDS domain {domain} (loopback), 100 Hz"]


def test_the_command_line_exits_2_with_one_line_on_a_bad_argument(capsys):
    with pytest.raises(SystemExit) as exited:
        main(["--name", "robot_1", "--rate-hz", "fast"])
    assert exited.value.code == 2
    assert capsys.readouterr().err.strip().count("\n") == 0


def test_the_command_line_exits_2_with_one_line_on_a_bridge_error(capsys):
    assert main(["--name", "robot_1", "--domain", "300"]) == 2
    err = capsys.readouterr().err
    assert err.strip() == (
        "python -m adapters.physical.standin: error: DDS domain 300 is out of range; "
        "expected 0..232"
    )


def test_the_command_line_prints_a_one_line_summary_after_a_run(capsys, domain):
    handler = signal.getsignal(signal.SIGTERM)
    assert main(["--name", "robot_4", "--domain", str(domain), "--duration-s", "0.2"]) == 0
    last = capsys.readouterr().out.strip().splitlines()[-1]
    assert last.startswith("robot_4: ") and "0 cmd_vel" in last
    assert signal.getsignal(signal.SIGTERM) is handler  # restored for whoever called main
