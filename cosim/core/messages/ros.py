"""Messages with a standard ROS 2 type (geometry_msgs, nav_msgs, sensor_msgs), planar views.

Each binds its fields onto the standard type it is sent as (:mod:`cosim.core.messages.std`):
what a planar robot does not use (z, roll, pitch, covariances) is zero on the wire.
Frames follow REP 105: ``map`` (fixed world frame), ``odom`` (drifting, continuous),
``base_link`` (robot body), ``laser`` (sensor).
"""

from __future__ import annotations

import math
from dataclasses import field
from typing import Any

import numpy as np
import numpy.typing as npt

from cosim.core.messages import std
from cosim.core.messages.declare import Message, ros_message
from cosim.core.messages.views import Const, Planar, Rows


@ros_message(std.TWIST, wire={"linear.x": "linear_x_mps", "angular.z": "angular_z_radps"})
class Twist(Message):
    """A velocity command for a planar robot (``geometry_msgs/msg/Twist``), frame ``base_link``.

    Attributes:
        linear_x_mps: forward speed in m/s.
        angular_z_radps: yaw rate in rad/s (counter-clockwise positive).
    """

    linear_x_mps: float
    angular_z_radps: float


@ros_message(
    std.ODOMETRY,
    wire={
        "header.stamp": "stamp_ns",
        "header.frame_id": "frame_id",
        "child_frame_id": "child_frame_id",
        "pose.pose": Planar("x_m", "y_m", "yaw_rad"),
        "twist.twist.linear.x": "v_mps",
        "twist.twist.angular.z": "w_radps",
    },
)
class Odometry(Message):
    """Pose and velocity estimate of a planar robot (``nav_msgs/msg/Odometry``).

    Both covariances are zero on the wire (unknown, as many drivers send).

    Attributes:
        stamp_ns: time of the estimate, ns.
        frame_id: pose frame (``odom``).
        child_frame_id: body frame (``base_link``).
        x_m, y_m, yaw_rad: pose of ``base_link`` in ``frame_id``.
        v_mps, w_radps: body-frame forward speed (m/s) and yaw rate (rad/s).
    """

    stamp_ns: int
    frame_id: str
    child_frame_id: str
    x_m: float
    y_m: float
    yaw_rad: float
    v_mps: float
    w_radps: float


@ros_message(
    std.POSE_STAMPED,
    wire={
        "header.stamp": "stamp_ns",
        "header.frame_id": "frame_id",
        "pose": Planar("x_m", "y_m", "yaw_rad"),
    },
)
class PoseStamped(Message):
    """A planar pose with a time stamp (``geometry_msgs/msg/PoseStamped``).

    Attributes:
        stamp_ns: time of the pose, ns.
        frame_id: frame of the pose (``map`` for ground truth and motion capture).
        x_m, y_m, yaw_rad: position (m) and heading (rad) in ``frame_id``.
    """

    stamp_ns: int
    frame_id: str
    x_m: float
    y_m: float
    yaw_rad: float


@ros_message(
    std.LASER_SCAN,
    wire={
        "header.stamp": "stamp_ns",
        "header.frame_id": "frame_id",
        "angle_min": "angle_min_rad",
        "angle_max": "angle_max_rad",
        "angle_increment": "angle_increment_rad",
        "scan_time": "scan_time_s",
        "range_min": "range_min_m",
        "range_max": "range_max_m",
        "ranges": "ranges_m",
    },
)
class LaserScan(Message):
    """One planar lidar sweep (``sensor_msgs/msg/LaserScan``), REP 117 range conventions.

    Beam ``i`` points at ``angle_min_rad + i * angle_increment_rad`` in ``frame_id``.
    A beam without a return holds ``+inf``; a dropped-out beam holds ``nan``. Every beam
    of a sweep is cast at its stamp (``time_increment`` 0); no intensities.

    Attributes:
        stamp_ns: acquisition time of the first beam, ns.
        frame_id: sensor frame.
        angle_min_rad, angle_increment_rad: beam angles (rad).
        range_min_m, range_max_m: valid range interval (m).
        scan_time_s: time between scans (s).
        ranges_m: float32 ranges, read-only.
    """

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


@ros_message(
    std.POSE_STAMPED,
    wire={
        "header.stamp": "stamp_ns",
        "header.frame_id": Const("map"),
        "pose": Planar("x_m", "y_m", "yaw_rad", yaw_nan=0.0),
    },
)
class Goal(Message):
    """A navigation goal in ``map`` (``geometry_msgs/msg/PoseStamped`` on the wire).

    No heading (``nan``) is written as yaw 0.

    Attributes:
        stamp_ns: when the goal was issued, ns.
        x_m, y_m: goal position in ``map`` (m).
        yaw_rad: goal heading in ``map`` (rad), or ``nan`` for "any heading".
    """

    stamp_ns: int
    x_m: float
    y_m: float
    yaw_rad: float = float("nan")


def _path_rows(path: Path) -> list[Any]:
    """Every waypoint as a PoseStamped row, heading along the path to the next one."""
    xy = path.xy_m
    if not len(xy):
        return []
    step = np.diff(xy, axis=0)
    yaw = np.arctan2(step[:, 1], step[:, 0]).tolist()
    yaw.append(yaw[-1] if yaw else 0.0)
    header = (path.stamp_ns, path.frame_id)
    return [
        (header, ((x, y, 0.0), (0.0, 0.0, math.sin(0.5 * h), math.cos(0.5 * h))))
        for (x, y), h in zip(xy.tolist(), yaw, strict=True)
    ]


def _path_xy(rows: list[Any]) -> npt.NDArray[np.float64]:
    """The waypoints of decoded PoseStamped rows."""
    return np.array([pose[0][:2] for _, pose in rows], dtype=np.float64).reshape(-1, 2)


@ros_message(
    std.PATH,
    wire={
        "header.stamp": "stamp_ns",
        "header.frame_id": "frame_id",
        "poses": Rows("xy_m", _path_rows, _path_xy),
    },
)
class Path(Message):
    """A planned path (``nav_msgs/msg/Path``), as Nav2's planner publishes on ``plan``.

    Attributes:
        stamp_ns: when the path was planned, ns.
        frame_id: frame of the waypoints (``map``).
        xy_m: waypoints (k, 2) in ``frame_id`` (m), read-only; each pose's heading points
            along the path to the next waypoint (every pose carries the path's stamp and
            frame).
    """

    stamp_ns: int
    frame_id: str
    xy_m: npt.NDArray[np.float64] = field(repr=False)

    def __post_init__(self) -> None:
        self.xy_m.flags.writeable = False
