"""Small recordings written as real ROS 2 bags (rosbags' writer) for ``cosim map``'s tests.

A robot drives in a 10 m x 8 m box room centred on the ``odom`` origin; its lidar's
ranges are the room's walls seen from the odometry's pose, so good input maps cleanly.
Every field of every message can be replaced to build pathological recordings.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore

TYPES = get_typestore(Stores.ROS2_HUMBLE)
_T = TYPES.types
ROOM_HALF_M = (5.0, 4.0)
"""Half the room's size along x and y (m), walls axis-aligned about the origin."""
T0_NS = 1_000_000_000
"""The first stamp (1 s: header stamps of 0 would mean "use the log time")."""


@dataclass(frozen=True)
class Scan:
    """A LaserScan's fields (ranges m, angles rad, stamps ns; frame ``base_laser``)."""

    stamp_ns: int
    ranges: Sequence[float]
    angle_min: float = -math.pi / 2
    angle_increment: float = math.pi / 90
    range_min: float = 0.1
    range_max: float = 20.0
    log_ns: int | None = None


@dataclass(frozen=True)
class Odom:
    """An Odometry pose (x m, y m, yaw rad in ``odom``; or a raw quaternion)."""

    stamp_ns: int
    x: float
    y: float
    yaw: float = 0.0
    quaternion: tuple[float, float, float, float] | None = None
    log_ns: int | None = None


def room_ranges(
    pose: tuple[float, float, float], beams: int = 91, increment: float = math.pi / 90
) -> list[float]:
    """Ranges (m) from ``pose`` (x, y, yaw in ``odom``) to the room's walls, beams from -90 deg."""
    x, y, yaw = pose
    ranges = []
    for k in range(beams):
        a = yaw - math.pi / 2 + k * increment
        c, s = math.cos(a), math.sin(a)
        hits = []
        if abs(c) > 1e-12:
            hits.append(((math.copysign(ROOM_HALF_M[0], c)) - x) / c)
        if abs(s) > 1e-12:
            hits.append(((math.copysign(ROOM_HALF_M[1], s)) - y) / s)
        ranges.append(min(h for h in hits if h > 0))
    return ranges


@dataclass
class Drive:
    """A recording: scans, odometry and optionally reference poses (all in one bag)."""

    scans: list[Scan]
    odom: list[Odom]
    reference: list[Odom] | None = None
    extra: dict[str, list[Odom]] = field(default_factory=dict)


def drive(n: int = 12, step_m: float = 0.3, dt_ns: int = 500_000_000) -> Drive:
    """A robot driving along x through the room, a scan and an odometry pose every ``dt_ns``."""
    scans, odom = [], []
    for k in range(n):
        t = T0_NS + k * dt_ns
        pose = (-1.5 + k * step_m, 0.5, 0.05 * k)
        scans.append(Scan(t, room_ranges(pose)))
        odom.append(Odom(t, *pose))
    return Drive(scans, odom, [replace(o) for o in odom])


def _header(stamp_ns: int, frame: str) -> object:
    time = _T["builtin_interfaces/msg/Time"](sec=stamp_ns // 10**9, nanosec=stamp_ns % 10**9)
    return _T["std_msgs/msg/Header"](stamp=time, frame_id=frame)


def _scan(scan: Scan) -> object:
    ranges = np.asarray(scan.ranges, dtype=np.float32)
    with np.errstate(over="ignore", invalid="ignore"):  # pathological scans: inf, NaN
        last = np.float32(scan.angle_min) + np.float32(scan.angle_increment) * (len(ranges) - 1)
    return _T["sensor_msgs/msg/LaserScan"](
        header=_header(scan.stamp_ns, "base_laser"),
        angle_min=scan.angle_min,
        angle_max=float(last) if len(ranges) else scan.angle_min,
        angle_increment=scan.angle_increment,
        time_increment=0.0,
        scan_time=0.0,
        range_min=scan.range_min,
        range_max=scan.range_max,
        ranges=ranges,
        intensities=np.zeros(0, dtype=np.float32),
    )


def _odometry(pose: Odom) -> object:
    x, y, z, w = pose.quaternion or (0.0, 0.0, math.sin(pose.yaw / 2), math.cos(pose.yaw / 2))
    geometry = _T["geometry_msgs/msg/Pose"](
        position=_T["geometry_msgs/msg/Point"](x=pose.x, y=pose.y, z=0.0),
        orientation=_T["geometry_msgs/msg/Quaternion"](x=x, y=y, z=z, w=w),
    )
    with_covariance = _T["geometry_msgs/msg/PoseWithCovariance"](
        pose=geometry, covariance=np.zeros(36)
    )
    zero = _T["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0)
    twist = _T["geometry_msgs/msg/TwistWithCovariance"](
        twist=_T["geometry_msgs/msg/Twist"](linear=zero, angular=zero), covariance=np.zeros(36)
    )
    return _T["nav_msgs/msg/Odometry"](
        header=_header(pose.stamp_ns, "odom"),
        child_frame_id="base_laser",
        pose=with_covariance,
        twist=twist,
    )


def write(path: Path, recording: Drive, storage: StoragePlugin = StoragePlugin.MCAP) -> Path:
    """Write ``recording`` as a rosbag2 folder: /scan, /odom, /ground_truth and ``extra``."""
    odometry = "nav_msgs/msg/Odometry"
    with Writer(path, version=8, storage_plugin=storage) as writer:
        rows: list[tuple[int, object, object, str]] = []
        scans = writer.add_connection("/scan", "sensor_msgs/msg/LaserScan", typestore=TYPES)
        for scan in recording.scans:
            log = scan.log_ns if scan.log_ns is not None else max(scan.stamp_ns, 1)
            rows.append((log, scans, _scan(scan), "sensor_msgs/msg/LaserScan"))
        topics = {"/odom": recording.odom, **recording.extra}
        if recording.reference is not None:
            topics["/ground_truth"] = recording.reference
        for topic, poses in topics.items():
            connection = writer.add_connection(topic, odometry, typestore=TYPES)
            for pose in poses:
                log = pose.log_ns if pose.log_ns is not None else max(pose.stamp_ns, 1)
                rows.append((log, connection, _odometry(pose), odometry))
        for log, connection, message, msgtype in sorted(rows, key=lambda r: r[0]):
            writer.write(connection, log, TYPES.serialize_cdr(message, msgtype))  # type: ignore[arg-type]
    return path
