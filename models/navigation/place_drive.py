"""Driving from place to place: turn on the spot, then straight, braking onto the point.

Robots that the fleet manager moves between reserved places drive the straight line
between them (the reservation covers that line and nothing else), as grid-bound
warehouse robots do: turn in place towards the next point, then drive at the speed from
which they can still stop on it. Any lidar hit in the strip ahead stops them: a protective
field in the robot's own frame, as on industrial AGVs' safety laser scanners, which holds
whatever the robot's pose estimate (a robot localizing on its own map may be 0.4 m off its
place, and a robot parked for long is in its neighbours' maps, not "moving").
"""

from __future__ import annotations

import numpy as np

from models.arrays import FloatArray, IntArray
from models.kinematics import DriveLimits, wrap_angle

TURN_FIRST_RAD = 0.3
"""Heading error above which a robot turns on the spot before driving (rad)."""
YAW_GAIN = 2.5
"""Yaw-rate command per radian of heading error (1/s)."""
FINAL_GAIN = 2.0
"""Speed limit per metre left to the point (1/s)."""
THERE_M = 0.02
"""A robot this close to its point stands still (m)."""
STRIP_MARGIN_M = 0.0
"""Half-width of the strip checked ahead, beyond the footprint radius (m)."""
STOP_MARGIN_M = 0.02
"""Free distance kept to a moving thing ahead beyond the braking distance (m)."""


def in_robot_frames(
    points: FloatArray, start: IntArray, poses: FloatArray
) -> tuple[IntArray, FloatArray, FloatArray]:
    """Lidar hits in their owners' ``base_link`` frames.

    Args:
        points: (k, 2) hits in ``map`` (m), CSR-packed by robot.
        start: (n + 1,) CSR offsets: robot ``i`` owns ``points[start[i]:start[i + 1]]``.
        poses: (n, 3) robot poses ``x y yaw`` in ``map`` (m, rad).

    Returns:
        ``(owner, ahead, side)``: (k,) the robot that saw each hit, and the hit's x
        (forward) and y (left) in that robot's ``base_link`` (m).
    """
    owner = np.repeat(np.arange(len(start) - 1), np.diff(start))
    pose = poses[owner]
    dx = points[:, 0] - pose[:, 0]
    dy = points[:, 1] - pose[:, 1]
    cos_yaw, sin_yaw = np.cos(pose[:, 2]), np.sin(pose[:, 2])
    return owner, cos_yaw * dx + sin_yaw * dy, cos_yaw * dy - sin_yaw * dx


def place_drive(
    poses: FloatArray,
    points: FloatArray,
    limits: DriveLimits,
    radius_m: float,
    owner: IntArray,
    ahead: FloatArray,
    side: FloatArray,
) -> tuple[FloatArray, FloatArray]:
    """Speed and yaw-rate commands that take every robot straight to its point.

    Args:
        poses: (n, 3) robot poses ``x y yaw`` in ``map`` (m, rad).
        points: (n, 2) point each robot drives to, in ``map`` (m).
        limits: drive limits.
        radius_m: footprint radius (m).
        owner: (k,) robot that saw each lidar hit.
        ahead: (k,) the hit's x in its owner's ``base_link`` (m).
        side: (k,) the hit's y in its owner's ``base_link`` (m).

    Returns:
        Forward speeds (m/s) and yaw rates (rad/s), (n,) each.
    """
    delta = points - poses[:, :2]
    distance = np.hypot(delta[:, 0], delta[:, 1])
    error = wrap_angle(np.arctan2(delta[:, 1], delta[:, 0]) - poses[:, 2])
    there = distance < THERE_M
    w = np.clip(YAW_GAIN * error, -limits.max_yaw_rate_radps, limits.max_yaw_rate_radps)
    # brake onto the point: the speed from which the robot stops on it
    # (at half the deceleration the robot can give, and slower still over the last
    # centimetres: a command holds for a control period, and robots stop 14 cm apart)
    v = np.minimum(limits.max_speed_mps, np.sqrt(limits.max_accel_mps2 * distance))
    v = np.minimum(v, FINAL_GAIN * distance)
    v = np.where(np.abs(error) > TURN_FIRST_RAD, 0.0, v * np.cos(error))
    v = np.where(there, 0.0, v)
    w = np.where(there, 0.0, w)
    # slow for any hit in the strip ahead short of the point, to stop before it
    strip = (ahead > 0) & (np.abs(side) < radius_m + STRIP_MARGIN_M)
    if strip.any():
        # how far the footprint (a disc) goes straight on before it touches the hit
        reach = np.sqrt(np.maximum(radius_m**2 - side[strip] ** 2, 0.0))
        free = np.full(len(poses), np.inf)
        np.minimum.at(free, owner[strip], ahead[strip] - reach)
        room = np.maximum(free - STOP_MARGIN_M, 0.0)  # how far it may go
        short = room < distance
        limit = np.minimum(np.sqrt(limits.max_accel_mps2 * room), FINAL_GAIN * room)
        v = np.where(short, np.minimum(v, limit), v)
    return v, w
