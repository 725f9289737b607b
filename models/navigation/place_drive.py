"""Driving from place to place: turn on the spot, then straight, braking onto the point.

Robots that the fleet manager moves between reserved places drive the straight line
between them (the reservation covers that line and nothing else), as grid-bound
warehouse robots do: turn in place towards the next point, then drive at the speed from
which they can still stop on it. Any lidar hit in the strip ahead stops them: a protective
field in the robot's own frame, as on industrial AGVs' safety laser scanners, which holds
whatever the robot's pose estimate (a robot localizing on its own map may be 0.4 m off its
place, and a robot parked for long is in its neighbours' maps, not "moving"). The strip is
the footprint's width: 3 cm wider, robots in fleet50 (20 seeds x 300 s, traffic "pibt") kept
37-40 mm apart instead of 7-15 mm but gave up 8 goals instead of 5, with as many reached.
"""

from __future__ import annotations

from typing import Any

import numba
import numpy as np

from models.arrays import FloatArray, IntArray
from models.fleet.kinematics import DriveLimits
from models.geometry.angles import wrap_angles

TURN_FIRST_RAD = 0.3
"""Heading error above which a robot turns on the spot before driving (rad)."""
YAW_GAIN = 2.5
"""Yaw-rate command per radian of heading error (1/s)."""
FINAL_GAIN = 2.0
"""Speed limit per metre left to the point (1/s)."""
THERE_M = 0.02
"""A robot this close to its point stands still (m)."""
STOP_MARGIN_M = 0.02
"""Free distance kept to a lidar hit ahead beyond the braking distance (m)."""


def free_ahead(
    points: FloatArray, start: IntArray, poses: FloatArray, radius_m: float
) -> FloatArray:
    """How far each robot's footprint can go straight on before it touches a lidar hit.

    Args:
        points: (k, 2) hits in ``map`` (m), CSR-packed by robot.
        start: (n + 1,) CSR offsets: robot ``i`` owns ``points[start[i]:start[i + 1]]``.
        poses: (n, 3) robot poses ``x y yaw`` in ``map`` (m, rad).
        radius_m: footprint radius (m).

    Returns:
        (n,) distance (m) the disc of ``radius_m`` travels along the robot's heading
        until it first touches one of its hits; inf when none lies in that strip ahead.
    """
    free = np.full(len(poses), np.inf)
    _free_ahead(
        np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 2),
        np.ascontiguousarray(start, dtype=np.int64),
        np.ascontiguousarray(poses, dtype=np.float64),
        float(radius_m),
        free,
    )
    return free


def _free_ahead_py(
    points: FloatArray, start: IntArray, poses: FloatArray, radius_m: float, free: FloatArray
) -> None:
    for i in range(poses.shape[0]):
        cos_yaw, sin_yaw = np.cos(poses[i, 2]), np.sin(poses[i, 2])
        for p in range(start[i], start[i + 1]):
            dx, dy = points[p, 0] - poses[i, 0], points[p, 1] - poses[i, 1]
            ahead = cos_yaw * dx + sin_yaw * dy
            side = cos_yaw * dy - sin_yaw * dx
            if ahead > 0.0 and abs(side) < radius_m:
                # the disc touches the hit once its centre is this far on
                touch = ahead - np.sqrt(radius_m * radius_m - side * side)
                free[i] = min(free[i], touch)


_free_ahead: Any = numba.njit(cache=True, nogil=True)(_free_ahead_py)


def place_drive(
    poses: FloatArray,
    points: FloatArray,
    limits: DriveLimits,
    free_m: FloatArray,
) -> tuple[FloatArray, FloatArray]:
    """Speed and yaw-rate commands that take every robot straight to its point.

    Args:
        poses: (n, 3) robot poses ``x y yaw`` in ``map`` (m, rad).
        points: (n, 2) point each robot drives to, in ``map`` (m).
        limits: drive limits.
        free_m: (n,) how far each robot can go straight on before it touches a lidar hit
            (m, :func:`free_ahead`).

    Returns:
        Forward speeds (m/s) and yaw rates (rad/s), (n,) each.
    """
    delta = points - poses[:, :2]
    distance = np.hypot(delta[:, 0], delta[:, 1])
    error = wrap_angles(np.arctan2(delta[:, 1], delta[:, 0]) - poses[:, 2])
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
    room = np.maximum(free_m - STOP_MARGIN_M, 0.0)  # how far it may go
    limit = np.minimum(np.sqrt(limits.max_accel_mps2 * room), FINAL_GAIN * room)
    v = np.where(room < distance, np.minimum(v, limit), v)
    return v, w
