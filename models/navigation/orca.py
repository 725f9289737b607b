"""Optimal Reciprocal Collision Avoidance for a whole fleet of differential-drive robots.

The method is van den Berg, Guy, Lin and Manocha, "Reciprocal n-Body Collision Avoidance",
Robotics Research (ISRR 2009), Springer Tracts in Advanced Robotics 70, 2011: each robot
picks the velocity nearest its preferred one inside a set of half-planes, one per thing
nearby, found by a 2-D linear program; when the half-planes leave nothing, a 3-D linear
program picks the velocity that violates the worst of them least. Per robot and call
(positions and velocities in ``map``):

- **Preferred velocity.** Towards the carrot at ``v_max``, lowered to ``arrive_gain_per_s
  * d_goal`` so robots slow onto their final goal.
- **Other robots** (``neighbours``: heard position, velocity and age). Each position is
  first moved on by its velocity times its age (``x + vx * age_s``, with ``extrapolate``):
  what was heard ``age_s`` ago over the network is where the robot was then, so latency
  shifts the constraint unless it is extrapolated. With ``p`` the relative position,
  ``v`` the relative velocity (own measured velocity along the heading minus the heard
  one) and ``R`` both radii plus both margins, the velocity obstacle for the horizon
  ``tau`` is the cone of ``p`` truncated by the disc ``p / tau``, ``R / tau``; ``u`` is
  the smallest change of ``v`` that leaves it, ``n`` its outward normal, and the robot
  takes half: the half-plane ``(x - (v_own + u / 2)) . n >= 0`` (the paper's ORCA). Robots
  already within ``R`` resolve the overlap within one control period instead of ``tau``.
- **Lidar hits** are static discs of radius 0 that take no share: the robot takes all of
  ``u`` (``obstacle_horizon_s``, ``R`` = own radius plus margin; the paper's static
  obstacles are line segments, here every hit is a point). The hits are cut to the
  nearest per angular sector (``obstacle_sectors``) within ``R + v_max *
  obstacle_horizon_s``, at most that many constraints; a hit within a heard robot's
  radius plus ``hit_tolerance_m`` of where it is extrapolated to is that robot, avoided
  reciprocally instead. A hit already within ``R`` forbids only moving towards it (the
  half-plane through the origin). Standing still keeps every hit's half-plane, so they
  stay hard in the 3-D program.
- **Keep right.** When a robot's half-plane excludes the preferred velocity, that is
  turned ``keep_right_rad`` clockwise first: in an exactly head-on encounter ORCA only
  slows both robots (the nearest way out of the truncated cone is straight back), and
  this deterministic nudge, standing in for the random perturbation ORCA's users add,
  makes both pass on the right. Three or more robots meeting exactly symmetrically still
  stall apart, reported blocked (the navigation's recovery then breaks the tie).
- **Linear programs.** The 2-D program adds the constraints one at a time, moving the
  velocity onto the first violated line within the speed disc ``|x| <= v_max``; the 3-D
  fallback, from the first line the 2-D program could not meet, minimizes the largest
  violation of the robots' lines keeping the hits' lines.
- **Differential drive.** The chosen holonomic velocity ``x`` is tracked by turning
  towards it, ``w = heading_gain * err`` clipped to the yaw-rate limit, and driving
  ``v = |x| cos(err)`` when ``|err| < pi / 2``, else turning on the spot (never
  backwards); ``v`` is then lowered until the velocity the robot really drives (``v``
  along its heading) also keeps every half-plane that standing still keeps, within
  ``slack_mps``. The tracking error left is covered by ``margin_m`` added to every
  radius: the effective radius of Alonso-Mora, Breitenmoser, Rufli, Beardsley and
  Siegwart, "Optimal Reciprocal Collision Avoidance for Multiple Non-Holonomic Robots",
  DARS 2010 (they bound the error of a tracking controller; here the margin is set).
- **Blocked** when the robot wants to move (preferred speed above ``stop_mps``) but the
  programs leave it a velocity below ``stop_mps``.

Each robot's command depends only on its own inputs, whatever the batch.
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
from models.geometry.angles import wrap_angle
from models.navigation.fleet_inputs import (
    check_limits,
    decide_sliced,
    fleet_rows,
    offsets,
    packed,
    points,
)
from models.navigation.orca_lp import det as _det
from models.navigation.orca_lp import half_plane as _half_plane
from models.navigation.orca_lp import lp2 as _lp2
from models.navigation.orca_lp import lp3 as _lp3
from models.slicing import Slices, whole


@dataclass(frozen=True)
class OrcaParams:
    """Parameters of :func:`orca_batch` (see the module docstring).

    Attributes:
        time_horizon_s: horizon of the other robots' velocity obstacles (s).
        obstacle_horizon_s: horizon of the lidar hits' velocity obstacles (s).
        margin_m: added to every footprint radius (m): clearance and tracking error.
        obstacle_sectors: angular sectors the nearby hits are cut to, the nearest each.
        heading_gain: yaw rate per radian of heading error (1/s).
        arrive_gain_per_s: preferred speed per metre to the final goal (1/s).
        keep_right_rad: clockwise turn of the preferred velocity when a robot is in its way (rad).
        extrapolate: move each heard robot on by its velocity times the age of the news.
        control_period_s: the control period (s): overlaps resolve within it.
        hit_tolerance_m: a hit within a heard robot's radius plus this is that robot (m).
        slack_mps: how far the driven velocity may stray beyond a half-plane (m/s).
        stop_mps: slower than this counts as standing (m/s).
    """

    time_horizon_s: float = 2.0
    obstacle_horizon_s: float = 1.0
    margin_m: float = 0.15
    obstacle_sectors: int = 32
    heading_gain: float = 2.0
    arrive_gain_per_s: float = 1.0
    keep_right_rad: float = 0.1
    extrapolate: bool = True
    control_period_s: float = 0.1
    hit_tolerance_m: float = 0.15
    slack_mps: float = 0.05
    stop_mps: float = 0.02

    def __post_init__(self) -> None:
        positive = ("time_horizon_s", "obstacle_horizon_s", "heading_gain", "control_period_s")
        for f in fields(self):
            value, key = getattr(self, f.name), f"orca.{f.name}"
            if f.name == "obstacle_sectors":
                if not (isinstance(value, int) and value >= 1):
                    raise ModelError(key, value, "an integer >= 1")
            elif f.name == "extrapolate":
                if not isinstance(value, bool):
                    raise ModelError(key, value, "true or false")
            elif f.name in positive:
                if not (math.isfinite(value) and value > 0):
                    raise ModelError(key, value, "a finite number > 0")
            elif not (math.isfinite(value) and value >= 0):
                raise ModelError(key, value, "a finite number >= 0")


class OrcaResult(NamedTuple):
    """Commands of :func:`orca_batch`, arrays indexed by robot.

    Attributes:
        v: forward speed commands (m/s, ``base_link``), never backwards.
        w: yaw-rate commands (rad/s, counter-clockwise).
        blocked: the robot wants to move but the constraints leave it standing.
        velocity: (n, 2) the holonomic velocity chosen by the linear programs (m/s, ``map``).
    """

    v: FloatArray
    w: FloatArray
    blocked: BoolArray
    velocity: FloatArray


# packed configuration: the fields of OrcaParams in order, then those of DriveLimits
_TAU, _TAU_OBST, _MARGIN, _SECTORS, _K_HEAD, _ARRIVE, _BIAS, _EXTRAP, _DT = range(9)
_HIT_TOL, _SLACK, _STOP, _V_MAX, _REVERSE, _W_MAX = range(9, 15)


_wrap: Any = numba.njit(cache=True, nogil=True, inline="always")(wrap_angle)


def _orca_py(
    state: FloatArray,
    hits: FloatArray,
    hit_start: IntArray,
    others: FloatArray,
    other_start: IntArray,
    cfg: FloatArray,
    out: FloatArray,
) -> None:
    """All robots' commands into ``out`` (n, 5), rows ``v w blocked ux uy``.

    ``state`` rows are ``x y yaw v w radius carrot_xy goal_xy``, ``others`` rows
    ``x y vx vy age radius``.
    """
    tau, tau_obst, margin, dt = cfg[_TAU], cfg[_TAU_OBST], cfg[_MARGIN], cfg[_DT]
    sectors, v_max, w_max = int(cfg[_SECTORS]), cfg[_V_MAX], cfg[_W_MAX]
    slack, stop, tol = cfg[_SLACK], cfg[_STOP], cfg[_HIT_TOL]
    n = state.shape[0]
    most = 0
    for i in range(n):
        most = max(most, other_start[i + 1] - other_start[i])
    lines, proj = np.empty((sectors + most, 4)), np.empty((sectors + most, 4))
    near = np.empty((most, 5))  # x y vx vy radius of the robots in range, extrapolated
    best_d2, best = np.empty(sectors), np.empty(sectors, dtype=np.int64)
    res = np.empty(2)
    for i in range(n):
        x, y, yaw, v0, rad = state[i, 0], state[i, 1], state[i, 2], state[i, 3], state[i, 5]
        cy, sy = math.cos(yaw), math.sin(yaw)
        vx, vy = v0 * cy, v0 * sy
        own = rad + margin
        # the preferred velocity: to the carrot, slowing onto the goal
        cdx, cdy = state[i, 6] - x, state[i, 7] - y
        dc = math.hypot(cdx, cdy)
        speed = min(v_max, cfg[_ARRIVE] * math.hypot(state[i, 8] - x, state[i, 9] - y))
        pref_x, pref_y = (cdx * speed / dc, cdy * speed / dc) if dc > 0.0 else (0.0, 0.0)
        # the heard robots within reach of a collision over the horizon, moved on by age
        k = 0
        for j in range(other_start[i], other_start[i + 1]):
            age = others[j, 4] if cfg[_EXTRAP] > 0.5 else 0.0
            ox, oy = others[j, 0] + others[j, 2] * age, others[j, 1] + others[j, 3] * age
            gap = math.hypot(ox - x, oy - y) - own - others[j, 5] - margin
            if gap < 2.0 * v_max * tau:
                near[k, 0], near[k, 1] = ox, oy
                near[k, 2], near[k, 3], near[k, 4] = others[j, 2], others[j, 3], others[j, 5]
                k += 1
        # the nearest hit per sector within reach that no heard robot explains
        reach = own + v_max * tau_obst
        best_d2[:] = np.inf
        best[:] = -1
        for h in range(hit_start[i], hit_start[i + 1]):
            hx, hy = hits[h, 0] - x, hits[h, 1] - y
            d2 = hx * hx + hy * hy
            if d2 > reach * reach:
                continue
            explained = False
            for e in range(k):
                if math.hypot(hits[h, 0] - near[e, 0], hits[h, 1] - near[e, 1]) <= (
                    near[e, 4] + tol
                ):
                    explained = True
                    break
            if explained:
                continue
            s = min(int((math.atan2(hy, hx) + math.pi) * sectors / (2.0 * math.pi)), sectors - 1)
            if d2 < best_d2[s]:
                best_d2[s], best[s] = d2, h
        count = 0
        for s in range(sectors):
            if best[s] < 0:
                continue
            hx, hy = hits[best[s], 0] - x, hits[best[s], 1] - y
            if best_d2[s] > own * own:
                ux, uy, dx, dy = _half_plane(hx, hy, vx, vy, own, tau_obst, dt)
                lines[count, 0], lines[count, 1] = vx + ux, vy + uy
            else:  # within the margin already: only never closer
                d = math.sqrt(best_d2[s])
                dx, dy = (-hy / d, hx / d) if d > 0.0 else (1.0, 0.0)
                lines[count, 0], lines[count, 1] = 0.0, 0.0
            lines[count, 2], lines[count, 3] = dx, dy
            count += 1
        fixed = count
        for e in range(k):
            radius = own + near[e, 4] + margin
            ux, uy, dx, dy = _half_plane(
                near[e, 0] - x, near[e, 1] - y, vx - near[e, 2], vy - near[e, 3], radius, tau, dt
            )
            lines[count, 0], lines[count, 1] = vx + 0.5 * ux, vy + 0.5 * uy
            lines[count, 2], lines[count, 3] = dx, dy
            count += 1
        # keep right: turn the preferred velocity a little clockwise when a robot's
        # half-plane excludes it, so that exactly symmetric encounters do not end nose to nose
        for c in range(fixed, count):
            if _det(lines[c, 2], lines[c, 3], lines[c, 0] - pref_x, lines[c, 1] - pref_y) > 0.0:
                cb, sb = math.cos(cfg[_BIAS]), math.sin(cfg[_BIAS])
                pref_x, pref_y = cb * pref_x + sb * pref_y, cb * pref_y - sb * pref_x
                break
        failed = _lp2(lines, count, v_max, pref_x, pref_y, False, res)
        if failed < count:
            _lp3(lines, count, fixed, failed, v_max, res, proj)
        # track it with a differential drive
        speed_u = math.hypot(res[0], res[1])
        if speed_u >= stop:
            err = _wrap(math.atan2(res[1], res[0]) - yaw)
        elif dc > 0.0:
            err = _wrap(math.atan2(cdy, cdx) - yaw)
        else:
            err = 0.0
        w = min(max(cfg[_K_HEAD] * err, -w_max), w_max)
        v = min(speed_u * math.cos(err), v_max) if speed_u >= stop else 0.0
        v = max(v, 0.0)
        for c in range(count):  # driven along the heading: keep what standing still keeps
            a = _det(lines[c, 2], lines[c, 3], lines[c, 0], lines[c, 1])
            b = _det(lines[c, 2], lines[c, 3], cy, sy)
            if a <= 0.0 and b < 0.0:
                v = min(v, (slack - a) / -b)
        out[i, 0], out[i, 1] = v, w
        out[i, 2] = 1.0 if speed >= stop and speed_u < stop else 0.0
        out[i, 3], out[i, 4] = res[0], res[1]


_orca: Any = numba.njit(cache=True, nogil=True)(_orca_py)


def orca_half_plane(
    rel_position: FloatArray,
    rel_velocity: FloatArray,
    radius_m: float,
    horizon_s: float,
    step_s: float,
) -> tuple[FloatArray, FloatArray]:
    """ORCA's smallest velocity change out of a velocity obstacle, and the line's direction.

    Args:
        rel_position: the other's position minus one's own (m, ``map``).
        rel_velocity: one's own velocity minus the other's (m/s, ``map``).
        radius_m: the two radii together (m).
        horizon_s: the velocity obstacle's horizon (s).
        step_s: the time within which an overlap is to be resolved (s).

    Returns:
        ``(u, direction)``: the change ``u`` (m/s) and the unit direction of the line; a
        robot taking a share ``s`` of ``u`` keeps to the left of the line through
        ``v_own + s u`` along ``direction``.
    """
    ux, uy, dx, dy = _half_plane(
        float(rel_position[0]),
        float(rel_position[1]),
        float(rel_velocity[0]),
        float(rel_velocity[1]),
        float(radius_m),
        float(horizon_s),
        float(step_s),
    )
    return np.array([ux, uy]), np.array([dx, dy])


def orca_batch(
    poses: FloatArray,
    velocities: FloatArray,
    limits: DriveLimits,
    radius_m: FloatArray,
    carrots: FloatArray,
    goals: FloatArray,
    hits: FloatArray,
    hit_start: IntArray,
    discs: FloatArray,
    neighbours: FloatArray,
    disc_start: IntArray,
    params: OrcaParams,
    slices: Slices = whole,
) -> OrcaResult:
    """ORCA commands for every robot (see the module docstring).

    Args:
        poses: (n, 3) poses ``x, y, yaw`` in ``map`` (m, m, rad).
        velocities: (n, 2) measured ``v, w`` (m/s, rad/s).
        limits: velocity limits, the same for every robot.
        radius_m: (n,) footprint radii (m).
        carrots: (n, 2) points to head for in ``map`` (m).
        goals: (n, 2) final goals in ``map`` (m); robots slow down onto them.
        hits: (m, 2) lidar hits in ``map`` (m), all robots concatenated.
        hit_start: (n + 1,) CSR offsets: robot ``i`` sees ``hits[hit_start[i]:hit_start[i + 1]]``.
        discs: (d, 3) heard robots ``x, y, r`` in ``map`` (m).
        neighbours: (d, 5) the same robots row for row: ``x, y, vx, vy, age_s`` (m, m/s,
            s) in ``map``.
        disc_start: (n + 1,) CSR offsets into ``discs`` and ``neighbours``.
        params: controller parameters.
        slices: how to cut the robots for threads (:mod:`models.slicing`); each robot's
            command is the same whatever the cut.

    Returns:
        The commands, blocked flags and chosen holonomic velocities, indexed by robot.

    Raises:
        ValueError: an array has the wrong shape, or offsets do not index the rows.
        ModelError: the speed limit is not positive.
    """
    rows = fleet_rows(poses, velocities, radius_m, carrots, goals)
    check_limits(limits)
    n = len(rows)
    pts, dsc, heard = points(hits, 2), points(discs, 3), points(neighbours, 5)
    if len(heard) != len(dsc):
        raise ValueError(f"neighbours must be ({len(dsc)}, 5) like discs, got {heard.shape}")
    others = np.ascontiguousarray(np.column_stack([heard, dsc[:, 2]]))
    pts_start = offsets(hit_start, n, len(pts), "hit_start")
    oth_start = offsets(disc_start, n, len(others), "disc_start")
    cfg = packed(params, limits)
    out = np.zeros((n, 5))

    decide_sliced(_orca, slices, rows, pts, pts_start, others, oth_start, cfg, out)
    return OrcaResult(out[:, 0].copy(), out[:, 1].copy(), out[:, 2] > 0.5, out[:, 3:5].copy())
