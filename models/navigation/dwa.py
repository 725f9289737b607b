"""Dynamic Window Approach local control for a whole fleet in one compiled call.

The method is Fox, Burgard and Thrun, "The Dynamic Window Approach to Collision
Avoidance", IEEE Robotics & Automation Magazine 4(1), 1997: search the velocities
reachable within one control period, keep those along which the robot can still stop
before hitting anything, and pick the best by a weighted sum of objectives. Per robot
and call (poses and points in ``map``, velocities in ``base_link``):

- **Window.** ``v`` in ``v0 +- a dt``, ``w`` in ``w0 +- alpha dt`` (``dt`` the control
  period, ``a``/``alpha`` the acceleration limits), clipped to ``[0, max_speed]`` and
  ``+-max_yaw_rate``. Forward speeds only, as Nav2's DWB by default: a scan says little
  about what is behind, and backing out is the recovery layer's job. The top of the
  ``v`` range is lowered (never below its bottom) to ``arrive_gain_per_s * d_goal`` so
  that robots slow exponentially onto their final goal without overshoot (the caller
  decides arrival), and to ``max_speed * cos(bearing of the carrot)`` so that a robot
  facing away from its carrot turns on the spot instead of driving a wide loop.
  ``v_samples x w_samples`` samples span the window; the ``w`` nearest 0 snaps to 0.
- **Trajectories.** Each ``(v, w)`` is held for ``sim_time_s`` and evaluated at
  ``sim_steps`` points on the exact arc of :func:`models.fleet.kinematics.integrate` (chord
  ``v t sinc(w t / 2)`` along the mid heading). A point's clearance is its distance to
  the nearest obstacle point or disc edge minus the footprint radius; a trajectory's
  clearance is the minimum over its points.
- **Admissible.** ``c0`` is the clearance at the current pose; nothing is admissible
  when ``c0 <= 0``. ``v = 0`` turns the disc footprint on the spot: admissible. ``v > 0``
  needs (1) a clearance ``>= min(safety_margin_m, c0)`` at every point (a robot already
  inside the margin may move along or away, never closer) and (2) ``v <= sqrt(2 a f
  d_free)``, ``d_free`` the free travel before the clearance drops below that, ``f =
  0.5`` with ``moving_obstacles`` (the other robot may close the gap as fast as we do),
  else 1. Under (1) ``d_free`` is the whole arc ``v T``, so (2) is the cap ``v <= 2 a f
  T``: it makes sure that, should no sample be admissible at the next call, both robots
  of a head-on encounter stop within the stretch this call found free.
- **Score.** ``w_heading (1 - |e| / pi) + w_progress (d0 - d1) / (v_max T) +
  w_clearance min(c, cap) / cap + w_speed v / v_max``; ``e`` the angle between the final
  heading and the direction from the final point to the carrot, ``d0``/``d1`` the
  distances from the start/final point to the carrot, ``c`` the trajectory clearance.
  A carrot nearer than ``2 v_max T`` is first pushed out to that distance along its
  bearing, as one within the horizon would reward stopping short of it. ``w_clearance``
  fades linearly over the last ``v_max T`` metres to the goal, or a goal near a shelf
  would be out of reach. Ties go to the first sample in the order ``v``, then ``w``,
  ascending.
- **Blocked** when the window allowed ``v > 0`` but no ``v > 0`` sample is admissible
  (a robot turning to face its carrot does not want to drive, so is not blocked).
  The best admissible ``v = 0`` sample (a turn on the spot, or a stop) is commanded; if
  there is none (too fast to stop within one period, or overlapping) the robot brakes
  as hard as it may along its current arc: ``v = v_lo``, ``w = w0 v_lo / v0`` clipped.

Commands always lie in the window. Points farther than ``v_hi T + radius +
max(clearance_cap_m, safety_margin_m)`` cannot change any (capped) clearance and are
dropped first. Obstacles are taken as static over the horizon: robots crossing each
other's paths are seen only as they come near, so crossings at speed can end in contact.

The default weights were tuned in closed loop (see the tests): a small heading weight
and a strong clearance term capped at 0.4 m (below the 0.47 m a robot has in the middle
of a 1.6 m aisle, so aisles cost nothing) make robots veer early enough to pass each
other head-on in corridors of 2.4 m and more, and still drive aisles at full speed.
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
class DwaParams:
    """Parameters of :func:`dwa_batch`.

    Attributes:
        sim_time_s: horizon of the forward simulation (s).
        sim_steps: points evaluated along each trajectory.
        v_samples: samples of forward speed in the window.
        w_samples: samples of yaw rate in the window.
        control_period_s: time within which the window is reachable (s).
        safety_margin_m: clearance kept beyond the footprint (m).
        w_heading: weight of the alignment of the final heading with the carrot.
        w_progress: weight of the reduction of the distance to the carrot.
        w_clearance: weight of the trajectory clearance, normalized by the cap; fades
            out over the last ``v_max * sim_time_s`` metres to the goal.
        w_speed: weight of the forward speed, normalized by the speed limit.
        clearance_cap_m: clearance beyond which more clearance earns nothing (m).
        arrive_gain_per_s: speed limit per metre of distance to the final goal (1/s).
        moving_obstacles: obstacles may be robots approaching as fast as we drive:
            halve the free distance in the braking condition.
    """

    sim_time_s: float = 1.5
    sim_steps: int = 10
    v_samples: int = 6
    w_samples: int = 15
    control_period_s: float = 0.1
    safety_margin_m: float = 0.1
    w_heading: float = 0.2
    w_progress: float = 1.0
    w_clearance: float = 1.5
    w_speed: float = 0.3
    clearance_cap_m: float = 0.4
    arrive_gain_per_s: float = 1.0
    moving_obstacles: bool = True

    def __post_init__(self) -> None:
        positive = ("sim_time_s", "control_period_s", "clearance_cap_m", "arrive_gain_per_s")
        for f in fields(self):
            value = getattr(self, f.name)
            key = f"navigation.{f.name}"
            if f.name in ("sim_steps", "v_samples", "w_samples"):
                if not (isinstance(value, int) and value >= 1):
                    raise ModelError(key, value, "an integer >= 1")
            elif f.name in positive:
                if not (math.isfinite(value) and value > 0):
                    raise ModelError(key, value, "a finite number > 0")
            elif f.name != "moving_obstacles" and not (math.isfinite(value) and value >= 0):
                raise ModelError(key, value, "a finite number >= 0")


class DwaResult(NamedTuple):
    """Commands of :func:`dwa_batch`, arrays indexed by robot.

    Attributes:
        v: forward speed commands (m/s, ``base_link``).
        w: yaw-rate commands (rad/s, counter-clockwise).
        blocked: the window allowed driving but no sample with ``v > 0`` was admissible.
        best_clearance_m: clearance of the chosen trajectory (m), saturated at
            ``clearance_cap_m``; the clearance at the current pose when braking.
    """

    v: FloatArray
    w: FloatArray
    blocked: BoolArray
    best_clearance_m: FloatArray


# packed configuration: the fields of DwaParams in order, then those of DriveLimits
_T, _STEPS, _NV, _NW, _DT, _MARGIN, _K_HEAD, _K_PROG, _K_CLEAR, _K_SPEED = range(10)
_CAP, _ARRIVE, _MOVING, _V_MAX, _REVERSE, _W_MAX, _ACC, _YAW_ACC = range(10, 18)


def _samples_py(lo: float, hi: float, count: int, out: FloatArray, snap: bool) -> int:
    """Fill ``out`` with ``count`` even samples of ``[lo, hi]`` (one if it is a point)."""
    used = count if hi > lo else 1
    nearest = 0
    for b in range(used):
        out[b] = lo if used == 1 else lo + (hi - lo) * b / (used - 1)
        if abs(out[b]) < abs(out[nearest]):
            nearest = b
    if snap and lo <= 0.0 <= hi:
        out[nearest] = 0.0
    return used


_samples: Any = numba.njit(cache=True, nogil=True)(_samples_py)


def _dwa_py(
    state: FloatArray,
    obstacles: FloatArray,
    obstacle_start: IntArray,
    discs: FloatArray,
    disc_start: IntArray,
    cfg: FloatArray,
    out: FloatArray,
) -> None:
    """All robots; ``state`` rows ``x y yaw v w radius carrot_xy goal_xy``; ``out`` (n, 4)."""
    horizon, dt, margin, cap = cfg[_T], cfg[_DT], cfg[_MARGIN], cfg[_CAP]
    steps, v_count, w_count = int(cfg[_STEPS]), int(cfg[_NV]), int(cfg[_NW])
    v_max, w_max = cfg[_V_MAX], cfg[_W_MAX]
    brake_cap = 2.0 * cfg[_ACC] * (0.5 if cfg[_MOVING] else 1.0) * horizon
    inf = np.inf
    n = state.shape[0]
    most_pts, most_discs = 0, 0
    for i in range(n):
        most_pts = max(most_pts, obstacle_start[i + 1] - obstacle_start[i])
        most_discs = max(most_discs, disc_start[i + 1] - disc_start[i])
    ox2, oy2, oo = np.empty(most_pts), np.empty(most_pts), np.empty(most_pts)
    first = np.empty(most_pts, dtype=np.int64)
    disc = np.empty((most_discs, 3))
    vs, ws = np.empty(v_count), np.empty(w_count)
    ux, uy, turn = np.empty((w_count, steps)), np.empty((w_count, steps)), np.empty((w_count, 2))
    # trajectory points of the moving samples, flattened as (step, v, w)
    size = steps * v_count * w_count
    px, py, uu = np.empty(size), np.empty(size), np.empty(size)
    acc, near = np.empty(size), np.empty(size)
    clear = np.empty((v_count, w_count))
    for i in range(n):
        x, y, yaw, v0, w0, rad = (
            state[i, 0],
            state[i, 1],
            state[i, 2],
            state[i, 3],
            state[i, 4],
            state[i, 5],
        )
        cy, sy = math.cos(yaw), math.sin(yaw)
        cdx, cdy = state[i, 6] - x, state[i, 7] - y
        crx, cry = cy * cdx + sy * cdy, cy * cdy - sy * cdx  # the carrot in base_link
        d0 = math.hypot(crx, cry)
        # the window, its top lowered by the goal, braking and facing caps
        v_lo = min(max(v0 - cfg[_ACC] * dt, 0.0), v_max)
        v_hi = min(max(v0 + cfg[_ACC] * dt, 0.0), v_max)
        w_lo = min(max(w0 - cfg[_YAW_ACC] * dt, -w_max), w_max)
        w_hi = min(max(w0 + cfg[_YAW_ACC] * dt, -w_max), w_max)
        d_goal = math.hypot(state[i, 8] - x, state[i, 9] - y)
        facing = crx / d0 if d0 > 0.0 else 1.0
        v_hi = max(v_lo, min(v_hi, cfg[_ARRIVE] * d_goal, brake_cap, v_max * max(facing, 0.0)))
        nv = _samples(v_lo, v_hi, v_count, vs, False)
        nw = _samples(w_lo, w_hi, w_count, ws, True)
        still = 1 if vs[0] == 0.0 else 0  # samples ascend: only vs[0] may be 0
        span = (nv - still) * nw
        total = steps * span
        # obstacles near enough to matter, in base_link (doubled); a point farther than
        # the reach of step k plus the radius and the cap cannot matter before step k
        keep = rad + max(cap, margin)
        reach = v_hi * horizon + keep
        m, oo_min = 0, inf
        for j in range(obstacle_start[i], obstacle_start[i + 1]):
            ddx, ddy = obstacles[j, 0] - x, obstacles[j, 1] - y
            d2 = ddx * ddx + ddy * ddy
            if d2 <= reach * reach:
                ox2[m], oy2[m], oo[m] = 2.0 * (cy * ddx + sy * ddy), 2.0 * (cy * ddy - sy * ddx), d2
                late = (math.sqrt(d2) - keep) * steps / max(v_hi * horizon, 1e-12)
                first[m] = span * min(max(math.ceil(late) - 1, 0), steps - 1)
                oo_min = min(oo_min, d2)
                m += 1
        nd, c0 = 0, math.sqrt(oo_min) - rad
        for j in range(disc_start[i], disc_start[i + 1]):
            ddx, ddy = discs[j, 0] - x, discs[j, 1] - y
            gap = math.sqrt(ddx * ddx + ddy * ddy) - discs[j, 2]
            if gap <= reach:
                disc[nd, 0], disc[nd, 1] = cy * ddx + sy * ddy, cy * ddy - sy * ddx
                disc[nd, 2] = discs[j, 2]
                c0 = min(c0, gap - rad)
                nd += 1
        # exact arcs: at a given w and t the point is v times a fixed vector; the half
        # angles grow by a fixed step, so rotate instead of calling sin and cos
        for b in range(nw):
            h1 = 0.5 * ws[b] * horizon / steps
            c1, s1 = math.cos(h1), math.sin(h1)
            ck, sk = c1, s1
            for k in range(steps):
                t = horizon * (k + 1) / steps
                length = t if h1 == 0.0 else sk / (h1 * (k + 1)) * t
                ux[b, k], uy[b, k] = length * ck, length * sk
                turn[b, 0], turn[b, 1] = ck * ck - sk * sk, 2.0 * sk * ck  # twice the half
                ck, sk = ck * c1 - sk * s1, sk * c1 + ck * s1
        for k in range(steps):
            for a in range(still, nv):
                for b in range(nw):
                    q = k * span + (a - still) * nw + b
                    px[q], py[q] = vs[a] * ux[b, k], vs[a] * uy[b, k]
                    uu[q] = px[q] * px[q] + py[q] * py[q]
                    acc[q], near[q] = inf, inf
        # |o - p|^2 = |o|^2 - 2 o.p + |p|^2: per point and sample two multiply-adds and
        # a min, vectorized over the samples; views from index 0 let the compiler prove
        # the index >= 0 and drop the wraparound checks that would stop vectorization
        for j in range(m):
            oxj, oyj, ooj = ox2[j], oy2[j], oo[j]
            tail, tx, ty = acc[first[j] : total], px[first[j] : total], py[first[j] : total]
            for q in range(tail.size):
                tail[q] = min(tail[q], ooj - oxj * tx[q] - oyj * ty[q])
        for e in range(nd):
            ex, ey, er = disc[e, 0], disc[e, 1], disc[e, 2]
            for q in range(total):
                gx, gy = ex - px[q], ey - py[q]
                near[q] = min(near[q], math.sqrt(gx * gx + gy * gy) - er)
        for q in range(total):
            acc[q] = min(math.sqrt(max(acc[q] + uu[q], 0.0)), near[q]) - rad
        for a in range(nv):
            for b in range(nw):
                clear[a, b] = c0 if a < still else inf
                for k in range(steps if a >= still else 0):
                    clear[a, b] = min(clear[a, b], acc[k * span + (a - still) * nw + b])
        # score the admissible samples against the carrot, pushed out to the reach
        far = 2.0 * v_max * horizon
        if 0.0 < d0 < far:
            crx, cry, d0 = crx * far / d0, cry * far / d0, far
        thr = min(margin, c0)
        k_clear = cfg[_K_CLEAR] * min(1.0, d_goal / (v_max * horizon)) / cap
        best_score, best_a, best_b, moving = -inf, -1, -1, False
        for a in range(nv):
            va = vs[a]
            for b in range(nw):
                if c0 <= 0.0 or (va > 0.0 and (clear[a, b] < thr or va > brake_cap)):
                    continue
                moving = moving or va > 0.0
                ex, ey = crx - va * ux[b, steps - 1], cry - va * uy[b, steps - 1]
                along, across = turn[b, 0] * ex + turn[b, 1] * ey, turn[b, 0] * ey - turn[b, 1] * ex
                score = (
                    cfg[_K_HEAD] * (1.0 - abs(math.atan2(across, along)) / math.pi)
                    + cfg[_K_PROG] * (d0 - math.sqrt(ex * ex + ey * ey)) / (v_max * horizon)
                    + k_clear * min(clear[a, b], cap)
                    + cfg[_K_SPEED] * va / v_max
                )
                if score > best_score:
                    best_score, best_a, best_b = score, a, b
        out[i, 2] = 1.0 if v_hi > 0.0 and not moving else 0.0
        if best_a >= 0:
            out[i, 0], out[i, 1] = vs[best_a], ws[best_b]
            out[i, 3] = min(clear[best_a, best_b], cap)
        else:
            w_brake = w0 * v_lo / v0 if v0 > 0.0 else 0.0
            out[i, 0], out[i, 1] = v_lo, min(max(w_brake, w_lo), w_hi)
            out[i, 3] = min(c0, cap)


_dwa: Any = numba.njit(cache=True, nogil=True)(_dwa_py)


def dwa_batch(
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
    params: DwaParams,
    slices: Slices = whole,
) -> DwaResult:
    """Dynamic Window Approach commands for every robot (see the module docstring).

    Args:
        poses: (n, 3) poses ``x, y, yaw`` in ``map`` (m, m, rad).
        velocities: (n, 2) current ``v, w`` (m/s, rad/s).
        limits: velocity and acceleration limits, the same for every robot.
        radius_m: (n,) footprint radii (m).
        carrots: (n, 2) local goals in ``map`` (m): a point ahead on each global path.
        goals: (n, 2) final goals in ``map`` (m); robots slow down onto them.
        obstacles: (m, 2) obstacle points in ``map`` (m), all robots concatenated.
        obstacle_start: (n + 1,) CSR offsets: robot ``i`` sees
            ``obstacles[obstacle_start[i]:obstacle_start[i + 1]]``.
        discs: (d, 3) obstacle discs ``x, y, r`` in ``map`` (m), e.g. other robots.
        disc_start: (n + 1,) CSR offsets into ``discs``, as ``obstacle_start``.
        params: controller parameters.
        slices: how to cut the robots for threads (:mod:`models.slicing`); each robot's
            command is the same whatever the cut.

    Returns:
        The commands, blocked flags and clearances, indexed by robot.

    Raises:
        ValueError: an array has the wrong shape, or offsets do not index the points.
        ModelError: the speed limit is not positive.
    """
    rows = fleet_rows(poses, velocities, radius_m, carrots, goals)
    check_limits(limits)
    n = len(rows)
    pts, dsc = points(obstacles, 2), points(discs, 3)
    pts_start = offsets(obstacle_start, n, len(pts), "obstacle_start")
    dsc_start = offsets(disc_start, n, len(dsc), "disc_start")
    cfg = packed(params, limits)
    out = np.zeros((n, 4))

    decide_sliced(_dwa, slices, rows, pts, pts_start, dsc, dsc_start, cfg, out)
    return DwaResult(out[:, 0].copy(), out[:, 1].copy(), out[:, 2] > 0.5, out[:, 3].copy())
