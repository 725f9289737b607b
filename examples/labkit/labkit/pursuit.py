"""Pure pursuit: steer on the arc through the carrot, stop for what is close ahead.

A robot heads for the point of its path a lookahead ahead (the carrot, ``navigation.lookahead_m``)
on the circular arc through it: curvature ``2 sin(a) / d`` for a carrot at distance ``d``
and bearing ``a`` (Coulter, "Implementation of the Pure Pursuit Path Tracking Algorithm",
CMU-RI-TR-92-01, 1992). A carrot behind the robot (``|a|`` above
``pure_pursuit.turn_in_place_rad``) is turned to on the spot. Speed is ``cruise_mps``,
slowed near the goal; a lidar hit within ``stop_distance_m`` ahead of the footprint stops
the robot and reports it blocked (it then replans and recovers as with any controller).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from adapters.navigation.contract import ControlInputs, ControllerContext
from cosim.scenario.fields import param
from models.arrays import BoolArray, FloatArray


@dataclass(frozen=True)
class PursuitSettings:
    """``[pure_pursuit]``: the pure-pursuit controller's gains and safety distance."""

    cruise_mps: float = param(0.8, "speed on a straight path (m/s)", gt=0, le=2.0)
    turn_in_place_rad: float = param(
        1.2, "a carrot further off the heading than this is turned to on the spot (rad)", gt=0
    )
    stop_distance_m: float = param(
        0.35, "a lidar hit this close ahead of the footprint stops the robot (m)", gt=0
    )
    max_yaw_rate_radps: float = param(1.5, "yaw-rate limit of the controller (rad/s)", gt=0)


class PurePursuit:
    """Pure pursuit (Coulter 1992) for the whole fleet at once, with a stop for obstacles."""

    name: ClassVar[str] = "pure_pursuit"

    def __init__(self, context: ControllerContext) -> None:
        self.settings = context.run.settings(PursuitSettings)
        self.limits = context.limits
        self.radii_m = context.radii_m

    def commands(self, inputs: ControlInputs) -> tuple[FloatArray, FloatArray, BoolArray]:
        """Speeds (m/s), yaw rates (rad/s), and the robots stopped by something ahead."""
        s = self.settings
        x, y, yaw = inputs.pose[:, 0], inputs.pose[:, 1], inputs.pose[:, 2]
        dx, dy = inputs.carrots[:, 0] - x, inputs.carrots[:, 1] - y
        dist = np.hypot(dx, dy)
        bearing = np.angle(np.exp(1j * (np.arctan2(dy, dx) - yaw)))
        to_goal = np.hypot(inputs.goals[:, 0] - x, inputs.goals[:, 1] - y)
        speed = np.minimum(min(s.cruise_mps, self.limits.max_speed_mps), 0.5 + to_goal)
        curvature = 2.0 * np.sin(bearing) / np.maximum(dist, 1e-6)
        v = np.where(np.abs(bearing) > s.turn_in_place_rad, 0.0, speed)
        w = np.where(v > 0, v * curvature, np.sign(bearing) * s.max_yaw_rate_radps)
        w = np.clip(w, -s.max_yaw_rate_radps, s.max_yaw_rate_radps)
        blocked = self._obstacle_ahead(inputs, yaw)
        v = np.where(blocked, 0.0, v)
        return v, w, blocked

    def _obstacle_ahead(self, inputs: ControlInputs, yaw: FloatArray) -> BoolArray:
        """Robots with a lidar hit within the stop distance ahead of their footprint."""
        blocked = np.zeros(len(yaw), dtype=bool)
        for i in range(len(yaw)):
            near = inputs.points[inputs.start[i] : inputs.start[i + 1]]
            if not len(near):
                continue
            rel = near - inputs.pose[i, :2]
            ahead = rel[:, 0] * np.cos(yaw[i]) + rel[:, 1] * np.sin(yaw[i])
            side = -rel[:, 0] * np.sin(yaw[i]) + rel[:, 1] * np.cos(yaw[i])
            radius = self.radii_m[i]
            front = (ahead > 0) & (ahead < radius + self.settings.stop_distance_m)
            blocked[i] = bool((front & (np.abs(side) < radius)).any())
        return blocked
