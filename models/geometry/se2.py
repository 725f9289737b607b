"""Planar rigid transforms (x, y, yaw) as tuples: composition, inverse, relative motion."""

from __future__ import annotations

import math

from models.geometry.angles import wrap_angle

Pose = tuple[float, float, float]
"""x (m), y (m), yaw (rad): a frame's pose, or a transform from child to parent frame."""


def compose(a: Pose, b: Pose) -> Pose:
    """``a`` followed by ``b`` expressed in ``a``'s frame (``a * b``)."""
    c, s = math.cos(a[2]), math.sin(a[2])
    return (a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], wrap_angle(a[2] + b[2]))


def inverse(a: Pose) -> Pose:
    """The inverse transform."""
    c, s = math.cos(a[2]), math.sin(a[2])
    return (-c * a[0] - s * a[1], s * a[0] - c * a[1], wrap_angle(-a[2]))


def relative(a: Pose, b: Pose) -> Pose:
    """``b`` in ``a``'s frame (``a^-1 * b``): the motion from ``a`` to ``b``."""
    return compose(inverse(a), b)


def yaw_of_quaternion(x: float, y: float, z: float, w: float) -> float:
    """Yaw (rad, in [-pi, pi]) of a unit quaternion: its rotation about z (REP 103, as tf2)."""
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
