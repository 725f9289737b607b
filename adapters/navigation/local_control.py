"""The local controller of every robot: a batched Dynamic Window Approach (Nav2's DWB role).

Each control tick it turns every robot's carrot (the point of its global path a lookahead
ahead) into a speed and a yaw rate, keeping clear of the lidar hits each robot remembers
near it and of the other robots' discs it heard of; near things that move, speeds are
capped (:func:`models.navigation.traffic.speed_caps`).
"""

from __future__ import annotations

import numpy as np

from adapters.navigation.robots_layer import RobotsLayer
from models.arrays import BoolArray, FloatArray, IntArray
from models.kinematics import DriveLimits
from models.navigation.dwa import DwaParams, dwa_batch
from models.navigation.traffic import MovingPoints, TrafficParams, speed_caps


class DwaControl:
    """DWA commands for the whole fleet at once.

    Args:
        limits: the robots' drive limits.
        radii_m: (n,) every robot's footprint radius (m).
        radius_m: the fleet's footprint radius (m): how wide a robot ahead reaches.
        control_hz: the control rate (Hz): the step DWA simulates.
        robots_layer: the other robots' discs heard over the network, if used.
        traffic: the traffic rules that cap speeds near moving things.
    """

    def __init__(
        self,
        limits: DriveLimits,
        radii_m: FloatArray,
        radius_m: float,
        control_hz: float,
        robots_layer: RobotsLayer | None,
        traffic: TrafficParams,
    ) -> None:
        self.limits = limits
        self.radii_m = radii_m
        self.radius_m = radius_m
        self.params = DwaParams(control_period_s=1.0 / control_hz)
        self.robots_layer = robots_layer
        self.traffic = traffic

    def commands(
        self,
        pose: FloatArray,
        vel: FloatArray,
        carrots: FloatArray,
        goals: FloatArray,
        points: FloatArray,
        start: IntArray,
        moving: MovingPoints,
        now_ns: int,
    ) -> tuple[FloatArray, FloatArray, BoolArray]:
        """Speeds (m/s, capped near moving things), yaw rates (rad/s), and blocked robots.

        Args:
            pose: (n, 3) pose estimates in ``map`` (m, rad).
            vel: (n, 2) measured speeds and yaw rates (m/s, rad/s).
            carrots: (n, 2) the points to head for (m, ``map``).
            goals: (n, 2) the goals (m, ``map``).
            points: lidar hits near the robots (m, ``map``), robot ``i``'s at
                ``points[start[i]:start[i + 1]]``.
            start: (n + 1,) offsets into ``points``.
            moving: the hits that belong to moving things.
            now_ns: simulated time (ns): the age of what the robots layer heard.

        Returns:
            Speeds, yaw rates, and which robots found nothing admissible ahead.
        """
        n = len(pose)
        if self.robots_layer is None:
            discs, disc_start = np.zeros((0, 3)), np.zeros(n + 1, dtype=np.int64)
        else:
            discs, disc_start = self.robots_layer.all_discs(now_ns)
        result = dwa_batch(
            pose,
            vel,
            self.limits,
            self.radii_m,
            carrots,
            goals,
            points,
            start,
            discs,
            disc_start,
            self.params,
        )
        caps = speed_caps(moving, n, self.radius_m, self.limits.max_speed_mps, self.traffic)
        return np.minimum(result.v, caps), result.w, result.blocked
