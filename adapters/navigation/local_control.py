"""The ``dwa`` local controller: a batched Dynamic Window Approach (Nav2's DWB role).

Each control tick it turns every robot's carrot into a speed and a yaw rate by scoring
sampled velocities over a short horizon against the lidar hits each robot remembers near it
and the other robots' discs it heard of (:func:`models.navigation.dwa.dwa_batch`), all
robots in one call.
"""

from __future__ import annotations

from typing import ClassVar

from adapters.navigation.contract import ControlInputs, ControllerContext
from models.arrays import BoolArray, FloatArray
from models.navigation.dwa import DwaParams, dwa_batch


class DwaControl:
    """Dynamic Window Approach (Fox, Burgard, Thrun 1997) for the whole fleet at once."""

    name: ClassVar[str] = "dwa"

    def __init__(self, context: ControllerContext) -> None:
        self.limits = context.limits
        self.radii_m = context.radii_m
        self.params = DwaParams(control_period_s=1.0 / context.control_hz)
        self.footprint_padding_m = self.params.safety_margin_m
        """DWA admits no trajectory closer than this beyond the footprint (m): the global
        planner keeps its paths out of gaps narrower than that on both sides."""

    def commands(self, inputs: ControlInputs) -> tuple[FloatArray, FloatArray, BoolArray]:
        """Speeds (m/s), yaw rates (rad/s), and the robots that found nothing admissible."""
        result = dwa_batch(
            inputs.pose,
            inputs.vel,
            self.limits,
            self.radii_m,
            inputs.carrots,
            inputs.goals,
            inputs.points,
            inputs.start,
            inputs.discs,
            inputs.disc_start,
            self.params,
            inputs.slices,
        )
        return result.v, result.w, result.blocked
