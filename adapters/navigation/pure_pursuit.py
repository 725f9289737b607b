"""The ``rpp`` local controller: Regulated Pure Pursuit (Nav2's RPP) for the whole fleet.

Macenski, Singh, Martin and Gines, "Regulated Pure Pursuit for Robot Path Tracking",
Autonomous Robots 47, 2023. Each control tick every robot pursues its carrot on an arc,
its speed regulated by the arc's curvature, by how close the nearest lidar hit or robot
disc is, and by the distance to its goal; it turns on the spot towards a carrot far off
its heading, and stops and reports itself blocked when its arc would come within
``collision_margin_m`` of something (:func:`models.navigation.pure_pursuit.rpp_batch`).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import ClassVar

from adapters.navigation.contract import ControlInputs, ControllerContext
from cosim.scenario.fields import param
from models.arrays import BoolArray, FloatArray
from models.navigation.pure_pursuit import RppParams, rpp_batch

_DEFAULT = RppParams()


@dataclass(frozen=True)
class RppSettings:
    """``[rpp]``: the speeds, distances and angles of Regulated Pure Pursuit.

    Defaults are Nav2's but for the speed (1 m/s, the robots' default limit, where Nav2
    has 0.5), the proximity distance (measured from the footprint's edge here, from its
    centre in Nav2) and the collision margin (5 cm, where Nav2 pads the footprint by 1 cm:
    a lidar hit has 1 cm of noise here).
    """

    ORDER: ClassVar[int] = 61
    """In a resolved scenario file, right after ``[navigation]``."""

    desired_speed_mps: float = param(
        _DEFAULT.desired_speed_mps,
        "speed on a straight, clear path, capped by robots.max_speed_mps (m/s)",
        gt=0,
    )
    lookahead_time_s: float = param(
        _DEFAULT.lookahead_time_s,
        "lookahead per m/s of speed, the carrot pulled in to it; 0: the carrot of "
        "navigation.lookahead_m as it is (s)",
        ge=0,
    )
    min_lookahead_m: float = param(
        _DEFAULT.min_lookahead_m, "shortest speed-scaled lookahead (m)", gt=0
    )
    min_turn_radius_m: float = param(
        _DEFAULT.min_turn_radius_m,
        "arcs tighter than this slow the robot by radius / this (m)",
        gt=0,
    )
    min_regulated_speed_mps: float = param(
        _DEFAULT.min_regulated_speed_mps,
        "curvature and proximity slow the robot no further than this (m/s)",
        ge=0,
    )
    proximity_clearance_m: float = param(
        _DEFAULT.proximity_clearance_m,
        "slow down when the nearest lidar hit or robot disc is closer than this to the "
        "footprint (m)",
        gt=0,
    )
    proximity_gain: float = param(
        _DEFAULT.proximity_gain,
        "speed scale per unit of clearance / proximity_clearance_m, at most 1",
        gt=0,
        le=1,
        unit="ratio",
    )
    approach_distance_m: float = param(
        _DEFAULT.approach_distance_m,
        "slow down linearly within this distance of the final goal (m)",
        gt=0,
    )
    min_approach_speed_mps: float = param(
        _DEFAULT.min_approach_speed_mps, "slowest speed onto the goal (m/s)", gt=0
    )
    rotate_to_heading_min_angle_rad: float = param(
        _DEFAULT.rotate_to_heading_min_angle_rad,
        "turn on the spot when the carrot is this far off the heading (rad)",
        gt=0,
    )
    rotate_to_heading_speed_radps: float = param(
        _DEFAULT.rotate_to_heading_speed_radps, "yaw rate of those turns on the spot (rad/s)", gt=0
    )
    collision_time_s: float = param(
        _DEFAULT.collision_time_s,
        "check the commanded arc this far ahead, up to the carrot (s)",
        gt=0,
    )
    collision_margin_m: float = param(
        _DEFAULT.collision_margin_m,
        "clearance beyond the footprint the commanded arc must keep, else the robot stops "
        "blocked (m)",
        ge=0,
    )
    footprint_padding_m: float = param(
        0.1,
        "the global planner keeps paths this much farther from obstacles than the footprint (m)",
        ge=0,
    )


class RegulatedPurePursuit:
    """Regulated Pure Pursuit (Macenski et al. 2023) for the whole fleet at once."""

    name: ClassVar[str] = "rpp"

    def __init__(self, context: ControllerContext) -> None:
        s = context.run.settings(RppSettings)
        self.limits = context.limits
        self.radii_m = context.radii_m
        kernel = {key: value for key, value in asdict(s).items() if key != "footprint_padding_m"}
        self.params = RppParams(control_period_s=1.0 / context.control_hz, **kernel)
        self.footprint_padding_m = s.footprint_padding_m
        """The arcs keep this clearance beyond the footprint (m): the global planner keeps
        its paths out of gaps narrower than that on both sides."""

    def commands(self, inputs: ControlInputs) -> tuple[FloatArray, FloatArray, BoolArray]:
        """Speeds (m/s), yaw rates (rad/s), and the robots whose arc ahead is not clear."""
        result = rpp_batch(
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
