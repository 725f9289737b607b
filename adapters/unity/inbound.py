"""What a Unity scene may publish into a run: goals, velocity commands, tracked poses.

A ``geometry_msgs/PoseStamped`` on ``/<robot>/goal_pose`` (in ``map``, as RViz's 2D Goal
Pose and Nav2 take it) becomes that robot's :class:`~cosim.core.messages.NavGoal`,
published on ``/<robot>/nav/goal`` as the run's own goal senders do. The bytes are
decoded as the declared ``geometry_msgs/PoseStamped`` (:mod:`cosim.core.messages.std`):
anything that does not decode, is not in ``map`` or is not finite is refused, never
evaluated.

A ``geometry_msgs/Twist`` on ``/<robot>/cmd_vel`` (``base_link``: linear.x forward m/s,
angular.z rad/s) drives a robot whose driver takes an operator's commands (``robots.driver
= "teleop"``, which advertises ``/<robot>/teleop/cmd_vel``); it is published there, and the
driver clips it to the robot's limits and stops the robot when commands stop.

A ``geometry_msgs/PoseStamped`` (``map``) on a tracked robot's body topic serves as its
motion capture (``mocap.source = "unity"``): the pose source
(:mod:`adapters.unity.pose_source`) advertises the bus topic of each body
(:func:`~adapters.unity.topics.pose_bus_topic`, ``/unity/robot_1/pose``), and the checked
poses are published there from the ``mocap`` host for its pose intake.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from adapters.drivers.topics import teleop_topic
from adapters.fleet.topics import cmd_vel_topic
from adapters.navigation.topics import goal_pose_topic, goal_topic
from adapters.unity.topics import POSE_PREFIX
from cosim.core.bus import Advertisement
from cosim.core.errors import WireError
from cosim.core.messages import NavGoal, PoseStamped, Twist, std
from cosim.core.messages.decoding import decode_tree
from cosim.core.messages.wire import Struct

GOAL_TYPE = std.POSE_STAMPED.ros_type
"""The ROS 2 type of a goal pose."""
GOAL_FRAME = "map"
"""The frame a goal pose must be given in."""
TWIST_TYPE = std.TWIST.ros_type
"""The ROS 2 type of a velocity command."""


@dataclass(frozen=True, slots=True)
class UnityGoal:
    """A goal pose from Unity, checked.

    Attributes:
        robot: the robot's name (``robot_1``).
        x_m, y_m: goal position in ``map`` (m).
        yaw_rad: goal heading in ``map`` (rad), ``nan`` for any heading (a zero quaternion).
    """

    robot: str
    x_m: float
    y_m: float
    yaw_rad: float


def unity_name(msgtype: str) -> str:
    """The Connector's spelling of a ROS 2 type: ``sensor_msgs/LaserScan``."""
    return msgtype.replace("/msg/", "/")


def same_type(message_name: str, msgtype: str) -> bool:
    """Whether the Connector's ``message_name`` names ``msgtype`` (with or without ``/msg/``)."""
    return message_name in (msgtype, unity_name(msgtype))


def goal_topics(advertised: Mapping[str, Advertisement]) -> dict[str, str]:
    """``/<robot>/goal_pose`` -> robot, for every robot whose navigation takes goals."""
    topics = {}
    for name, ad in advertised.items():
        robot = _robot_of(name, goal_topic)
        if ad.message_type is NavGoal and robot:
            topics[goal_pose_topic(robot)] = robot
    return topics


def decode_goal(robot: str, data: bytes) -> UnityGoal:
    """Robot ``robot``'s goal from a CDR ``geometry_msgs/PoseStamped``.

    Raises:
        ValueError: naming what is wrong (bytes that do not decode, another frame, a
            position that is not finite).
    """
    x, y, yaw = _planar_pose(goal_pose_topic(robot), data)
    return UnityGoal(robot, x, y, yaw)


def _decode(topic: str, data: bytes, kind: Struct) -> Any:
    """A scene's CDR bytes as the fields of a ``kind`` message (nested tuples).

    Raises:
        ValueError: naming ``topic``, the byte count and what did not decode.
    """
    try:
        return decode_tree(kind, data)
    except WireError as problem:
        raise ValueError(f"{topic}: {len(data)} bytes are not a CDR {problem}") from None


