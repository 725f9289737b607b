"""The ``mppi`` local controller: Model Predictive Path Integral control for the fleet.

Williams, Drews, Goldfain, Rehg, Theodorou, "Aggressive Driving with Model Predictive Path
Integral Control", IEEE ICRA 2016, with critics in the roles of Nav2's MPPI controller.
Each control tick every robot's nominal control sequence is improved from sampled
perturbations scored against its carrot, goal, lidar hits and the other robots' discs
(:func:`models.navigation.mppi.mppi_batch`), all robots in one call; the sequences are
kept here between ticks. The noise comes from the run's random stream ``mppi``: the
same seed gives the same commands.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import ClassVar

import numpy as np

from adapters.navigation.contract import ControlInputs, ControllerContext
from cosim.scenario.fields import param
from models.arrays import BoolArray, FloatArray
from models.navigation.mppi import MppiParams, mppi_batch, noise_knots

_D = MppiParams()
"""The model's defaults: the section's."""


@dataclass(frozen=True)
class MppiSettings:
    """``[mppi]``: samples, horizon, noise and critic weights of the ``mppi`` controller.

    Defaults keep a tick of 50 robots at the time ``dwa`` takes: 24 samples over 12 steps
    of 0.1 s, a 1.2 s horizon (Nav2 samples 2000 over 56 steps of 0.05 s, for one robot).
    On fleet50 (runs interleaved with ``dwa``, medians; 2026-11-29) 48 samples over 15
    steps took 1.55x ``dwa``'s time per robot, these 0.84x and 1.02x in two measurements;
    20 over 12 (0.87-0.92x) reached 100 goals in ``warehouse-humans`` (8 seeds x 120 s)
    where these reached 114, and over 10 steps a robot backs up to a goal behind it
    instead of turning. Weights are
    relative: a sample's cost is their weighted sum of terms of order 1, and
    ``temperature`` is in the same units.
    """

    ORDER: ClassVar[int] = 62
    """In a resolved scenario file, right after ``[navigation]``."""

    samples: int = param(
        _D.samples, "perturbed control sequences per robot and tick", ge=1, le=4096, unit="count"
    )
    time_steps: int = param(
        _D.time_steps, "controls in a sequence (the horizon)", ge=1, le=200, unit="count"
    )
    model_dt_s: float = param(
        _D.model_dt_s, "how long each control is held in the rollouts (s)", gt=0, le=1.0
    )
    v_std_mps: float = param(_D.v_std_mps, "standard deviation of the speed noise (m/s)", ge=0)
    w_std_radps: float = param(
        _D.w_std_radps, "standard deviation of the yaw-rate noise (rad/s)", ge=0
    )
    knot_steps: int = param(
        _D.knot_steps,
        "steps between two knots of noise, linear in between",
        ge=1,
        le=200,
        unit="count",
    )
    temperature: float = param(
        _D.temperature,
        "softmax temperature lambda: lower follows the best samples more",
        gt=0,
        unit="cost",
    )
    footprint_padding_m: float = param(
        _D.footprint_padding_m,
        "clearance beyond the footprint a sample must keep, else it collides (m)",
        ge=0,
    )
    repulsion_m: float = param(_D.repulsion_m, "clearance within which obstacles cost (m)", gt=0)
    collision_cost: float = param(
        _D.collision_cost, "cost of a sample that collides", ge=0, unit="cost"
    )
    path_weight: float = param(
        _D.path_weight, "weight of the distance to the carrot ahead", ge=0, unit="weight"
    )
    heading_weight: float = param(
        _D.heading_weight, "weight of the heading error to the carrot", ge=0, unit="weight"
    )
    goal_weight: float = param(
        _D.goal_weight, "weight of the distance to the carrot near the goal", ge=0, unit="weight"
    )
    goal_zone_m: float = param(
        _D.goal_zone_m, "the carrot this near the goal: aim to stop at it, not past it (m)", ge=0
    )
    obstacle_weight: float = param(
        _D.obstacle_weight, "weight of the proximity of obstacles", ge=0, unit="weight"
    )
    smooth_weight: float = param(
        _D.smooth_weight, "weight of the change of the controls", ge=0, unit="weight"
    )
    forward_weight: float = param(
        _D.forward_weight, "weight of the distance driven backwards", ge=0, unit="weight"
    )
    goal_reset_m: float = param(
        _D.goal_reset_m,
        "a goal moved farther than this starts the robot's sequence again (m)",
        gt=0,
    )


class Mppi:
    """Model Predictive Path Integral control (Williams et al. 2016) for the whole fleet.

    Keeps every robot's nominal control sequence between ticks (one row per robot); a
    robot whose goal moved by more than ``goal_reset_m`` since the last tick (or that had
    none) starts again from a sequence of zeros.
    """

    name: ClassVar[str] = "mppi"

    def __init__(self, context: ControllerContext) -> None:
        settings = context.run.settings(MppiSettings)
        values = {f.name: getattr(settings, f.name) for f in fields(MppiSettings)}
        self.params = MppiParams(control_period_s=1.0 / context.control_hz, **values)
        self.limits = context.limits
        self.radii_m = context.radii_m
        self.rng = context.run.rng.stream("mppi")
        n = len(context.radii_m)
        self.nominal = np.zeros((n, self.params.time_steps, 2))
        """(n, time_steps, 2) every robot's nominal ``v, w`` (m/s, rad/s)."""
        self.goals = np.full((n, 2), np.nan)
        """(n, 2) the goals of the last tick in ``map`` (m); NaN before the first."""
        self.footprint_padding_m = self.params.footprint_padding_m
        """No sample comes closer than this beyond the footprint (m): the global planner
        keeps its paths out of gaps narrower than that on both sides."""

    def commands(self, inputs: ControlInputs) -> tuple[FloatArray, FloatArray, BoolArray]:
        """Speeds (m/s), yaw rates (rad/s), and the robots every sample of which collided."""
        p, n = self.params, len(self.nominal)
        moved = ~(np.hypot(*(inputs.goals - self.goals).T) <= p.goal_reset_m)
        self.nominal[moved] = 0.0
        self.goals = np.array(inputs.goals, dtype=np.float64)
        # one draw for the whole fleet: the same whatever the robots' cut over threads
        noise = self.rng.standard_normal((n, noise_knots(p), 2, p.samples))
        result = mppi_batch(
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
            self.nominal,
            noise,
            p,
            inputs.slices,
        )
        return result.v, result.w, result.blocked
