"""What a Unity scene may publish into a run: goals, velocity commands, tracked poses.

A ``geometry_msgs/PoseStamped`` on ``/<robot>/goal_pose`` (in ``map``, as RViz's 2D Goal
Pose and Nav2 take it) becomes that robot's :class:`~cosim.core.messages.NavGoal`,
published on ``/<robot>/nav/goal`` as the run's own goal senders do. The bytes are
decoded by rosbags as a DDS sample would be: anything that does not decode, is not in
``map`` or is not finite is refused, never evaluated.

A ``geometry_msgs/Twist`` on ``/<robot>/cmd_vel`` (``base_link``: linear.x forward m/s,
angular.z rad/s) drives a robot whose driver takes an operator's commands (``robots.driver
= "teleop"``, which advertises ``/<robot>/teleop/cmd_vel``); it is published there, and the
driver clips it to the robot's limits and stops the robot when commands stop.

A ``geometry_msgs/PoseStamped`` (``map``) on a tracked robot's body topic serves as its
motion capture (``mocap.source = "unity"``): the mocap adapter advertises the bus topic
:data:`POSE_PREFIX` + the body topic (``/unity/robot_1/pose``; ``adapters.mocap.unity``
spells the prefix the same), and the checked poses are published there from the ``mocap``
host for its pose intake.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from cosim.core.bus import Advertisement
from cosim.core.messages import NavGoal, PoseStamped, Twist
from cosim.recording.schemas import typestore

GOAL_TYPE = "geometry_msgs/msg/PoseStamped"
"""The ROS 2 type of a goal pose."""
GOAL_FRAME = "map"
"""The frame a goal pose must be given in."""
_GOAL_LEAF = "/nav/goal"
TWIST_TYPE = "geometry_msgs/msg/Twist"
"""The ROS 2 type of a velocity command."""
_TELEOP_LEAF = "/teleop/cmd_vel"
POSE_PREFIX = "/unity"
"""Bus topics of tracked poses from Unity: this prefix, then the topic a scene publishes on."""


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
        if ad.message_type is NavGoal and name.endswith(_GOAL_LEAF) and name.count("/") == 3:
            robot = name[1 : -len(_GOAL_LEAF)]
            topics[f"/{robot}/goal_pose"] = robot
    return topics


def decode_goal(robot: str, data: bytes) -> UnityGoal:
    """Robot ``robot``'s goal from a CDR ``geometry_msgs/PoseStamped``.

    Raises:
        ValueError: naming what is wrong (bytes that do not decode, another frame, a
            position that is not finite).
    """
    x, y, yaw = _planar_pose(f"/{robot}/goal_pose", data)
    return UnityGoal(robot, x, y, yaw)


def _decode(topic: str, data: bytes, msgtype: str) -> Any:
    """A scene's CDR bytes as a ``msgtype`` message (rosbags' typestore), nothing evaluated.

    Raises:
        ValueError: naming ``topic``, the byte count and rosbags' reason.
    """
    try:
        return typestore().deserialize_cdr(data, msgtype)
    except Exception as problem:  # rosbags raises several kinds on bytes it cannot follow
        raise ValueError(
            f"{topic}: {len(data)} bytes are not a CDR {msgtype} "
            f"({type(problem).__name__}: {problem})"
        ) from None


def _planar_pose(topic: str, data: bytes) -> tuple[float, float, float]:
    """(x_m, y_m, yaw_rad) in ``map`` of a CDR PoseStamped; yaw ``nan`` for a zero quaternion.

    Raises:
        ValueError: naming ``topic`` and what is wrong.
    """
    message = _decode(topic, data, GOAL_TYPE)
    frame_id = message.header.frame_id
    if frame_id != GOAL_FRAME:
        raise ValueError(f"{topic}: header.frame_id is {frame_id!r}; expected {GOAL_FRAME!r}")
    position, q = message.pose.position, message.pose.orientation
    x, y = float(position.x), float(position.y)
    if not (math.isfinite(x) and math.isfinite(y)):
        raise ValueError(f"{topic}: position ({x}, {y}); expected finite metres")
    quaternion = (float(q.x), float(q.y), float(q.z), float(q.w))
    if not all(math.isfinite(c) for c in quaternion):
        raise ValueError(f"{topic}: orientation {quaternion}; expected finite")
    qx, qy, qz, qw = quaternion
    yaw = (
        math.atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))
        if any(quaternion)
        else math.nan
    )
    return x, y, yaw


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


def _robot_of(name: str, leaf: str) -> str | None:
    """``robot`` of ``/<robot><leaf>``, or None."""
    if name.endswith(leaf) and name.count("/") == 1 + leaf.count("/"):
        return name[1 : -len(leaf)]
    return None


def teleop_topics(advertised: Mapping[str, Advertisement]) -> dict[str, str]:
    """``/<robot>/cmd_vel`` -> robot, for every robot whose driver takes teleoperation."""
    topics = {}
    for name, ad in advertised.items():
        robot = _robot_of(name, _TELEOP_LEAF)
        if ad.message_type is Twist and robot:
            topics[f"/{robot}/cmd_vel"] = robot
    return topics


def teleop_bus_topic(robot: str) -> str:
    """The bus topic a Unity command for ``robot`` is published on."""
    return f"/{robot}{_TELEOP_LEAF}"


def decode_twist(robot: str, data: bytes) -> UnityTwist:
    """Robot ``robot``'s velocity command from a CDR ``geometry_msgs/Twist``.

    Raises:
        ValueError: naming what is wrong (bytes that do not decode, a value not finite).
    """
    message = _decode(f"/{robot}/cmd_vel", data, TWIST_TYPE)
    linear, angular = message.linear, message.angular
    values = [float(v) for v in (linear.x, linear.y, linear.z, angular.x, angular.y, angular.z)]
    if not all(math.isfinite(v) for v in values):
        raise ValueError(
            f"/{robot}/cmd_vel: linear {values[:3]}, angular {values[3:]}; expected finite "
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
