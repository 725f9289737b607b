"""ROS 2 messages as Cyclone DDS types, laid out exactly as ROS 2 puts them on the wire.

Each class is a ``@final`` IDL struct named as ``rmw_cyclonedds`` names the ROS type
(``pkg::msg::dds_::Name_``, see :mod:`adapters.ros2dds.naming`), with the fields of the
ROS 2 Humble/Jazzy message definition in order; final structs are serialized as plain
CDR (XCDR1), which is what ROS 2 sends, so a sample is byte-equal to rosbags'
``serialize_cdr`` of the same message. Units and frames are ROS's (REP 103): metres,
radians, seconds; ``header.frame_id`` names the frame a message is expressed in.
"""

# No ``from __future__ import annotations``: cyclonedds resolves string annotations by
# splitting them at dots (``idl.float64`` as a module ``idl``), so they must be evaluated.
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Annotated

from cyclonedds.idl import IdlStruct
from cyclonedds.idl import types as idl
from cyclonedds.idl.annotations import final

from models.geometry.se2 import yaw_of_quaternion

Covariance = Annotated[Sequence[idl.float64], idl.array(idl.float64, 36)]
"""Row-major 6x6 covariance over (x, y, z, rot x, rot y, rot z)."""
Float32Sequence = Annotated[Sequence[idl.float32], idl.sequence(idl.float32)]

_NS_PER_S = 1_000_000_000
_INT32 = 2**31


def _zeros36() -> list[float]:
    return [0.0] * 36


@final
@dataclass
class Time(IdlStruct, typename="builtin_interfaces::msg::dds_::Time_"):
    """builtin_interfaces/msg/Time: seconds and nanoseconds since the epoch (or sim start)."""

    sec: idl.int32 = 0
    nanosec: idl.uint32 = 0


@final
@dataclass
class Header(IdlStruct, typename="std_msgs::msg::dds_::Header_"):
    """std_msgs/msg/Header: the instant a message describes and the frame it is in."""

    stamp: Time = field(default_factory=Time)
    frame_id: str = ""


@final
@dataclass
class Point(IdlStruct, typename="geometry_msgs::msg::dds_::Point_"):
    """geometry_msgs/msg/Point: a position (m)."""

    x: idl.float64 = 0.0
    y: idl.float64 = 0.0
    z: idl.float64 = 0.0


@final
@dataclass
class Quaternion(IdlStruct, typename="geometry_msgs::msg::dds_::Quaternion_"):
    """geometry_msgs/msg/Quaternion: an orientation; the identity by default, as in ROS 2."""

    x: idl.float64 = 0.0
    y: idl.float64 = 0.0
    z: idl.float64 = 0.0
    w: idl.float64 = 1.0


@final
@dataclass
class Pose(IdlStruct, typename="geometry_msgs::msg::dds_::Pose_"):
    """geometry_msgs/msg/Pose: position (m) and orientation."""

    position: Point = field(default_factory=Point)
    orientation: Quaternion = field(default_factory=Quaternion)


@final
@dataclass
class PoseStamped(IdlStruct, typename="geometry_msgs::msg::dds_::PoseStamped_"):
    """geometry_msgs/msg/PoseStamped: a pose in ``header.frame_id`` at ``header.stamp``."""

    header: Header = field(default_factory=Header)
    pose: Pose = field(default_factory=Pose)


@final
@dataclass
class PoseWithCovariance(IdlStruct, typename="geometry_msgs::msg::dds_::PoseWithCovariance_"):
    """geometry_msgs/msg/PoseWithCovariance: a pose and its 6x6 covariance (m^2, rad^2)."""

    pose: Pose = field(default_factory=Pose)
    covariance: Covariance = field(default_factory=_zeros36)


@final
@dataclass
class PoseWithCovarianceStamped(
    IdlStruct, typename="geometry_msgs::msg::dds_::PoseWithCovarianceStamped_"
):
    """geometry_msgs/msg/PoseWithCovarianceStamped: e.g. a localization estimate."""

    header: Header = field(default_factory=Header)
    pose: PoseWithCovariance = field(default_factory=PoseWithCovariance)


@final
@dataclass
class Vector3(IdlStruct, typename="geometry_msgs::msg::dds_::Vector3_"):
    """geometry_msgs/msg/Vector3: a free vector (units given by its use)."""

    x: idl.float64 = 0.0
    y: idl.float64 = 0.0
    z: idl.float64 = 0.0


@final
@dataclass
class Twist(IdlStruct, typename="geometry_msgs::msg::dds_::Twist_"):
    """geometry_msgs/msg/Twist: body velocities, linear (m/s) and angular (rad/s).

    As a ``cmd_vel`` it is in ``base_link``: ``linear.x`` forward, ``angular.z``
    counter-clockwise.
    """

    linear: Vector3 = field(default_factory=Vector3)
    angular: Vector3 = field(default_factory=Vector3)


