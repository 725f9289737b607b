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

A physical robot whose pose has not been accepted for ``physical.pose_timeout_s`` (none
since the start, or none since its last) ends the run: an event ``silent`` is recorded and
:class:`SilentRobotError` names the robot, the pose source and where it was listened
for. The run talks on the DDS domain it claimed (:mod:`adapters.ros2dds.domain`), given in
the summary as ``physical_dds_domain``.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping
from typing import Any, ClassVar

from adapters.fleet.mirror import Mirrors
from adapters.fleet.topics import cmd_vel_topic, odom_topic
from adapters.mocap.intake import PoseIntake
from adapters.mocap.settings import MocapConfig
from adapters.mocap.tables import MOCAP_SUMMARY
from adapters.mocap.tracking import live_sources, source_of, tracked_bodies
from adapters.navigation.topics import goal_pose_topic, goal_topic
from adapters.physical.settings import PhysicalConfig
from adapters.ros2dds import types as dds
from adapters.ros2dds.participant import Publisher, Subscription
from adapters.ros2dds.qos import QosKind
from adapters.ros2dds.session import DdsSession, dds_session
from adapters.sensing.topics import scan_topic
from cosim.core.adapter import RunContext, ScenarioView
from cosim.core.bus import Envelope
from cosim.core.errors import BridgeError, ConfigError
from cosim.core.hosts import HostId
from cosim.core.kernel import Stage
from cosim.core.messages import LaserScan, Message, PoseStamped, Twist
from cosim.core.messages.navigation import NavGoal
from cosim.core.recorder import Recorder
from cosim.core.summary import SummaryKey
from cosim.core.timebase import NS_PER_S, period_ns, s_to_ns
from models.fleet.kinematics import FleetState

WATCH_HZ = 4.0
"""Rate at which the physical robots' poses are checked for silence (Hz)."""


class SilentRobotError(BridgeError):
    """A physical robot sent no usable pose for ``physical.pose_timeout_s``."""


def physical_robots(scenario: ScenarioView, names: list[str]) -> list[str]:
    """The physical robots, checked against the fleet and the pose they need.

    Raises:
        ConfigError: for an unknown robot, or a physical robot that would have no pose.
    """
    cfg = scenario.section(PhysicalConfig)
    robots = list(cfg.robots)
    for robot in robots:
        if robot not in names:
            raise ConfigError(
                f"{scenario.source}: [physical] robots names {robot!r}: expected one of the "
                f"robots {', '.join(names)}"
            )
    if cfg.pose == "mocap" and robots:
        tracked = {robot for robot, _ in tracked_bodies(scenario, names)}
        source = source_of(scenario)
        live = source is not None and source.live
        missing = [robot for robot in robots if robot not in tracked or not live]
        if missing:
            sources = " or ".join(repr(name) for name in live_sources())
            raise ConfigError(
                f"{scenario.source}: [physical] robots names {missing[0]!r} with pose = "
                f"'mocap': expected it tracked by a live mocap source (mocap.source = "
                f"{sources}), or physical.pose = 'odom'"
            )
    return robots


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
        self.poses = 0
        """Poses accepted so far (the twin's updates)."""
        self.heard_ns: int | None = None
        """Kernel time of the last accepted pose, None before the first."""


