"""Mirrored robots: twins whose ground truth is where a real (or replayed) robot was measured.

A physical robot is not integrated from its commands: the simulation takes its pose from
the motion capture (or the robot's own odometry) and every other part of the run, lidars
and collision checks included, sees the twin there. The fleet applies the newest measured
pose at its next physics tick, after the motion guards (a real robot cannot be held back
by a simulated contact; the contact is still recorded).
"""

from __future__ import annotations

import numpy as np

from models.fleet.kinematics import FleetState, Motion
from models.geometry.angles import wrap_angles


class Mirrors:
    """The robots whose poses come from outside, and their newest measured poses (``map``).

    Args:
        fleet: the ground-truth state the twins live in.
    """

    def __init__(self, fleet: FleetState) -> None:
        n = len(fleet)
        self.fleet = fleet
        self.mirrored = np.zeros(n, dtype=bool)
        self.target = np.stack([fleet.x, fleet.y, fleet.yaw], axis=1)
        self.fresh = np.zeros(n, dtype=bool)
        self.updates = np.zeros(n, dtype=np.int64)

    def add(self, index: int) -> None:
        """Make robot ``index`` a twin: from now on it moves only when a pose arrives."""
        self.mirrored[index] = True

    def set(self, index: int, x_m: float, y_m: float, yaw_rad: float) -> None:
        """The newest measured pose of twin ``index`` in ``map`` (m, m, rad)."""
        if not self.mirrored[index]:
            raise ValueError(f"robot {self.fleet.names[index]} is not mirrored")
        self.target[index] = (x_m, y_m, yaw_rad)
        self.fresh[index] = True
        self.updates[index] += 1

    @property
    def any(self) -> bool:
        """Whether any robot is mirrored."""
        return bool(self.mirrored.any())

    def apply(self, motion: Motion, dt_s: float) -> None:
        """Put every twin at its newest pose in ``motion``; without one it stands still.

        The velocities are those that explain the displacement over ``dt_s``: forward
        speed along the heading, yaw rate from the wrapped heading change.
        """
        fleet = self.fleet
        moved = self.mirrored & self.fresh
        still = self.mirrored & ~self.fresh
        if still.any():
            fleet.hold(motion, np.flatnonzero(still))
        if not moved.any():
            return
        idx = np.flatnonzero(moved)
        x, y, yaw = self.target[idx, 0], self.target[idx, 1], self.target[idx, 2]
        dx, dy = x - fleet.x[idx], y - fleet.y[idx]
        heading = fleet.yaw[idx]
        motion.v[idx] = (dx * np.cos(heading) + dy * np.sin(heading)) / dt_s
        motion.w[idx] = wrap_angles(yaw - heading) / dt_s
        motion.x[idx], motion.y[idx], motion.yaw[idx] = x, y, wrap_angles(yaw)
        self.fresh[idx] = False
