"""How the robots moved, and what deciding it cost: jerk and the local controller's time.

A controller is judged by more than goals reached: a comparison of controllers
(``studies/local_replanning.toml``) also wants how smoothly the robots drove and how long
the controller took to decide. At every control tick of robots following their own paths
this keeps

- **jerk**: from the robots' true body velocities (:class:`~models.fleet.kinematics.FleetState`
  ``v``, ``w``) sampled at the control ticks, the second difference over the tick
  (``(v_k - 2 v_{k-1} + v_{k-2}) / dt**2``), absolute, averaged over robots driving to a
  goal (m/s^3, and rad/s^3 for the yaw rate). A controller that dithers between braking
  and driving scores high; one that holds its speed scores 0. The sampling is the control
  rate, so runs at different ``navigation.control_hz`` are not comparable by it.
- **decision time**: the wall-clock time of the controller's ``commands`` call per tick
  (the whole fleet) and per robot, in milliseconds and microseconds (volatile: a property
  of the machine, left out when runs are compared).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from cosim.core.summary import SummaryKey
from models.arrays import BoolArray, FloatArray

MOTION_SUMMARY: Mapping[str, SummaryKey] = {
    "mean_abs_jerk_mps3": SummaryKey(
        "m/s^3",
        "mean absolute jerk of the robots' speed at the control ticks, over robots driving "
        "to a goal on their own paths (null: none)",
    ),
    "mean_abs_yaw_jerk_radps3": SummaryKey(
        "rad/s^3",
        "the same for the yaw rate (null: none)",
    ),
    "controller_ms_per_tick": SummaryKey(
        "ms",
        "wall-clock time of the local controller's decision for the whole fleet, mean over "
        "control ticks (null: never called)",
        volatile=True,
    ),
    "controller_us_per_robot": SummaryKey(
        "us",
        "the same per robot: controller_ms_per_tick over the fleet's size (null: never called)",
        volatile=True,
    ),
}
"""The summary keys :meth:`MotionQuality.summary` writes."""


class MotionQuality:
    """Jerk of the robots' motion and the controller's decision time over a run.

    Args:
        robots: the fleet's size.
        control_hz: the rate of the ticks :meth:`sample` is called at (Hz).
    """

    def __init__(self, robots: int, control_hz: float) -> None:
        self.robots = robots
        self.dt_s = 1.0 / control_hz
        self.history = np.full((2, robots, 2), math.nan)
        """The last two samples of ``v, w`` per robot (m/s, rad/s); NaN: none yet."""
        self.jerk_sum = np.zeros(2)
        self.jerk_count = 0
        self.decide_s = 0.0
        self.decisions = 0

    def sample(self, v: FloatArray, w: FloatArray, driving: BoolArray) -> None:
        """Take the fleet's true speeds (m/s) and yaw rates (rad/s) at one control tick.

        Args:
            v: (n,) speeds.
            w: (n,) yaw rates.
            driving: (n,) robots driving to a goal: only their jerk counts, and a robot
                that stops driving starts again from two fresh samples.
        """
        now = np.stack([np.asarray(v, dtype=float), np.asarray(w, dtype=float)], axis=1)
        older, old = self.history
        jerk = (now - 2.0 * old + older) / self.dt_s**2
        counted = driving & np.isfinite(jerk).all(axis=1)
        if counted.any():
            self.jerk_sum += np.abs(jerk[counted]).sum(axis=0)
            self.jerk_count += int(counted.sum())
        self.history = np.stack([old, now])
        self.history[:, ~driving] = math.nan

    def decided(self, seconds: float) -> None:
        """Count one decision of the controller for the whole fleet, ``seconds`` of wall time."""
        self.decide_s += seconds
        self.decisions += 1

    def summary(self) -> dict[str, Any]:
        """The :data:`MOTION_SUMMARY` keys."""
        jerk = self.jerk_sum / self.jerk_count if self.jerk_count else None
        per_tick_ms = 1e3 * self.decide_s / self.decisions if self.decisions else None
        return {
            "mean_abs_jerk_mps3": None if jerk is None else round(float(jerk[0]), 6),
            "mean_abs_yaw_jerk_radps3": None if jerk is None else round(float(jerk[1]), 6),
            "controller_ms_per_tick": None if per_tick_ms is None else round(per_tick_ms, 4),
            "controller_us_per_robot": (
                None if per_tick_ms is None else round(1e3 * per_tick_ms / max(self.robots, 1), 3)
            ),
        }
