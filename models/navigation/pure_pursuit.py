"""Regulated Pure Pursuit local control for a whole fleet in one compiled call.

The method is Macenski, Singh, Martin and Gines, "Regulated Pure Pursuit for Robot Path
Tracking", Autonomous Robots 47, 2023 (Nav2's RPP controller): pure pursuit of a point of
the path a lookahead ahead, its speed regulated so that the robot slows where tracking is
hard or risky. Per robot and call (poses, carrots and obstacles in ``map``, velocities in
``base_link``):

- **Lookahead.** The carrot (the point of the path ``navigation.lookahead_m`` ahead) is
  taken in ``base_link`` as ``(x, y)`` at distance ``L``. With ``lookahead_time_s > 0``
  the lookahead scales with the measured speed: the carrot is pulled in along the robot ->
  carrot line to ``clip(|v0| lookahead_time_s, min_lookahead_m, L)``.
- **Rotate to heading.** When the carrot's bearing exceeds
  ``rotate_to_heading_min_angle_rad`` the robot turns on the spot (``v = 0``) towards it
  at ``rotate_to_heading_speed_radps``, capped at ``sqrt(2 alpha |bearing|)`` (``alpha``
  the yaw acceleration limit) so that it can brake the turn by the time it faces the carrot.
- **Pursuit.** Otherwise the curvature of the arc through the carrot is
  ``kappa = 2 y / L^2`` and the speed ``desired_speed_mps`` is regulated by (1) curvature:
  below ``min_turn_radius_m`` scaled by ``radius / min_turn_radius_m``; (2) proximity:
  when the clearance ``c0`` (distance from the footprint's edge to the nearest lidar hit
  or robot disc) is below ``proximity_clearance_m`` scaled by ``proximity_gain c0 /
  proximity_clearance_m``. The lower of the two holds, but not below
  ``min_regulated_speed_mps``; then (3) within ``approach_distance_m`` of the final goal
  the speed is at most ``desired d / approach_distance_m``, not below
  ``min_approach_speed_mps``. The yaw rate is ``v kappa``; beyond the yaw-rate limit it is
  held at the limit and the speed lowered to stay on the arc.
- **Limits.** Forward speeds only (backing out is the recovery layer's job). The speed lies
  in ``v0 +- a dt`` and ``[0, max_speed]``, the yaw rate in ``w0 +- alpha dt`` and
  ``+-max_yaw_rate`` (``dt`` the control period): the commands are reachable in one period.
- **Collision ahead.** The commanded arc (curvature ``w / v``, ``v`` the larger of the
  command and the measured speed) is projected over ``s = max(min(v collision_time_s, L),
  v dt + v^2 / 2a)``: up to the carrot, yet never short of where the robot could stop. Its
  clearance (the exact distance from every hit and disc to the arc, minus the radius) must
  stay at least ``keep = min(collision_margin_m, c0)`` (a robot already inside the margin
  may move along or away, not closer), less 2 cm for the lidar's range noise but never
  less than ``keep / 2``. Otherwise the robot is **blocked**: it is commanded ``v = 0,
  w = 0`` (it brakes as hard as its limits allow) and reported, and navigation recovers or
  replans. A robot turning on the spot never is: its disc footprint sweeps nothing.

Every robot's command depends only on its own row: the same whatever the batch.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Any, NamedTuple

import numba
import numpy as np

from models.arrays import BoolArray, FloatArray, IntArray
from models.errors import ModelError
from models.fleet.kinematics import DriveLimits
from models.navigation.fleet_inputs import (
    check_limits,
    decide_sliced,
    fleet_rows,
    offsets,
    packed,
    points,
)
from models.slicing import Slices, whole


@dataclass(frozen=True)
class RppParams:
    """Parameters of :func:`rpp_batch` (Nav2's names in brackets).

    Attributes:
        control_period_s: time within which the commands must be reachable (s).
        desired_speed_mps: speed on a straight, clear path, capped by the speed limit
            (m/s) [``desired_linear_vel``].
        lookahead_time_s: lookahead per m/s of measured speed; 0 takes the carrot as it
            is (s) [``lookahead_time``].
        min_lookahead_m: shortest scaled lookahead (m) [``min_lookahead_dist``].
        min_turn_radius_m: arcs tighter than this slow the robot (m)
            [``regulated_linear_scaling_min_radius``].
        min_regulated_speed_mps: curvature and proximity slow the robot no further (m/s)
            [``regulated_linear_scaling_min_speed``].
        proximity_clearance_m: clearance below which the robot slows (m)
            [``cost_scaling_dist``, here beyond the footprint].
        proximity_gain: speed scale per unit of ``clearance / proximity_clearance_m``
            [``cost_scaling_gain``].
        approach_distance_m: distance to the final goal within which the robot slows (m)
            [``approach_velocity_scaling_dist``].
        min_approach_speed_mps: slowest speed onto the goal (m/s)
            [``min_approach_linear_velocity``].
        rotate_to_heading_min_angle_rad: turn on the spot when the carrot is this far off
            the heading (rad) [``rotate_to_heading_min_angle``].
        rotate_to_heading_speed_radps: yaw rate of those turns (rad/s)
            [``rotate_to_heading_angular_vel``].
        collision_time_s: how far ahead the commanded arc is checked (s)
            [``max_allowed_time_to_collision_up_to_carrot``].
        collision_margin_m: clearance beyond the footprint the arc must keep (m)
            [the ``footprint_padding`` of its collision check].
    """

    control_period_s: float = 0.1
    desired_speed_mps: float = 1.0
    lookahead_time_s: float = 1.5
    min_lookahead_m: float = 0.3
    min_turn_radius_m: float = 0.9
    min_regulated_speed_mps: float = 0.25
    proximity_clearance_m: float = 0.3
    proximity_gain: float = 1.0
    approach_distance_m: float = 0.6
    min_approach_speed_mps: float = 0.05
    rotate_to_heading_min_angle_rad: float = 0.785
    rotate_to_heading_speed_radps: float = 1.8
    collision_time_s: float = 1.5
    collision_margin_m: float = 0.05

    def __post_init__(self) -> None:
        may_be_zero = ("lookahead_time_s", "collision_margin_m", "min_regulated_speed_mps")
        for f in fields(self):
            value = getattr(self, f.name)
            key = f"rpp.{f.name}"
            if f.name in may_be_zero:
                if not (math.isfinite(value) and value >= 0):
                    raise ModelError(key, value, "a finite number >= 0")
            elif not (math.isfinite(value) and value > 0):
                raise ModelError(key, value, "a finite number > 0")
        if self.proximity_gain > 1.0:
            raise ModelError("rpp.proximity_gain", self.proximity_gain, "a number <= 1")


class RppResult(NamedTuple):
    """Commands of :func:`rpp_batch`, arrays indexed by robot.

    Attributes:
        v: forward speed commands (m/s, ``base_link``).
        w: yaw-rate commands (rad/s, counter-clockwise).
        blocked: the commanded arc came too close to a lidar hit or a robot disc.
        clearance_m: clearance of the footprint at the present pose (m; inf if nothing
            is near).
    """

    v: FloatArray
    w: FloatArray
    blocked: BoolArray
    clearance_m: FloatArray


# packed configuration: the fields of RppParams in order, then those of DriveLimits
_DT, _V_DES, _LA_TIME, _LA_MIN, _R_MIN, _V_REG_MIN, _PROX, _PROX_GAIN = range(8)
_APPROACH, _V_APPROACH, _ROT_ANGLE, _ROT_SPEED, _T_COLL, _MARGIN = range(8, 14)
_V_MAX, _REVERSE, _W_MAX, _ACC, _YAW_ACC = range(14, 19)
_TWO_PI = 2.0 * math.pi
_SLACK_M = 0.02
"""What the arc's clearance may fall short of the one it must keep (m): two standard
deviations of the lidar's default range noise, so that a robot driving along a wall at the
margin is not stopped by the noise of its hits."""


def _arc_distance_py(px: float, py: float, k: float, s: float) -> float:
    """Distance (m) from ``(px, py)`` to the arc leaving the origin along +x.

    The arc (``base_link``) has curvature ``k`` (1/m, positive to the left) and length
    ``s`` (m); an arc whose sagitta is below a micrometre is taken as its chord.
    """
    if abs(k) * s * s < 8e-6:
        t = min(max(px, 0.0), s)
        return math.hypot(px - t, py)
    if k < 0.0:
        py, k = -py, -k
    r = 1.0 / k
    sweep = k * s
    # the point's angle round the centre (0, r), counted from the start (at -pi/2)
    around = math.atan2(py - r, px) + 0.5 * math.pi
    if around < 0.0:
        around += _TWO_PI
    if sweep >= _TWO_PI or around <= sweep:
        return abs(math.hypot(px, py - r) - r)
    ex, ey = r * math.sin(sweep), r - r * math.cos(sweep)
    return min(math.hypot(px, py), math.hypot(px - ex, py - ey))


_arc_distance: Any = numba.njit(cache=True, nogil=True)(_arc_distance_py)


def _rpp_py(
    state: FloatArray,
    obstacles: FloatArray,
    obstacle_start: IntArray,
    discs: FloatArray,
    disc_start: IntArray,
    cfg: FloatArray,
    out: FloatArray,
) -> None:
    """All robots; ``state`` rows ``x y yaw v w radius carrot_xy goal_xy``; ``out`` (n, 4)."""
    dt, acc, yaw_acc = cfg[_DT], cfg[_ACC], cfg[_YAW_ACC]
    v_max, w_max = cfg[_V_MAX], cfg[_W_MAX]
    v_des = min(cfg[_V_DES], v_max)
    margin = cfg[_MARGIN]
    for i in range(state.shape[0]):
        x, y, yaw, v0, w0, rad = (
            state[i, 0],
            state[i, 1],
            state[i, 2],
            state[i, 3],
            state[i, 4],
            state[i, 5],
        )
        cy, sy = math.cos(yaw), math.sin(yaw)
        # the clearance at the present pose: nearest hit or disc edge, minus the radius
        near2 = np.inf
        for j in range(obstacle_start[i], obstacle_start[i + 1]):
            ddx, ddy = obstacles[j, 0] - x, obstacles[j, 1] - y
            near2 = min(near2, ddx * ddx + ddy * ddy)
        c0 = math.sqrt(near2) - rad
        for j in range(disc_start[i], disc_start[i + 1]):
            gap = math.hypot(discs[j, 0] - x, discs[j, 1] - y) - discs[j, 2]
            c0 = min(c0, gap - rad)
        # the carrot in base_link, pulled in to the speed-scaled lookahead
        cdx, cdy = state[i, 6] - x, state[i, 7] - y
        lx, ly = cy * cdx + sy * cdy, cy * cdy - sy * cdx
        reach = math.hypot(lx, ly)
        look = reach
        if cfg[_LA_TIME] > 0.0:
            look = min(max(abs(v0) * cfg[_LA_TIME], cfg[_LA_MIN]), reach)
            if 0.0 < look < reach:
                lx, ly = lx * look / reach, ly * look / reach
        v_lo = min(max(v0 - acc * dt, 0.0), v_max)
        v_hi = min(max(v0 + acc * dt, 0.0), v_max)
        w_lo = min(max(w0 - yaw_acc * dt, -w_max), w_max)
        w_hi = min(max(w0 + yaw_acc * dt, -w_max), w_max)
        bearing = math.atan2(ly, lx)
        v_cmd, w_cmd = 0.0, 0.0
        if look <= 1e-9:
            pass  # no carrot (no path): stand still
        elif abs(bearing) > cfg[_ROT_ANGLE]:
            turn = min(cfg[_ROT_SPEED], math.sqrt(2.0 * yaw_acc * abs(bearing)))
            w_cmd = math.copysign(turn, bearing)
        else:
            kappa = 2.0 * ly / (look * look)
            v_curve = v_des
            if abs(kappa) * cfg[_R_MIN] > 1.0:
                v_curve = v_des / (abs(kappa) * cfg[_R_MIN])
            v_prox = v_des
            if c0 < cfg[_PROX]:
                v_prox = v_des * cfg[_PROX_GAIN] * max(c0, 0.0) / cfg[_PROX]
            v_cmd = max(min(v_curve, v_prox), min(cfg[_V_REG_MIN], v_des))
            d_goal = math.hypot(state[i, 8] - x, state[i, 9] - y)
            if d_goal < cfg[_APPROACH]:
                v_near = max(v_des * d_goal / cfg[_APPROACH], cfg[_V_APPROACH])
                v_cmd = min(v_cmd, v_near)
            v_cmd = min(max(v_cmd, v_lo), v_hi)
            w_cmd = v_cmd * kappa
            if abs(w_cmd) > w_max:
                w_cmd = math.copysign(w_max, w_cmd)
                v_cmd = max(w_max / abs(kappa), v_lo)
        v_cmd = min(max(v_cmd, v_lo), v_hi)
        w_cmd = min(max(w_cmd, w_lo), w_hi)
        # the arc ahead: as far as the carrot, and at least as far as the robot may go
        v_run = max(v_cmd, v0)
        blocked = False
        if v_run > 0.0:
            span = max(min(v_run * cfg[_T_COLL], reach), v_run * dt + v_run * v_run / (2.0 * acc))
            k = w_cmd / v_run
            keep = min(margin, c0)
            need = max(keep - _SLACK_M, 0.5 * keep)
            far = span + rad + need
            blocked = c0 <= 0.0
            for j in range(obstacle_start[i], obstacle_start[i + 1]):
                if blocked:
                    break
                ddx, ddy = obstacles[j, 0] - x, obstacles[j, 1] - y
                if ddx * ddx + ddy * ddy > far * far:
                    continue
                bx, by = cy * ddx + sy * ddy, cy * ddy - sy * ddx
                blocked = _arc_distance(bx, by, k, span) - rad < need
            for j in range(disc_start[i], disc_start[i + 1]):
                if blocked:
                    break
                ddx, ddy = discs[j, 0] - x, discs[j, 1] - y
                bx, by = cy * ddx + sy * ddy, cy * ddy - sy * ddx
                blocked = _arc_distance(bx, by, k, span) - discs[j, 2] - rad < need
        if blocked:
            v_cmd, w_cmd = 0.0, 0.0
        out[i, 0], out[i, 1] = v_cmd, w_cmd
        out[i, 2] = 1.0 if blocked else 0.0
        out[i, 3] = c0


_rpp: Any = numba.njit(cache=True, nogil=True)(_rpp_py)


def rpp_batch(
    poses: FloatArray,
    velocities: FloatArray,
    limits: DriveLimits,
    radius_m: FloatArray,
    carrots: FloatArray,
    goals: FloatArray,
    obstacles: FloatArray,
    obstacle_start: IntArray,
    discs: FloatArray,
    disc_start: IntArray,
    params: RppParams,
    slices: Slices = whole,
) -> RppResult:
    """Regulated Pure Pursuit commands for every robot (see the module docstring).

    Args:
        poses: (n, 3) poses ``x, y, yaw`` in ``map`` (m, m, rad).
        velocities: (n, 2) measured ``v, w`` (m/s, rad/s).
        limits: velocity and acceleration limits, the same for every robot.
        radius_m: (n,) footprint radii (m).
        carrots: (n, 2) points of the paths a lookahead ahead, in ``map`` (m).
        goals: (n, 2) final goals in ``map`` (m); robots slow down onto them.
        obstacles: (m, 2) lidar hits in ``map`` (m), all robots concatenated.
        obstacle_start: (n + 1,) offsets: robot ``i`` sees
            ``obstacles[obstacle_start[i]:obstacle_start[i + 1]]``.
        discs: (d, 3) other robots' discs ``x, y, r`` in ``map`` (m).
        disc_start: (n + 1,) offsets into ``discs``, as ``obstacle_start``.
        params: controller parameters.
        slices: how to cut the robots for threads (:mod:`models.slicing`); each robot's
            command is the same whatever the cut.

    Returns:
        The commands, blocked flags and present clearances, indexed by robot.

    Raises:
        ValueError: an array has the wrong shape, or offsets do not index the points.
        ModelError: a speed or acceleration limit is not positive.
    """
    rows = fleet_rows(poses, velocities, radius_m, carrots, goals)
    check_limits(limits, "max_accel_mps2", "max_yaw_accel_radps2")
    n = len(rows)
    pts, dsc = points(obstacles, 2), points(discs, 3)
    pts_start = offsets(obstacle_start, n, len(pts), "obstacle_start")
    dsc_start = offsets(disc_start, n, len(dsc), "disc_start")
    cfg = packed(params, limits)
    out = np.zeros((n, 4))

    decide_sliced(_rpp, slices, rows, pts, pts_start, dsc, dsc_start, cfg, out)
    return RppResult(out[:, 0].copy(), out[:, 1].copy(), out[:, 2] > 0.5, out[:, 3].copy())
