"""The ``orca`` local controller: Optimal Reciprocal Collision Avoidance over the network.

Each control tick it turns every robot's carrot into a speed and a yaw rate with ORCA (van
den Berg, Guy, Lin, Manocha, "Reciprocal n-Body Collision Avoidance", ISRR 2009, Springer
STAR 70, 2011), all robots in one compiled call (:func:`models.navigation.orca.orca_batch`):
the other robots it heard of over the robots layer (``navigation.robots_layer``) are
avoided reciprocally, each moved on from where it was heard by its heard velocity times the
age of the news, so network latency is accounted for; the lidar hits are static obstacles
it keeps clear of alone. Without the robots layer every other robot is only lidar hits.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from adapters.navigation.contract import ControlInputs, ControllerContext
from cosim.scenario.fields import param
from models.arrays import BoolArray, FloatArray
from models.navigation.orca import OrcaParams, orca_batch


@dataclass(frozen=True)
class OrcaSettings:
    """``[orca]``: horizons, margin and gains of the ORCA local controller."""

    ORDER: ClassVar[int] = 63
    """In a resolved scenario file, right after ``[navigation]``."""

    time_horizon_s: float = param(
        2.0, "horizon of the other robots' velocity obstacles: avoid contact within it (s)", gt=0
    )
    obstacle_horizon_s: float = param(
        1.0, "horizon of the lidar hits' velocity obstacles (s); shorter lets robots nearer", gt=0
    )
    margin_m: float = param(
        0.15,
        "added to every footprint radius (m): the clearance kept and the differential drive's "
        "tracking error (an effective radius, Alonso-Mora et al. 2010); the global planner "
        "keeps its paths this far off obstacles too",
        ge=0,
        le=1.0,
    )
    obstacle_sectors: int = param(
        32,
        "lidar hits are cut to the nearest in each of this many sectors round the robot",
        ge=4,
        le=360,
        unit="count",
    )
    heading_gain: float = param(
        2.0,
        "yaw rate per radian between the heading and the chosen velocity (1/s)",
        gt=0,
        unit="1/s",
    )
    arrive_gain_per_s: float = param(
        1.0, "preferred speed per metre still to go to the goal, near it (1/s)", gt=0
    )
    keep_right_rad: float = param(
        0.1,
        "turn the preferred velocity this far clockwise when another robot is in the way (rad), "
        "so that exactly symmetric encounters pass on the right",
        ge=0,
        le=1.5,
    )
    extrapolate: bool = param(
        True,
        "move every heard robot on by its heard velocity times the age of the news (latency "
        "included); false: avoid it where it was when it sent its state",
    )


class Orca:
    """ORCA (van den Berg et al. 2011) for the whole fleet at once, with heard neighbours."""

    name: ClassVar[str] = "orca"

    def __init__(self, context: ControllerContext) -> None:
        settings = context.run.settings(OrcaSettings)
        self.limits = context.limits
        self.radii_m = context.radii_m
        self.params = OrcaParams(
            time_horizon_s=settings.time_horizon_s,
            obstacle_horizon_s=settings.obstacle_horizon_s,
            margin_m=settings.margin_m,
            obstacle_sectors=settings.obstacle_sectors,
            heading_gain=settings.heading_gain,
            arrive_gain_per_s=settings.arrive_gain_per_s,
            keep_right_rad=settings.keep_right_rad,
            extrapolate=settings.extrapolate,
            control_period_s=1.0 / context.control_hz,
        )
        self.footprint_padding_m = settings.margin_m
        """ORCA keeps this beyond the footprint from every lidar hit (m): the global planner
        keeps its paths out of gaps narrower than that on both sides."""

    def commands(self, inputs: ControlInputs) -> tuple[FloatArray, FloatArray, BoolArray]:
        """Speeds (m/s), yaw rates (rad/s), and the robots left standing against their will."""
        neighbours = inputs.neighbours
        if len(neighbours) != len(inputs.discs):
            # nothing heard of how they move: standing, as of now
            neighbours = np.zeros((len(inputs.discs), 5))
            neighbours[:, :2] = inputs.discs[:, :2]
        result = orca_batch(
            inputs.pose,
            inputs.vel,
            self.limits,
            self.radii_m,
            inputs.carrots,
            inputs.goals,
            inputs.points,
            inputs.start,
            inputs.discs,
            neighbours,
            inputs.disc_start,
            self.params,
            inputs.slices,
        )
        return result.v, result.w, result.blocked
