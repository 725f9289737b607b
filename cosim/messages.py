"""Messages carried by the bus: immutable, typed, each mapped to a ROS 2 type.

Every message knows its ROS 2 type (for bag export and the DDS bridge) and its size in
bytes as ROS 2 would put it on the wire: the CDR encoding (XCDR1, little endian) of the
message plus the 4-byte encapsulation header (alignment counts from the end of that
header). The network model uses this size for
serialization delay and bandwidth, so sizes are computed from content, never guessed.

Frames follow REP 105: ``map`` (fixed world frame), ``odom`` (drifting, continuous),
``base_link`` (robot body), ``laser`` (sensor).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache
from typing import ClassVar

import numpy as np
import numpy.typing as npt

_ENCAPSULATION = 4


def _align(offset: int, alignment: int) -> int:
    return (offset + alignment - 1) // alignment * alignment


def _string(offset: int, text: str) -> int:
    # uint32 length (including the NUL) + bytes + NUL
    return _align(offset, 4) + 4 + len(text.encode("utf-8")) + 1


def _header(offset: int, frame_id: str) -> int:
    # builtin_interfaces/Time (int32 sec, uint32 nanosec) + string frame_id
    return _string(_align(offset, 4) + 8, frame_id)


def _doubles(offset: int, count: int) -> int:
    return _align(offset, 8) + 8 * count


def _float_seq(offset: int, count: int) -> int:
    return _align(offset, 4) + 4 + 4 * count


@lru_cache(maxsize=4096)
def _odometry_size(frame_id: str, child_frame_id: str) -> int:
    offset = _header(0, frame_id)
    offset = _string(offset, child_frame_id)
    offset = _doubles(offset, 7 + 36)
    return _ENCAPSULATION + _doubles(offset, 6 + 36)


@lru_cache(maxsize=4096)
def _scan_size(frame_id: str, beams: int) -> int:
    offset = _header(0, frame_id)
    offset = _align(offset, 4) + 7 * 4
    offset = _float_seq(offset, beams)
    return _ENCAPSULATION + _float_seq(offset, 0)


class Message:
    """Base of all bus messages."""

    ros_type: ClassVar[str]
    """ROS 2 type name, ``pkg/msg/Type``."""

    def size_bytes(self) -> int:
        """Serialized size on the wire in bytes (CDR body + encapsulation header)."""
        raise NotImplementedError


@dataclass(frozen=True, slots=True)
class Twist(Message):
    """A velocity command for a planar robot (``geometry_msgs/msg/Twist``), frame ``base_link``.

    Attributes:
        linear_x_mps: forward speed in m/s.
        angular_z_radps: yaw rate in rad/s (counter-clockwise positive).
    """

    ros_type: ClassVar[str] = "geometry_msgs/msg/Twist"
    linear_x_mps: float
    angular_z_radps: float

    def size_bytes(self) -> int:
        """Two Vector3 of float64."""
        return _ENCAPSULATION + 48


@dataclass(frozen=True, slots=True)
class Odometry(Message):
    """Pose and velocity estimate of a planar robot (``nav_msgs/msg/Odometry``).

    Attributes:
        stamp_ns: time of the estimate, ns.
        frame_id: pose frame (``odom``).
        child_frame_id: body frame (``base_link``).
        x_m, y_m, yaw_rad: pose of ``base_link`` in ``frame_id``.
        v_mps, w_radps: body-frame forward speed (m/s) and yaw rate (rad/s).
    """

    ros_type: ClassVar[str] = "nav_msgs/msg/Odometry"
    stamp_ns: int
    frame_id: str
    child_frame_id: str
    x_m: float
    y_m: float
    yaw_rad: float
    v_mps: float
    w_radps: float

    def size_bytes(self) -> int:
        """Header, child frame, PoseWithCovariance (7+36 doubles), TwistWithCovariance (6+36)."""
        return _odometry_size(self.frame_id, self.child_frame_id)


@dataclass(frozen=True, slots=True)
class PoseStamped(Message):
    """A planar pose with a time stamp (``geometry_msgs/msg/PoseStamped``).

    Attributes:
        stamp_ns: time of the pose, ns.
        frame_id: frame of the pose (``map`` for ground truth and motion capture).
        x_m, y_m, yaw_rad: position (m) and heading (rad) in ``frame_id``.
    """

    ros_type: ClassVar[str] = "geometry_msgs/msg/PoseStamped"
    stamp_ns: int
    frame_id: str
    x_m: float
    y_m: float
    yaw_rad: float

    def size_bytes(self) -> int:
        """Header plus Point and Quaternion (7 doubles)."""
        return _ENCAPSULATION + _doubles(_header(0, self.frame_id), 7)


@dataclass(frozen=True, slots=True)
class LaserScan(Message):
    """One planar lidar sweep (``sensor_msgs/msg/LaserScan``), REP 117 range conventions.

    Beam ``i`` points at ``angle_min_rad + i * angle_increment_rad`` in ``frame_id``.
    A beam without a return holds ``+inf``; a dropped-out beam holds ``nan``.

    Attributes:
        stamp_ns: acquisition time of the first beam, ns.
        frame_id: sensor frame.
        angle_min_rad, angle_increment_rad: beam angles (rad).
        range_min_m, range_max_m: valid range interval (m).
        scan_time_s: time between scans (s).
        ranges_m: float32 ranges, read-only.
    """

    ros_type: ClassVar[str] = "sensor_msgs/msg/LaserScan"
    stamp_ns: int
    frame_id: str
    angle_min_rad: float
    angle_increment_rad: float
    range_min_m: float
    range_max_m: float
    scan_time_s: float
    ranges_m: npt.NDArray[np.float32] = field(repr=False)

    def __post_init__(self) -> None:
        self.ranges_m.flags.writeable = False

    @property
    def angle_max_rad(self) -> float:
        """Angle of the last beam (rad)."""
        return self.angle_min_rad + (len(self.ranges_m) - 1) * self.angle_increment_rad

    def size_bytes(self) -> int:
        """Header, 7 float32 fields, ranges and an empty intensities sequence."""
        return _scan_size(self.frame_id, len(self.ranges_m))


@dataclass(frozen=True, slots=True)
class Goal(Message):
    """A navigation goal in ``map`` (``geometry_msgs/msg/PoseStamped`` on the wire).

    Attributes:
        stamp_ns: when the goal was issued, ns.
        x_m, y_m: goal position in ``map`` (m).
        yaw_rad: goal heading in ``map`` (rad), or ``nan`` for "any heading".
    """

    ros_type: ClassVar[str] = "geometry_msgs/msg/PoseStamped"
    stamp_ns: int
    x_m: float
    y_m: float
    yaw_rad: float = float("nan")

    def size_bytes(self) -> int:
        """Same layout as a PoseStamped in ``map``."""
        return _ENCAPSULATION + _doubles(_header(0, "map"), 7)


def _uint32(offset: int) -> int:
    return _align(offset, 4) + 4


@dataclass(frozen=True, slots=True)
class NavGoal(Message):
    """A "go to (x, y[, yaw])" goal for a robot's navigation (``cosim_msgs/msg/NavGoal``).

    Attributes:
        stamp_ns: when the goal was issued, ns.
        goal_id: the sender's id of this goal; statuses refer to it.
        x_m, y_m: goal position in ``map`` (m).
        yaw_rad: goal heading in ``map`` (rad), or ``nan`` for any heading.
    """

    ros_type: ClassVar[str] = "cosim_msgs/msg/NavGoal"
    stamp_ns: int
    goal_id: int
    x_m: float
    y_m: float
    yaw_rad: float = float("nan")

    def size_bytes(self) -> int:
        """Header in ``map``, uint32 id, three float64."""
        return _ENCAPSULATION + _doubles(_uint32(_header(0, "map")), 3)


@dataclass(frozen=True, slots=True)
class NavStatus(Message):
    """Progress of a navigation goal (``cosim_msgs/msg/NavStatus``).

    Attributes:
        stamp_ns: time of the report, ns.
        goal_id: the goal it is about.
        state: ``accepted`` | ``progress`` | ``arrived`` | ``stuck`` | ``unreachable`` |
            ``cancelled``.
        x_m, y_m: the robot's position in ``map`` (m).
        remaining_m: path length still to go (m), ``nan`` when unknown.
    """

    ros_type: ClassVar[str] = "cosim_msgs/msg/NavStatus"
    stamp_ns: int
    goal_id: int
    state: str
    x_m: float
    y_m: float
    remaining_m: float

    def size_bytes(self) -> int:
        """Header, uint32 id, state string, three float64."""
        offset = _string(_uint32(_header(0, "map")), self.state)
        return _ENCAPSULATION + _doubles(offset, 3)


@dataclass(frozen=True, slots=True)
class RobotState(Message):
    """A robot's pose, speed and footprint, broadcast to the others (robots layer).

    ``cosim_msgs/msg/RobotState``, as a Nav2 user's shared "robots layer" would send.

    Attributes:
        stamp_ns: time of the pose, ns.
        robot: the robot's name.
        x_m, y_m, yaw_rad: pose in ``map`` (m, m, rad).
        v_mps: forward speed (m/s).
        radius_m: footprint radius (m).
    """

    ros_type: ClassVar[str] = "cosim_msgs/msg/RobotState"
    stamp_ns: int
    robot: str
    x_m: float
    y_m: float
    yaw_rad: float
    v_mps: float
    radius_m: float

    def size_bytes(self) -> int:
        """Header, robot name, five float64."""
        return _ENCAPSULATION + _doubles(_string(_header(0, "map"), self.robot), 5)