def _planar_pose(topic: str, data: bytes) -> tuple[float, float, float]:
    """(x_m, y_m, yaw_rad) in ``map`` of a CDR PoseStamped; yaw ``nan`` for a zero quaternion.

    Raises:
        ValueError: naming ``topic`` and what is wrong.
    """
    (_stamp, frame_id), ((x, y, _z), q) = _decode(topic, data, std.POSE_STAMPED)
    if frame_id != GOAL_FRAME:
        raise ValueError(f"{topic}: header.frame_id is {frame_id!r}; expected {GOAL_FRAME!r}")
    if not (math.isfinite(x) and math.isfinite(y)):
        raise ValueError(f"{topic}: position ({x}, {y}); expected finite metres")
    quaternion = tuple(float(c) for c in q)
    if not all(math.isfinite(c) for c in quaternion):
        raise ValueError(f"{topic}: orientation {quaternion}; expected finite")
    norm = math.hypot(*quaternion)
    if norm == 0.0:
        return x, y, math.nan
    # normalized first: the products of a very large or very small one overflow or vanish
    qx, qy, qz, qw = (c / norm for c in quaternion)
    return x, y, math.atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))


@dataclass(frozen=True, slots=True)
class UnityTwist:
    """A velocity command from Unity, checked.

    Attributes:
        robot: the robot's name (``robot_1``).
        linear_x_mps: forward speed in ``base_link`` (m/s), not yet clipped.
        angular_z_radps: yaw rate (rad/s, counter-clockwise positive), not yet clipped.
    """

    robot: str
    linear_x_mps: float
    angular_z_radps: float


def _robot_of(name: str, topic_of: Any) -> str | None:
    """``robot`` if ``name`` is ``topic_of(robot)`` (a robot's own topic), else None."""
    parts = name.split("/")
    if len(parts) < 3 or parts[0] or not parts[1]:
        return None
    return parts[1] if topic_of(parts[1]) == name else None


def teleop_topics(advertised: Mapping[str, Advertisement]) -> dict[str, str]:
    """``/<robot>/cmd_vel`` -> robot, for every robot whose driver takes teleoperation."""
    topics = {}
    for name, ad in advertised.items():
        robot = _robot_of(name, teleop_topic)
        if ad.message_type is Twist and robot:
            topics[cmd_vel_topic(robot)] = robot
    return topics


def decode_twist(robot: str, data: bytes) -> UnityTwist:
    """Robot ``robot``'s velocity command from a CDR ``geometry_msgs/Twist``.

    Raises:
        ValueError: naming what is wrong (bytes that do not decode, a value not finite).
    """
    topic = cmd_vel_topic(robot)
    linear, angular = _decode(topic, data, std.TWIST)
    values = [float(v) for v in (*linear, *angular)]
    if not all(math.isfinite(v) for v in values):
        raise ValueError(
            f"{topic}: linear {values[:3]}, angular {values[3:]}; expected finite "
            "numbers (m/s, rad/s)"
        )
    return UnityTwist(robot, values[0], values[5])


@dataclass(frozen=True, slots=True)
class UnityPose:
    """A tracked pose from Unity, checked.

    Attributes:
        bus_topic: where the run takes it (``/unity/robot_1/pose``).
        x_m, y_m: position in ``map`` (m).
        yaw_rad: heading in ``map`` (rad).
    """

    bus_topic: str
    x_m: float
    y_m: float
    yaw_rad: float


def pose_topics(advertised: Mapping[str, Advertisement]) -> dict[str, str]:
    """Unity-side topic -> bus topic, for every tracked pose the run takes from Unity."""
    prefix = POSE_PREFIX + "/"
    return {
        name[len(POSE_PREFIX) :]: name
        for name, ad in advertised.items()
        if ad.message_type is PoseStamped and name.startswith(prefix)
    }


def decode_pose(topic: str, bus_topic: str, data: bytes) -> UnityPose:
    """A tracked pose published on ``topic`` from a CDR ``geometry_msgs/PoseStamped``.

    Raises:
        ValueError: naming what is wrong (bytes that do not decode, another frame than
            ``map``, a value that is not finite, a zero quaternion: no heading).
    """
    x, y, yaw = _planar_pose(topic, data)
    if math.isnan(yaw):
        raise ValueError(f"{topic}: orientation is a zero quaternion; expected a heading")
    return UnityPose(bus_topic, x, y, yaw)
