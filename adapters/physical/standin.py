"""A stand-in physical robot: a separate process that a ROS 2 stack drives over DDS.

It behaves like a real differential-drive robot seen through ROS 2: it obeys
``/<name>/cmd_vel`` (geometry_msgs/Twist in ``base_link``, with the drive limits of
:mod:`models.fleet.kinematics` and a twist watchdog), reports its pose in ``map`` on
``/<name>/pose`` as a motion-capture system would (optionally late and noisy), its
wheel odometry on ``/<name>/odom`` (``<name>/odom`` -> ``<name>/base_link``, REP 105,
the odom frame being its start pose) and counts the scans sent to ``/<name>/scan``.
It runs on the wall clock and stamps with wall-clock time, as ROS does.

Run it as ``python -m adapters.physical.standin --name robot_0 [--domain N] ...``.
"""

from __future__ import annotations

import argparse
import math
import signal
import sys
import threading
import time
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass, fields
from types import FrameType
from typing import NoReturn

import numpy as np

from adapters.fleet.topics import cmd_vel_topic, odom_topic
from adapters.mocap.topics import pose_topic
from adapters.physical.standin_options import StandinOptions, add_arguments, options_from
from adapters.ros2dds.participant import RosParticipant
from adapters.ros2dds.qos import QosKind
from adapters.ros2dds.types import (
    Header,
    LaserScan,
    Odometry,
    Point,
    Pose,
    PoseStamped,
    PoseWithCovariance,
    Quaternion,
    Twist,
    TwistWithCovariance,
    Vector3,
    stamp,
    yaw_to_quaternion,
)
from adapters.sensing.topics import scan_topic
from cosim.core.errors import CosimError
from models.arrays import FloatArray
from models.fleet.kinematics import DriveLimits, FleetState

RADIUS_M = 0.33
"""Footprint radius of the stand-in (m, a Jackal's); it never collides with anything."""


def drive_limits(options: StandinOptions) -> DriveLimits:
    """The stand-in's drive limits."""
    names = {f.name for f in fields(DriveLimits)}
    return DriveLimits(**{key: getattr(options, key) for key in names})


@dataclass(frozen=True)
class StandinReport:
    """What a stand-in run did.

    Attributes:
        poses_published: poses sent on ``/<name>/pose``.
        cmd_vel_received: commands received on ``/<name>/cmd_vel``.
        scans_received: scans received on ``/<name>/scan``.
        distance_m: distance driven (m).
        duration_s: wall-clock run time (s).
    """

    poses_published: int
    cmd_vel_received: int
    scans_received: int
    distance_m: float
    duration_s: float

    def summary(self, name: str) -> str:
        """One line for the console."""
        return (
            f"{name}: {self.poses_published} poses published, {self.cmd_vel_received} cmd_vel"
            f" and {self.scans_received} scans received, {self.distance_m:.2f} m driven"
            f" in {self.duration_s:.1f} s"
        )


def _pose(state: FleetState, stamp_ns: int, noise: FloatArray) -> PoseStamped:
    x, y, yaw = state.x[0] + noise[0], state.y[0] + noise[1], state.yaw[0] + noise[2]
    qx, qy, qz, qw = yaw_to_quaternion(float(yaw))
    return PoseStamped(
        header=Header(stamp=stamp(stamp_ns), frame_id="map"),
        pose=Pose(position=Point(x=float(x), y=float(y)), orientation=Quaternion(qx, qy, qz, qw)),
    )


def _odometry(options: StandinOptions, state: FleetState, stamp_ns: int) -> Odometry:
    # the odom frame is the start pose: the robot's pose relative to where it started
    dx, dy = state.x[0] - options.x_m, state.y[0] - options.y_m
    cos0, sin0 = math.cos(options.yaw_rad), math.sin(options.yaw_rad)
    qx, qy, qz, qw = yaw_to_quaternion(float(state.yaw[0]) - options.yaw_rad)
    pose = Pose(
        position=Point(x=float(cos0 * dx + sin0 * dy), y=float(-sin0 * dx + cos0 * dy)),
        orientation=Quaternion(qx, qy, qz, qw),
    )
    twist = Twist(linear=Vector3(x=float(state.v[0])), angular=Vector3(z=float(state.w[0])))
    return Odometry(
        header=Header(stamp=stamp(stamp_ns), frame_id=f"{options.name}/odom"),
        child_frame_id=f"{options.name}/base_link",
        pose=PoseWithCovariance(pose=pose),
        twist=TwistWithCovariance(twist=twist),
    )


