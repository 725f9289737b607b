"""The physical-robot bridge: a real ROS 2 robot's twin in the run, over DDS.

For each robot in ``physical.robots`` (ROS 2 topic names; DDS names and QoS as
rmw_cyclonedds maps them, see :mod:`adapters.ros2dds`):

* in: its pose, from the mocap source (``physical.pose = "mocap"``, handled by the mocap
  adapter) or its own ``/<robot>/odom`` (nav_msgs/Odometry, sensor-data QoS; its odometry
  frame taken as ``map``). Poses move the twin (it is mirrored, not integrated).
* out: the lidar scan the twin senses in the virtual world, on ``/<robot>/scan``
  (sensor_msgs/LaserScan, sensor-data QoS), and either the navigation's velocity commands
  on ``/<robot>/cmd_vel`` (geometry_msgs/Twist, reliable: ``physical.drive = "cosim"``) or
  its navigation goals on ``/<robot>/goal_pose`` (geometry_msgs/PoseStamped, reliable, the
  topic Nav2 takes goals on: ``physical.drive = "own"``).

Stamps going out are ROS time (wall clock) of the simulated instant. DDS is polled at
``physical.poll_hz`` in the SENSING stage. Samples that fail to deserialize, carry no
valid pose, or come from writers of another type on our topics are counted, never used.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping
from typing import Any, ClassVar

from adapters.mocap.intake import PoseIntake
from adapters.mocap.tracking import physical_robots
from adapters.naming import topic
from adapters.physical.settings import PhysicalConfig
from adapters.ros2dds import types as dds
from adapters.ros2dds.participant import Publisher, Subscription
from adapters.ros2dds.qos import QosKind
from adapters.ros2dds.session import DdsSession, dds_session
from cosim.core.adapter import RunContext
from cosim.core.bus import Envelope
from cosim.core.hosts import HostId
from cosim.core.kernel import Stage
from cosim.core.messages import LaserScan, Message, PoseStamped, Twist
from cosim.core.messages.navigation import NavGoal
from cosim.core.timebase import period_ns
from models.kinematics import FleetState


class PhysicalRobot:
    """The DDS endpoints of one physical robot."""

    def __init__(self, index: int, name: str) -> None:
        self.index = index
        self.name = name
        self.host = HostId(name)
        self.scan: Publisher[dds.LaserScan] | None = None
        self.command: Publisher[Any] | None = None
        self.odom: Subscription[dds.Odometry] | None = None
        self.scans_sent = 0
        self.commands_sent = 0
        self.invalid = 0


class PhysicalAdapter:
    """Bridges the physical robots' twins to the real robots (see the module docstring)."""

    name: ClassVar[str] = "physical"
    requires: ClassVar[tuple[str, ...]] = ("fleet", "lidar")

    def __init__(self, run: RunContext) -> None:
        self.cfg = run.settings(PhysicalConfig)
        fleet = run.service(FleetState)
        names = list(fleet.names)
        self.robots = [
            PhysicalRobot(names.index(name), name) for name in physical_robots(run.scenario, names)
        ]
        self.intake: PoseIntake | None = None
        if self.cfg.pose == "odom":
            self.intake = PoseIntake(run, self.robots[0].host)
            for robot in self.robots:
                self.intake.mirrors.add(robot.index)
                self.intake.advertise(robot.index)
        self.session: DdsSession | None = None
        self.foreign = 0
        self.malformed = 0

    def start(self, run: RunContext) -> None:
        """Join the DDS domain, open every robot's endpoints and start polling."""
        self.session = dds_session(run)
        participant = self.session.participant
        for robot in self.robots:
            robot.scan = participant.publisher(
                topic(robot.name, "scan"), dds.LaserScan, QosKind.SENSOR_DATA
            )
            run.bus.subscribe(topic(robot.name, "scan"), robot.host, self._on_scan(run, robot))
            if self.cfg.drive == "cosim":
                robot.command = participant.publisher(
                    topic(robot.name, "cmd_vel"), dds.Twist, QosKind.DEFAULT
                )
                run.bus.subscribe(topic(robot.name, "cmd_vel"), robot.host, self._on_cmd(robot))
            else:
                robot.command = participant.publisher(
                    topic(robot.name, "goal_pose"), dds.PoseStamped, QosKind.DEFAULT
                )
                run.bus.subscribe(
                    topic(robot.name, "nav/goal"), robot.host, self._on_goal(run, robot)
                )
            if self.intake is not None:
                robot.odom = participant.subscription(
                    topic(robot.name, "odom"), dds.Odometry, QosKind.SENSOR_DATA
                )
        if self.intake is not None:
            run.kernel.every(period_ns(self.cfg.poll_hz), self._poll, stage=Stage.SENSING)

    def _on_scan(
        self, run: RunContext, robot: PhysicalRobot
    ) -> Callable[[Message, Envelope], None]:
        wall_ns = run.kernel.wall_ns

        def on_scan(message: Message, _envelope: Envelope) -> None:
            assert isinstance(message, LaserScan) and robot.scan is not None
            stamped = dataclasses.replace(message, stamp_ns=wall_ns(message.stamp_ns))
            robot.scan.publish(dds.LaserScan.deserialize(stamped.to_cdr()))
            robot.scans_sent += 1

        return on_scan

    def _on_cmd(self, robot: PhysicalRobot) -> Callable[[Message, Envelope], None]:
        def on_cmd(message: Message, _envelope: Envelope) -> None:
            assert isinstance(message, Twist) and robot.command is not None
            robot.command.publish(dds.Twist.deserialize(message.to_cdr()))
            robot.commands_sent += 1

        return on_cmd

    def _on_goal(
        self, run: RunContext, robot: PhysicalRobot
    ) -> Callable[[Message, Envelope], None]:
        wall_ns = run.kernel.wall_ns

        def on_goal(message: Message, _envelope: Envelope) -> None:
            assert isinstance(message, NavGoal) and robot.command is not None
            yaw = message.yaw_rad if math.isfinite(message.yaw_rad) else 0.0
            goal = PoseStamped(wall_ns(message.stamp_ns), "map", message.x_m, message.y_m, yaw)
            robot.command.publish(dds.PoseStamped.deserialize(goal.to_cdr()))
            robot.commands_sent += 1

        return on_goal

    def _poll(self, now_ns: int) -> None:
        assert self.intake is not None
        sim_ns = self.intake.run.kernel.sim_ns
        for robot in self.robots:
            assert robot.odom is not None
            for sample in robot.odom.take():
                pose = dds.planar_pose(sample.header, sample.pose.pose)
                if pose is None:
                    robot.invalid += 1
                    continue
                stamp, x, y, yaw = pose
                self.intake.submit(
                    robot.index,
                    sim_ns(stamp),
                    x,
                    y,
                    yaw,
                    mirror=True,
                    now_ns=now_ns,
                    host=robot.host,
                )

    def close(self) -> None:
        """Count foreign writers and malformed samples, then leave the DDS domain."""
        if self.session is None or self.session.closed:
            return
        participant = self.session.participant
        for robot in self.robots:
            self.foreign += (
                participant.foreign_writers(topic(robot.name, "cmd_vel"), "geometry_msgs/msg/Twist")
                if self.cfg.drive == "cosim"
                else 0
            )
            if robot.odom is not None:
                self.foreign += participant.foreign_writers(
                    topic(robot.name, "odom"), "nav_msgs/msg/Odometry"
                )
                self.malformed += robot.odom.malformed
        self.session.close()

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        """``physical_*`` counts (and the mocap counts when no mocap adapter runs)."""
        self.close()
        summary: dict[str, Any] = {
            "physical_robots": len(self.robots),
            "physical_scans_sent": sum(r.scans_sent for r in self.robots),
            "physical_commands_sent": sum(r.commands_sent for r in self.robots),
            "physical_invalid_samples": sum(r.invalid for r in self.robots),
            "physical_malformed_samples": self.malformed,
            "physical_foreign_writers": self.foreign,
        }
        if self.intake is not None:
            summary.update(self.intake.records.summary())
        return summary