@final
@dataclass
class TwistWithCovariance(IdlStruct, typename="geometry_msgs::msg::dds_::TwistWithCovariance_"):
    """geometry_msgs/msg/TwistWithCovariance: a twist and its 6x6 covariance."""

    twist: Twist = field(default_factory=Twist)
    covariance: Covariance = field(default_factory=_zeros36)


@final
@dataclass
class Transform(IdlStruct, typename="geometry_msgs::msg::dds_::Transform_"):
    """geometry_msgs/msg/Transform: translation (m) and rotation of a child frame."""

    translation: Vector3 = field(default_factory=Vector3)
    rotation: Quaternion = field(default_factory=Quaternion)


@final
@dataclass
class TransformStamped(IdlStruct, typename="geometry_msgs::msg::dds_::TransformStamped_"):
    """geometry_msgs/msg/TransformStamped: ``child_frame_id`` in ``header.frame_id``."""

    header: Header = field(default_factory=Header)
    child_frame_id: str = ""
    transform: Transform = field(default_factory=Transform)


@final
@dataclass
class Odometry(IdlStruct, typename="nav_msgs::msg::dds_::Odometry_"):
    """nav_msgs/msg/Odometry (REP 105).

    The pose is ``child_frame_id`` (``base_link``) in ``header.frame_id`` (``odom``); the
    twist is in ``child_frame_id``.
    """

    header: Header = field(default_factory=Header)
    child_frame_id: str = ""
    pose: PoseWithCovariance = field(default_factory=PoseWithCovariance)
    twist: TwistWithCovariance = field(default_factory=TwistWithCovariance)


@final
@dataclass
class LaserScan(IdlStruct, typename="sensor_msgs::msg::dds_::LaserScan_"):
    """sensor_msgs/msg/LaserScan: one planar scan in the laser's frame.

    Angles in rad counter-clockwise from the laser's x axis, times in s, ranges in m.
    """

    header: Header = field(default_factory=Header)
    angle_min: idl.float32 = 0.0
    angle_max: idl.float32 = 0.0
    angle_increment: idl.float32 = 0.0
    time_increment: idl.float32 = 0.0
    scan_time: idl.float32 = 0.0
    range_min: idl.float32 = 0.0
    range_max: idl.float32 = 0.0
    ranges: Float32Sequence = field(default_factory=list)
    intensities: Float32Sequence = field(default_factory=list)


def yaw_to_quaternion(yaw: float) -> tuple[float, float, float, float]:
    """The quaternion ``(x, y, z, w)`` of a rotation by ``yaw`` (rad) about z."""
    return (0.0, 0.0, math.sin(0.5 * yaw), math.cos(0.5 * yaw))


quaternion_to_yaw = yaw_of_quaternion
"""The yaw (rad, in [-pi, pi]) of a quaternion ``(x, y, z, w)``, as tf2 computes it."""

QUATERNION_NORM_TOLERANCE = 0.05
"""How far from 1 a received quaternion's norm may be before the sample is refused."""


def planar_pose(header: Header, pose: Pose) -> tuple[int, float, float, float] | None:
    """(stamp ns, x_m, y_m, yaw_rad) of a received pose, or None if it is not a pose.

    Received samples are untrusted: any non-finite value, or a quaternion whose norm is
    off 1 by more than :data:`QUATERNION_NORM_TOLERANCE`, and the sample is refused.
    """
    p, q = pose.position, pose.orientation
    if not all(math.isfinite(v) for v in (p.x, p.y, p.z, q.x, q.y, q.z, q.w)):
        return None
    norm = math.sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w)
    if abs(norm - 1.0) > QUATERNION_NORM_TOLERANCE:
        return None
    return stamp_ns(header.stamp), p.x, p.y, quaternion_to_yaw(q.x, q.y, q.z, q.w)


def stamp(ns: int) -> Time:
    """A ROS time from integer nanoseconds (``nanosec`` is always in [0, 1e9)).

    Raises:
        ValueError: the seconds do not fit ROS's int32.
    """
    sec, nanosec = divmod(ns, _NS_PER_S)
    if not -_INT32 <= sec < _INT32:
        raise ValueError(f"time {ns} ns is out of ROS's range; expected |seconds| < 2^31")
    return Time(sec=sec, nanosec=nanosec)


def stamp_ns(time: Time) -> int:
    """Integer nanoseconds of a ROS time."""
    return time.sec * _NS_PER_S + time.nanosec