def run_standin(
    options: StandinOptions,
    *,
    stop: threading.Event | None = None,
    status: Callable[[str], None] | None = None,
) -> StandinReport:
    """Run the stand-in robot until ``options.duration_s`` has passed or ``stop`` is set.

    Args:
        options: the robot and how it behaves.
        stop: set it (from another thread or a signal handler) to end the run.
        status: receives one-line messages for an operator (start, commands, watchdog).

    Raises:
        BridgeError: DDS cannot be opened on the domain or interface.
    """
    stop = stop if stop is not None else threading.Event()
    say = status if status is not None else (lambda _: None)
    name = options.name
    state = FleetState([name], np.array([[options.x_m, options.y_m, options.yaw_rad]]), RADIUS_M)
    limits, rng = drive_limits(options), np.random.default_rng(options.seed)
    # the step is compiled: load it now (a proposal changes nothing), not in the first tick
    state.propose(limits, 0.0)
    sigma = np.array([options.noise_std_m, options.noise_std_m, options.noise_std_rad])
    period_ns = round(1e9 / options.rate_hz)
    latency_ns, timeout_ns = round(options.latency_ms * 1e6), round(options.cmd_timeout_s * 1e9)
    pending: deque[tuple[int, PoseStamped]] = deque()
    poses = commands = scans = 0
    with RosParticipant(options.domain, interface=options.interface) as ros:
        cmd_vel = ros.subscription(cmd_vel_topic(name), Twist, QosKind.DEFAULT)
        scan = ros.subscription(scan_topic(name), LaserScan, QosKind.SENSOR_DATA)
        pose_out = ros.publisher(pose_topic(name), PoseStamped, QosKind.SENSOR_DATA)
        odom_out = ros.publisher(odom_topic(name), Odometry, QosKind.SENSOR_DATA)
        where = options.interface or "loopback"
        say(f"{name}: on DDS domain {options.domain} ({where}), {options.rate_hz:g} Hz")
        start = last_ns = time.monotonic_ns()
        end = None if options.duration_s is None else start + round(options.duration_s * 1e9)
        last_cmd: int | None = None
        tick = 0
        while not stop.is_set():
            tick = max(tick + 1, (time.monotonic_ns() - start) // period_ns)  # skip missed ticks
            if stop.wait(max(0.0, (start + tick * period_ns - time.monotonic_ns()) / 1e9)):
                break
            now, wall = time.monotonic_ns(), time.time_ns()
            if end is not None and now >= end:
                break
            received = cmd_vel.take()
            timed_out = last_cmd is None or now - last_cmd > timeout_ns
            if received:
                if timed_out:
                    say(f"{name}: following cmd_vel")
                commands, last_cmd = commands + len(received), now
                state.v_cmd[0], state.w_cmd[0] = received[-1].linear.x, received[-1].angular.z
            elif timed_out:  # the twist watchdog
                if state.v_cmd.any() or state.w_cmd.any():
                    say(f"{name}: no cmd_vel for {options.cmd_timeout_s:g} s, stopping")
                state.v_cmd[0] = state.w_cmd[0] = 0.0
            scans += len(scan.take())
            state.step(limits, (now - last_ns) / 1e9)
            last_ns = now
            odom_out.publish(_odometry(options, state, wall))
            noise = rng.normal(0.0, sigma) if sigma.any() else np.zeros(3)
            pending.append((now + latency_ns, _pose(state, wall, noise)))
            while pending and pending[0][0] <= now:
                pose_out.publish(pending.popleft()[1])
                poses += 1
    return StandinReport(
        poses_published=poses,
        cmd_vel_received=commands,
        scans_received=scans,
        distance_m=float(state.distance_m[0]),
        duration_s=(time.monotonic_ns() - start) / 1e9,
    )


class _Parser(argparse.ArgumentParser):
    """Exits 2 with one line, not the usage block, on a bad argument."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {message}\n")


def serve(args: argparse.Namespace) -> int:
    """Run the stand-in until SIGTERM/SIGINT or ``--duration-s``; print a one-line summary.

    Raises:
        ConfigError: for a bad option; BridgeError: when DDS cannot be opened.
    """
    options = options_from(args)
    stop = threading.Event()

    def _on_signal(signum: int, frame: FrameType | None) -> None:
        stop.set()

    previous = {signum: signal.getsignal(signum) for signum in (signal.SIGTERM, signal.SIGINT)}
    try:
        for signum in previous:
            signal.signal(signum, _on_signal)
        report = run_standin(options, stop=stop, status=lambda line: print(line, flush=True))
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)
    print(report.summary(options.name), flush=True)
    return 0


def _parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="python -m adapters.physical.standin", description="A stand-in robot on ROS 2 DDS."
    )
    add_arguments(parser)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the stand-in from the command line (same as ``cosim standin``).

    Returns:
        0 after a run (a one-line summary is printed), 2 on a bad argument or a DDS failure.
    """
    args = _parser().parse_args(argv)
    try:
        return serve(args)
    except CosimError as exc:
        print(f"python -m adapters.physical.standin: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