class PhysicalAdapter:
    """Bridges the physical robots' twins to the real robots (see the module docstring)."""

    name: ClassVar[str] = "physical"
    requires: ClassVar[tuple[str, ...]] = ("fleet", "lidar")
    summary_keys: ClassVar[Mapping[str, SummaryKey]] = {
        "physical_robots": SummaryKey("count", "physical robots in the run"),
        "physical_dds_domain": SummaryKey(
            "id", "the DDS domain the run joined (null: it never joined one)"
        ),
        "physical_poses": SummaryKey("count", "pose updates of the physical robots taken in"),
        "physical_scans_sent": SummaryKey("count", "virtual lidar scans sent to the robots"),
        "physical_commands_sent": SummaryKey(
            "count", "velocity commands or goals sent to the robots"
        ),
        "physical_invalid_samples": SummaryKey(
            "count", "odometry samples from the robots that held no planar pose"
        ),
        "physical_malformed_samples": SummaryKey(
            "count", "odometry samples that failed to deserialize"
        ),
        "physical_foreign_writers": SummaryKey(
            "count", "other DDS writers on the robots' command and odometry topics"
        ),
        **{
            key: dataclasses.replace(value, when="physical.pose = 'odom' without a mocap adapter")
            for key, value in MOCAP_SUMMARY.items()
        },
    }
    """The summary keys :meth:`finish` writes (documented in the summary reference)."""

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
        self.mirrors = run.service(Mirrors)
        self.scenario = run.scenario
        self.fleet_names = names

    def start(self, run: RunContext) -> None:
        """Join the DDS domain, open every robot's endpoints and start polling."""
        self.session = dds_session(run)
        participant = self.session.participant
        for robot in self.robots:
            robot.scan = participant.publisher(
                scan_topic(robot.name), dds.LaserScan, QosKind.SENSOR_DATA
            )
            run.bus.subscribe(scan_topic(robot.name), robot.host, self._on_scan(run, robot))
            if self.cfg.drive == "cosim":
                robot.command = participant.publisher(
                    cmd_vel_topic(robot.name), dds.Twist, QosKind.DEFAULT
                )
                run.bus.subscribe(cmd_vel_topic(robot.name), robot.host, self._on_cmd(robot))
            else:
                robot.command = participant.publisher(
                    goal_pose_topic(robot.name), dds.PoseStamped, QosKind.DEFAULT
                )
                run.bus.subscribe(goal_topic(robot.name), robot.host, self._on_goal(run, robot))
            if self.intake is not None:
                robot.odom = participant.subscription(
                    odom_topic(robot.name), dds.Odometry, QosKind.SENSOR_DATA
                )
        if self.intake is not None:
            run.kernel.every(period_ns(self.cfg.poll_hz), self._poll, stage=Stage.SENSING)
        recorder = run.recorder
        run.kernel.every(
            period_ns(WATCH_HZ), lambda now: self._watch(now, recorder), stage=Stage.SENSING
        )

    def _watch(self, now_ns: int, recorder: Recorder) -> None:
        """End the run when a physical robot has sent no pose for ``pose_timeout_s``.

        Raises:
            SilentRobotError: naming the robot, its pose source and where it was
                listened for.
        """
        timeout_ns = s_to_ns(self.cfg.pose_timeout_s)
        for robot in self.robots:
            updates = int(self.mirrors.updates[robot.index])
            if updates != robot.poses:
                robot.poses, robot.heard_ns = updates, now_ns
                continue
            since = 0 if robot.heard_ns is None else robot.heard_ns
            if now_ns - since < timeout_ns:
                continue
            when = (
                "since the run started"
                if robot.heard_ns is None
                else f"since its last one at {robot.heard_ns / NS_PER_S:.1f} s"
            )
            text = (
                f"physical robot {robot.name} sent no pose for {self.cfg.pose_timeout_s:g} s "
                f"({when}): listened for {self._listened(robot)}"
            )
            recorder.event(now_ns, robot.name, "silent", text)
            raise SilentRobotError(
                f"{text}; expected the robot (or its stand-in, cosim run --standin) publishing "
                f"there (physical.pose_timeout_s = {self.cfg.pose_timeout_s:g})"
            )

    def _listened(self, robot: PhysicalRobot) -> str:
        """Where the poses of ``robot`` were expected: source, topic or body, domain."""
        where = "" if self.session is None else f" on {self.session.where()}"
        if self.cfg.pose == "odom":
            return f"nav_msgs/Odometry on /{robot.name}/odom{where} (physical.pose = 'odom')"
        mocap = self.scenario.section(MocapConfig)
        body = dict(tracked_bodies(self.scenario, self.fleet_names)).get(robot.name, robot.name)
        source = source_of(self.scenario)
        said = source.describe(mocap, body) + (where if source.uses_dds else "")
        return f"{said} (mocap.source = {mocap.source!r})"

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
                participant.foreign_writers(cmd_vel_topic(robot.name), "geometry_msgs/msg/Twist")
                if self.cfg.drive == "cosim"
                else 0
            )
            if robot.odom is not None:
                self.foreign += participant.foreign_writers(
                    odom_topic(robot.name), "nav_msgs/msg/Odometry"
                )
                self.malformed += robot.odom.malformed
        self.session.close()

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        """``physical_*`` counts (and the mocap counts when no mocap adapter runs)."""
        self.close()
        summary: dict[str, Any] = {
            "physical_robots": len(self.robots),
            "physical_dds_domain": None if self.session is None else self.session.domain,
            "physical_poses": sum(r.poses for r in self.robots),
            "physical_scans_sent": sum(r.scans_sent for r in self.robots),
            "physical_commands_sent": sum(r.commands_sent for r in self.robots),
            "physical_invalid_samples": sum(r.invalid for r in self.robots),
            "physical_malformed_samples": self.malformed,
            "physical_foreign_writers": self.foreign,
        }
        if self.intake is not None:
            summary.update(self.intake.records.summary())
        return summary
