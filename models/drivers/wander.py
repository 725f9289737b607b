"""A reactive wander behaviour from lidar scans, vectorized over robots.

Each robot drives forward, slows down as the free range ahead shrinks, and turns towards
the more open side; when the way ahead is blocked it turns on the spot. It needs no map
and no goal: the classic way to keep a simulated fleet moving (as Stage's ``wander``
controller does) so that sensors, kinematics and contacts can be exercised and timed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from models.arrays import FloatArray


@dataclass(frozen=True)
class WanderParams:
    """Parameters of :func:`wander`.

    Attributes:
        stop_m: free range ahead (from the sensor) below which the robot turns in place (m).
        slow_m: free range ahead over which the robot slows from full speed to zero (m).
        front_half_width_rad: half width of the sector looked at ahead (rad).
        turn_gain: yaw rate per metre of left/right clearance difference (rad/s/m).
    """

    stop_m: float = 0.8
    slow_m: float = 1.5
    front_half_width_rad: float = 0.6
    turn_gain: float = 0.8


def wander(
    ranges: FloatArray,
    angles: FloatArray,
    range_max_m: float,
    max_speed_mps: float,
    max_yaw_rate_radps: float,
    params: WanderParams,
) -> tuple[FloatArray, FloatArray]:
    """Velocity commands for robots from their latest scans.

    Args:
        ranges: (n, b) ranges (m) in the sensor frame; ``inf``/``nan`` read as free.
        angles: (b,) beam angles in the sensor frame (rad, 0 = ahead).
        range_max_m: maximum range of the lidar (m).
        max_speed_mps: cruise speed (m/s).
        max_yaw_rate_radps: yaw-rate limit (rad/s).
        params: behaviour parameters.

    Returns:
        ``(v, w)``: forward speeds (m/s) and yaw rates (rad/s), one per robot.
    """
    free = np.where(np.isfinite(ranges) & (ranges > 0), ranges, range_max_m)
    front = np.abs(angles) <= params.front_half_width_rad
    left = (angles > params.front_half_width_rad) & (angles < np.pi / 2 + 0.3)
    right = (angles < -params.front_half_width_rad) & (angles > -np.pi / 2 - 0.3)
    ahead = free[:, front].min(axis=1)
    left_clear = free[:, left].mean(axis=1) if left.any() else np.zeros(len(free))
    right_clear = free[:, right].mean(axis=1) if right.any() else np.zeros(len(free))
    speed = np.clip((ahead - params.stop_m) / params.slow_m, 0.0, 1.0) * max_speed_mps
    bias = params.turn_gain * (left_clear - right_clear)
    # blocked: turn on the spot towards the more open side, at full rate
    blocked_turn = np.where(left_clear >= right_clear, 1.0, -1.0) * max_yaw_rate_radps
    w = np.where(speed > 0, np.clip(bias, -max_yaw_rate_radps, max_yaw_rate_radps), blocked_turn)
    return speed, w
