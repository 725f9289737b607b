"""A go-to-goal controller for differential-drive robots, vectorized over robots.

Turn towards the goal, drive forward with a speed that falls with the heading error and
the remaining distance. It avoids nothing: it is the simplest correct way to drive
between points that see each other, and the baseline for the navigation layer.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from models.arrays import FloatArray
from models.geometry.angles import wrap_angles


@dataclass(frozen=True)
class GoToGains:
    """Gains of :func:`go_to_goal`.

    Attributes:
        k_heading: yaw rate per rad of heading error (1/s).
        k_distance: forward speed per metre of remaining distance (1/s).
        turn_in_place_rad: heading error above which the robot turns on the spot (rad).
        tolerance_m: distance at which the goal counts as reached (m).
    """

    k_heading: float = 2.0
    k_distance: float = 1.0
    turn_in_place_rad: float = 0.8
    tolerance_m: float = 0.2


def go_to_goal(
    x: FloatArray,
    y: FloatArray,
    yaw: FloatArray,
    goal_x: FloatArray,
    goal_y: FloatArray,
    max_speed_mps: float,
    gains: GoToGains,
) -> tuple[FloatArray, FloatArray, npt.NDArray[np.bool_]]:
    """Velocity commands that drive each robot towards its goal.

    Args:
        x: current x in ``map`` (m).
        y: current y in ``map`` (m).
        yaw: current heading in ``map`` (rad).
        goal_x: goal x in ``map`` (m).
        goal_y: goal y in ``map`` (m).
        max_speed_mps: cruise speed (m/s).
        gains: controller gains.

    Returns:
        ``(v, w, arrived)``: forward speed (m/s), yaw rate (rad/s), and whether each
        robot is within the tolerance (its command is then zero).
    """
    dx = goal_x - x
    dy = goal_y - y
    distance = np.hypot(dx, dy)
    error = wrap_angles(np.arctan2(dy, dx) - yaw)
    arrived = distance <= gains.tolerance_m
    w = gains.k_heading * error
    v = np.minimum(max_speed_mps, gains.k_distance * distance) * np.cos(error)
    v = np.where(np.abs(error) > gains.turn_in_place_rad, 0.0, np.maximum(v, 0.0))
    return np.where(arrived, 0.0, v), np.where(arrived, 0.0, w), arrived
