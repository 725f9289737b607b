"""Messages with a standard ROS 2 type (geometry_msgs, nav_msgs, sensor_msgs).

Frames follow REP 105: ``map`` (fixed world frame), ``odom`` (drifting, continuous),
``base_link`` (robot body), ``laser`` (sensor).
"""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np
import numpy.typing as npt

from cosim.core.messages.base import Message
from cosim.core.messages.cdr import (
    ENCAPSULATION,
    doubles,
    header,
    odometry_size,
    scan_size,
    uint32,
)
from cosim.core.messages.encoder import HEADER, CdrWriter, strings_block, time_bytes

_ODOM_BODY = struct.Struct("<2d24x2d288xd32xd288x")
"""Odometry after its strings: x, y, (z, qx, qy = 0), qz, qw, zero covariance, v, 0 x 4, w,
zero covariance."""
_SCAN_FIELDS = struct.Struct("<7fI")
"""LaserScan after its header: 7 float32 fields and the count of ranges."""
_NO_INTENSITIES = bytes(4)


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
        return ENCAPSULATION + 48

    def to_cdr(self) -> bytes:
        """Linear (x, 0, 0) and angular (0, 0, z) Vector3."""
        w = CdrWriter()
        w.f64s((self.linear_x_mps, 0.0, 0.0, 0.0, 0.0, self.angular_z_radps))
        return w.data()


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
        return odometry_size(self.frame_id, self.child_frame_id)

    def to_cdr(self) -> bytes:
        """Planar pose and twist; both covariances zero (unknown, as many drivers send)."""
        half = 0.5 * self.yaw_rad
        return b"".join(
            (
                HEADER,
                time_bytes(self.stamp_ns),
                strings_block(8, (self.frame_id, self.child_frame_id), 8),
                _ODOM_BODY.pack(
                    self.x_m, self.y_m, math.sin(half), math.cos(half), self.v_mps, self.w_radps
                ),
            )
        )


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
        return ENCAPSULATION + doubles(header(0, self.frame_id), 7)

    def to_cdr(self) -> bytes:
        """Header and planar pose."""
        w = CdrWriter()
        w.header(self.stamp_ns, self.frame_id)
        w.pose2d(self.x_m, self.y_m, self.yaw_rad)
        return w.data()


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
        return scan_size(self.frame_id, len(self.ranges_m))

    def to_cdr(self) -> bytes:
        """Header, angles, times, range limits, ranges; no intensities."""
        ranges = self.ranges_m
        fields = _SCAN_FIELDS.pack(
            self.angle_min_rad,
            self.angle_max_rad,
            self.angle_increment_rad,
            0.0,  # time_increment: every beam of a sweep is cast at its stamp
            self.scan_time_s,
            self.range_min_m,
            self.range_max_m,
            len(ranges),
        )
        return b"".join(
            (
                HEADER,
                time_bytes(self.stamp_ns),
                strings_block(8, (self.frame_id,), 4),
                fields,
                np.ascontiguousarray(ranges, dtype="<f4").tobytes(),
                _NO_INTENSITIES,
            )
        )


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
        return ENCAPSULATION + doubles(header(0, "map"), 7)

    def to_cdr(self) -> bytes:
        """A PoseStamped in ``map``; no heading is written as yaw 0."""
        yaw = self.yaw_rad if math.isfinite(self.yaw_rad) else 0.0
        return PoseStamped(self.stamp_ns, "map", self.x_m, self.y_m, yaw).to_cdr()


@dataclass(frozen=True, slots=True)
class Path(Message):
    """A planned path (``nav_msgs/msg/Path``), as Nav2's planner publishes on ``plan``.

    Attributes:
        stamp_ns: when the path was planned, ns.
        frame_id: frame of the waypoints (``map``).
        xy_m: waypoints (k, 2) in ``frame_id`` (m), read-only; each pose's heading points
            along the path to the next waypoint.
    """

    ros_type: ClassVar[str] = "nav_msgs/msg/Path"
    stamp_ns: int
    frame_id: str
    xy_m: npt.NDArray[np.float64] = field(repr=False)

    def __post_init__(self) -> None:
        self.xy_m.flags.writeable = False

    def size_bytes(self) -> int:
        """Header and a sequence of PoseStamped in the same frame."""
        offset = uint32(header(0, self.frame_id))
        for _ in range(len(self.xy_m)):
            offset = doubles(header(offset, self.frame_id), 7)
        return ENCAPSULATION + offset

    def to_cdr(self) -> bytes:
        """Header, then every waypoint as a PoseStamped with the path's stamp and frame."""
        w = CdrWriter()
        w.header(self.stamp_ns, self.frame_id)
        xy = self.xy_m
        w.u32(len(xy))
        if len(xy):
            step = np.diff(xy, axis=0)
            yaw = np.arctan2(step[:, 1], step[:, 0]).tolist()
            yaw.append(yaw[-1] if yaw else 0.0)
            for (x, y), heading in zip(xy.tolist(), yaw, strict=True):
                w.header(self.stamp_ns, self.frame_id)
                w.pose2d(x, y, heading)
        return w.data()
