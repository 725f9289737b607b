"""Model Predictive Path Integral (MPPI) local control for a whole fleet in one compiled call.

The method is Williams, Drews, Goldfain, Rehg and Theodorou, "Aggressive Driving with
Model Predictive Path Integral Control", IEEE ICRA 2016, and the same authors'
"Information-Theoretic Model Predictive Control: Theory and Applications to Autonomous
Driving", IEEE Transactions on Robotics 34(6), 2018: perturb a nominal control sequence,
roll the samples out through the robot's model, and make the nominal their mean weighted
by ``exp(-cost / temperature)``. The critics play the roles of Nav2's MPPI controller's
(goal, path follow, path angle, obstacles, prefer forward). Per robot and call (points in
``map``, controls ``v, w`` in ``base_link``; ``R = max_speed * time_steps * model_dt_s``):

- **Samples**: the nominal plus Gaussian noise (``v_std_mps``, ``w_std_radps``) drawn at
  knots every ``knot_steps`` steps and mixed linearly in between, rescaled to the same
  deviation at every step, so that few samples still explore sustained turns; the first
  sample is the nominal itself. Each control is clipped to the speed limits (reverse to
  ``-max_reverse_mps``), then to what the accelerations reach from the one before (from
  the measured velocity), and held ``model_dt_s`` along an exact unicycle arc.
- **Critics**: ``c`` a rollout point's clearance (distance to the nearest obstacle point
  or disc edge, minus the radius), ``c0`` the robot's where it stands. A sample with
  ``c < min(footprint_padding_m, c0)`` at a point *collides* (a robot inside the padding
  may move along or away, never closer) and costs ``collision_cost`` more. Obstacles:
  ``obstacle_weight`` times the mean of ``max(0, repulsion_m - c) / repulsion_m``, faded
  over the last ``R`` to the goal (goals may lie by shelves). Heading: ``heading_weight``
  times the mean of ``(1 - cos e) / 2``, ``e`` the angle from the heading to the target,
  faded within ``goal_zone_m`` of it near the goal. ``forward_weight`` times the reverse
  travel over ``R``; ``smooth_weight`` times the mean squared change of the controls per
  step over the acceleration limits. Target: while the carrot is farther than
  ``goal_zone_m`` from the goal, the carrot pushed out to ``2 R`` along its bearing (one
  within reach would reward stopping short), ``path_weight`` times the final point's
  distance to it over ``R``; else the carrot itself, ``goal_weight`` times the points'
  mean distance to it over ``R`` (get there and stay).
- **Update**: the nominal becomes the samples' clipped controls averaged with weights
  ``exp(-(S - min S) / temperature)``; its first control is commanded (within the limits
  by construction) and it is shifted by the control period (interpolated, last held).
- **Blocked** when every sample collides: the robot brakes (``v`` and ``w`` towards 0 by
  a control period of acceleration) and its nominal is reset to zeros.

The caller draws the noise for all robots at once: a robot's command depends only on its
own inputs and noise, however the robots are cut for threads. Obstacles are taken as
static over the horizon; a point is checked only from the first step that may near it.
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
from models.navigation.fleet_inputs import check_limits, fleet_rows, offsets, points
from models.slicing import Slices, whole


@dataclass(frozen=True)
class MppiParams:
    """Parameters of :func:`mppi_batch` (their meaning: the module docstring).

    Attributes:
        samples: perturbed control sequences per robot and call.
        time_steps: controls in a sequence.
        model_dt_s: how long each control is held in the rollouts (s).
        control_period_s: time between two calls: the nominal is shifted by it (s).
        v_std_mps: standard deviation of the speed noise (m/s).
        w_std_radps: standard deviation of the yaw-rate noise (rad/s).
        knot_steps: steps between two knots of noise, linear in between.
        temperature: softmax temperature lambda (cost units).
        footprint_padding_m: clearance beyond the footprint a sample must keep (m).
        repulsion_m: clearance within which obstacles cost (m).
        collision_cost: cost of a sample that collides.
        path_weight: weight of the final distance to the carrot pushed out.
        heading_weight: weight of the heading error to the target.
        goal_weight: weight of the mean distance to the carrot near the goal.
        goal_zone_m: the carrot this near the goal: aim to stop at it (m).
        obstacle_weight: weight of the proximity of obstacles.
        smooth_weight: weight of the change of the controls.
        forward_weight: weight of the reverse travel.
        goal_reset_m: a goal moved farther than this resets the robot's nominal (m).
    """

    samples: int = 24
    time_steps: int = 12
    model_dt_s: float = 0.1
    control_period_s: float = 0.1
    v_std_mps: float = 0.2
    w_std_radps: float = 0.5
    knot_steps: int = 5
    temperature: float = 0.01
    footprint_padding_m: float = 0.1
    repulsion_m: float = 0.4
    collision_cost: float = 1000.0
    path_weight: float = 1.0
    heading_weight: float = 0.3
    goal_weight: float = 1.0
    goal_zone_m: float = 1.0
    obstacle_weight: float = 1.0
    smooth_weight: float = 0.05
    forward_weight: float = 1.0
    goal_reset_m: float = 0.1

    def __post_init__(self) -> None:
        for f in fields(self):
            value, key = getattr(self, f.name), f"mppi.{f.name}"
            if f.type == "int" and not (isinstance(value, int) and value >= 1):
                raise ModelError(key, value, "an integer >= 1")
            if f.type != "float":
                continue
            positive = f.name in ("model_dt_s", "control_period_s", "temperature", "repulsion_m")
            if not (math.isfinite(value) and (value > 0 if positive else value >= 0)):
                raise ModelError(key, value, "a finite number " + ("> 0" if positive else ">= 0"))


class MppiResult(NamedTuple):
    """Commands of :func:`mppi_batch`, arrays indexed by robot.

    Attributes:
        v: forward speed commands (m/s, ``base_link``).
        w: yaw-rate commands (rad/s, counter-clockwise).
        blocked: every sample collided.
    """

    v: FloatArray
    w: FloatArray
    blocked: BoolArray


# packed configuration: MppiParams' float fields in order, the knots, then the limits
_CFG = tuple(f.name for f in fields(MppiParams) if f.type == "float" and f.name != "goal_reset_m")
_DT, _PERIOD, _V_STD, _W_STD, _LAMBDA, _PAD, _REP, _COLLIDE = range(8)
_K_PATH, _K_HEAD, _K_GOAL, _ZONE, _K_OBST, _K_SMOOTH, _K_FWD, _KNOT = range(8, 16)
_V_MAX, _REVERSE, _W_MAX, _ACC, _YAW_ACC = range(16, 21)


def noise_knots(params: MppiParams) -> int:
    """Knots of noise per sample and channel: every ``knot_steps`` steps, and one past."""
    return (params.time_steps - 1) // params.knot_steps + 2


@numba.njit(cache=True, nogil=True, inline="always")
def _clip(value: float, lo: float, hi: float) -> float:
    return min(max(value, lo), hi)


@numba.njit(cache=True, nogil=True, inline="always")
def _turn(h: float) -> tuple[float, float, float]:
    """``cos h, sin h, sin h / h`` by their series, for ``|h| <= 0.3`` (error below 2e-10)."""
    h2 = h * h
    sinc = 1.0 - h2 / 6.0 * (1.0 - h2 / 20.0 * (1.0 - h2 / 42.0))
    cos = 1.0 - h2 / 2.0 * (1.0 - h2 / 12.0 * (1.0 - h2 / 30.0 * (1.0 - h2 / 56.0)))
    return cos, h * sinc, sinc


def _mppi_py(
    state: FloatArray,
    nominal: FloatArray,
    noise: FloatArray,
    obstacles: FloatArray,
    obstacle_start: IntArray,
    discs: FloatArray,
    disc_start: IntArray,
    cfg: FloatArray,
    out: FloatArray,
) -> None:
    """All robots; ``state`` rows ``x y yaw v w radius carrot_xy goal_xy``; ``out`` (n, 3).

    ``nominal`` (n, T, 2) is updated in place; ``noise`` (n, knots, 2, K) is standard
    normal (zeros for the first sample). Loops run over the samples innermost, on arrays
    laid out by step then sample, so that the compiler vectorizes them.
    """
    n, samples, steps = state.shape[0], noise.shape[3], nominal.shape[1]
    dt, rep, pad, zone = cfg[_DT], cfg[_REP], cfg[_PAD], max(cfg[_ZONE], 1e-9)
    v_max, v_min, w_max = cfg[_V_MAX], -cfg[_REVERSE], cfg[_W_MAX]
    dv, dw = cfg[_ACC] * dt, cfg[_YAW_ACC] * dt
    to_dv, to_dw = 1.0 / max(dv, 1e-12), 1.0 / max(dw, 1e-12)
    pieces = max(1, math.ceil(w_max * dt / 0.6))  # every half turn within the series' reach
    sub, knot = dt / pieces, int(cfg[_KNOT])
    reach, norm, inf = max(v_max, -v_min) * dt * steps, max(v_max * dt * steps, 1e-9), np.inf
    most_pts = max(0, np.max(obstacle_start[1:] - obstacle_start[:-1])) if n else 0
    most_discs = max(0, np.max(disc_start[1:] - disc_start[:-1])) if n else 0
    ox2, oy2, oo = np.empty(most_pts), np.empty(most_pts), np.empty(most_pts)
    first, disc = np.empty(most_pts, dtype=np.int64), np.empty((most_discs, 3))
    uv, uw = np.empty((steps, samples)), np.empty((steps, samples))
    total = steps * samples  # rollout points, flattened as (step, sample)
    px, py, uu = np.empty(total), np.empty(total), np.empty(total)
    acc, near = np.empty(total), np.empty(total)
    xs, ys, ch, sh = np.empty(samples), np.empty(samples), np.empty(samples), np.empty(samples)
    vp, wp, cost = np.empty(samples), np.empty(samples), np.empty(samples)
    least, prox, back = np.empty(samples), np.empty(samples), np.empty(samples)
    smooth, gsum, hsum = np.empty(samples), np.empty(samples), np.empty(samples)
    mean = np.empty((steps, 2))
    for i in range(n):
        x, y, yaw, rad = state[i, 0], state[i, 1], state[i, 2], state[i, 5]
        v0, w0 = _clip(state[i, 3], v_min, v_max), _clip(state[i, 4], -w_max, w_max)
        tx, ty = state[i, 6] - x, state[i, 7] - y
        d_goal, d_target = math.hypot(state[i, 8] - x, state[i, 9] - y), math.hypot(tx, ty)
        path_mode = math.hypot(state[i, 8] - state[i, 6], state[i, 9] - state[i, 7]) > cfg[_ZONE]
        if path_mode and 0.0 < d_target < 2.0 * norm:
            tx, ty = tx * 2.0 * norm / d_target, ty * 2.0 * norm / d_target
        fade = 1e300 if path_mode else 1.0 / zone  # the heading matters less near the goal
        # the samples' controls, rollouts (relative to the robot) and the critics of both
        xs[:], ys[:], ch[:], sh[:], vp[:], wp[:] = 0.0, 0.0, math.cos(yaw), math.sin(yaw), v0, w0
        least[:], prox[:], back[:], smooth[:], gsum[:], hsum[:] = inf, 0.0, 0.0, 0.0, 0.0, 0.0
        for k in range(steps):
            # step k's noise: knots j and j + 1 mixed, scaled back to a unit variance
            j, f = k // knot, (k % knot) / knot
            scale = math.sqrt((1.0 - f) ** 2 + f * f)
            a, b = (1.0 - f) / scale, f / scale
            av, bv, aw, bw = cfg[_V_STD] * a, cfg[_V_STD] * b, cfg[_W_STD] * a, cfg[_W_STD] * b
            nv, nw, uvk, uwk = nominal[i, k, 0], nominal[i, k, 1], uv[k], uw[k]
            ev0, ev1, ew0, ew1 = (
                noise[i, j, 0],
                noise[i, j + 1, 0],
                noise[i, j, 1],
                noise[i, j + 1, 1],
            )
            for s in range(samples):
                vc = _clip(nv + av * ev0[s] + bv * ev1[s], v_min, v_max)
                wc = _clip(nw + aw * ew0[s] + bw * ew1[s], -w_max, w_max)
                vc, wc = _clip(vc, vp[s] - dv, vp[s] + dv), _clip(wc, wp[s] - dw, wp[s] + dw)
                ddv, ddw = (vc - vp[s]) * to_dv, (wc - wp[s]) * to_dw
                smooth[s] += ddv * ddv + ddw * ddw
                back[s] += max(-vc, 0.0)
                uvk[s], uwk[s], vp[s], wp[s] = vc, wc, vc, wc
            # exact arcs in pieces turning <= 0.6 rad: the chord along the half-way heading
            for _ in range(pieces):
                for s in range(samples):
                    c, sn, sinc = _turn(0.5 * wp[s] * sub)
                    mc, ms = ch[s] * c - sh[s] * sn, sh[s] * c + ch[s] * sn
                    xs[s], ys[s] = xs[s] + vp[s] * sub * sinc * mc, ys[s] + vp[s] * sub * sinc * ms
                    ch[s], sh[s] = mc * c - ms * sn, ms * c + mc * sn
            base = k * samples
            pxk, pyk, uuk, acck, neark = px[base:], py[base:], uu[base:], acc[base:], near[base:]
            for s in range(samples):
                pxk[s], pyk[s], acck[s], neark[s] = xs[s], ys[s], inf, inf
                uuk[s] = xs[s] * xs[s] + ys[s] * ys[s]
                ex, ey = tx - xs[s], ty - ys[s]
                gap = math.sqrt(ex * ex + ey * ey)
                gsum[s] += gap
                # (1 - cos) / 2 of the angle between the heading and the way to the target
                miss = 0.5 - 0.5 * (ex * ch[s] + ey * sh[s]) / max(gap, 1e-9)
                hsum[s] += miss * min(1.0, gap * fade)
        # obstacles (doubled) within reach; one beyond step k's reach + keep matters later
        keep = rad + max(rep, pad)
        m, oo_min = 0, inf
        for j in range(obstacle_start[i], obstacle_start[i + 1]):
            ddx, ddy = obstacles[j, 0] - x, obstacles[j, 1] - y
            d2 = ddx * ddx + ddy * ddy
            oo_min = min(oo_min, d2)
            if d2 <= (reach + keep) * (reach + keep):
                ox2[m], oy2[m], oo[m] = 2.0 * ddx, 2.0 * ddy, d2
                late = (math.sqrt(d2) - keep) * steps / max(reach, 1e-12)
                first[m] = samples * min(max(math.ceil(late) - 1, 0), steps - 1)
                m += 1
        nd, c0 = 0, math.sqrt(oo_min) - rad
        for j in range(disc_start[i], disc_start[i + 1]):
            ddx, ddy = discs[j, 0] - x, discs[j, 1] - y
            gap = math.sqrt(ddx * ddx + ddy * ddy) - discs[j, 2]
            c0 = min(c0, gap - rad)
            if gap <= reach + keep:
                disc[nd, 0], disc[nd, 1], disc[nd, 2] = ddx, ddy, discs[j, 2]
                nd += 1
        # |o - p|^2 = |o|^2 - 2 o.p + |p|^2 vectorized; views from 0 drop wraparound checks
        for j in range(m):
            oxj, oyj, ooj = ox2[j], oy2[j], oo[j]
            tail, tpx, tpy = acc[first[j] : total], px[first[j] : total], py[first[j] : total]
            for q in range(tail.size):
                tail[q] = min(tail[q], ooj - oxj * tpx[q] - oyj * tpy[q])
        for e in range(nd):
            ex, ey, er = disc[e, 0], disc[e, 1], disc[e, 2]
            for q in range(total):
                near[q] = min(near[q], math.sqrt((ex - px[q]) ** 2 + (ey - py[q]) ** 2) - er)
        for k in range(steps):  # the clearances' critics
            acck, uuk, neark = acc[k * samples :], uu[k * samples :], near[k * samples :]
            for s in range(samples):
                c = min(math.sqrt(max(acck[s] + uuk[s], 0.0)), neark[s]) - rad
                least[s], prox[s] = min(least[s], c), prox[s] + max(rep - c, 0.0)
        thr = min(pad, c0)
        k_obst = cfg[_K_OBST] * min(1.0, d_goal / norm) / (rep * steps)
        best, free, last = inf, 0, (steps - 1) * samples
        for s in range(samples):
            score = k_obst * prox[s] + cfg[_K_FWD] * back[s] * dt / norm
            score += cfg[_K_SMOOTH] * smooth[s] / steps + cfg[_K_HEAD] * hsum[s] / steps
            if path_mode:
                score += cfg[_K_PATH] * math.hypot(tx - px[last + s], ty - py[last + s]) / norm
            else:
                score += cfg[_K_GOAL] * gsum[s] / (steps * norm)
            if c0 <= 0.0 or least[s] < thr:
                score += cfg[_COLLIDE]
            else:
                free += 1
            cost[s] = score
            best = min(best, score)
        if free == 0:  # brake: towards 0 as far as one control period allows
            slow_v, slow_w = cfg[_ACC] * cfg[_PERIOD], cfg[_YAW_ACC] * cfg[_PERIOD]
            out[i, 0], out[i, 2] = _clip(0.0, v0 - slow_v, v0 + slow_v), 1.0
            out[i, 1], nominal[i, :, :] = _clip(0.0, w0 - slow_w, w0 + slow_w), 0.0
            continue
        cost[:] = np.exp((best - cost) / cfg[_LAMBDA])
        cost /= np.sum(cost)
        for k in range(steps):  # clipped again: rounding may take a mean of limits beyond
            mean[k, 0] = _clip(np.sum(cost * uv[k]), v_min, v_max)
            mean[k, 1] = _clip(np.sum(cost * uw[k]), -w_max, w_max)
        out[i, 0], out[i, 1], out[i, 2] = mean[0, 0], mean[0, 1], 0.0
        # shift the nominal by the control period, the last control held
        for k in range(steps):
            at = min(k + cfg[_PERIOD] / dt, steps - 1.0)
            lo, f = int(at), at - int(at)
            nominal[i, k] = (1.0 - f) * mean[lo] + f * mean[min(lo + 1, steps - 1)]


_mppi: Any = numba.njit(cache=True, nogil=True)(_mppi_py)


def mppi_batch(
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
    nominal: FloatArray,
    noise: FloatArray,
    params: MppiParams,
    slices: Slices = whole,
) -> MppiResult:
    """MPPI commands for every robot, its nominal updated in place (module docstring).

    Args:
        poses: (n, 3) poses ``x, y, yaw`` in ``map`` (m, m, rad).
        velocities: (n, 2) measured ``v, w`` (m/s, rad/s).
        limits: velocity and acceleration limits, the same for every robot.
        radius_m: (n,) footprint radii (m).
        carrots: (n, 2) points ahead on the global paths, in ``map`` (m).
        goals: (n, 2) final goals in ``map`` (m).
        obstacles: (m, 2) obstacle points in ``map`` (m), robot ``i``'s from row
            ``obstacle_start[i]`` to ``obstacle_start[i + 1]``.
        obstacle_start: (n + 1,) offsets into ``obstacles``.
        discs: (d, 3) discs ``x, y, r`` in ``map`` (m), e.g. other robots, as the points.
        disc_start: (n + 1,) offsets into ``discs``.
        nominal: (n, time_steps, 2) float64 C-contiguous nominal ``v, w`` (m/s, rad/s),
            one per ``model_dt_s``; updated and shifted in place.
        noise: (n, :func:`noise_knots`, 2, samples) standard normal draws by robot,
            knot, channel (``v``, ``w``) and sample; the first sample's are not used.
        params: controller parameters.
        slices: how to cut the robots for threads (:mod:`models.slicing`); each robot's
            command is the same whatever the cut.

    Returns:
        The commands and blocked flags, indexed by robot.

    Raises:
        ValueError: an array has the wrong shape, or offsets do not index the points.
        ModelError: the speed limit is not positive.
    """
    rows = fleet_rows(poses, velocities, radius_m, carrots, goals)
    n, knots = len(rows), noise_knots(params)
    shapes = {"nominal": (n, params.time_steps, 2), "noise": (n, knots, 2, params.samples)}
    for (name, shape), array in zip(shapes.items(), (nominal, noise), strict=True):
        if np.shape(array) != shape:
            raise ValueError(f"{name} must be {shape}, got {np.shape(array)}")
    if nominal.dtype != np.float64 or not nominal.flags.c_contiguous:
        raise ValueError("nominal must be C-contiguous float64: it is updated in place")
    check_limits(limits)
    draws = np.array(noise, dtype=np.float64)  # a copy: the first sample is the nominal
    draws[:, :, :, 0] = 0.0
    pts, dsc = points(obstacles, 2), points(discs, 3)
    pts_start = offsets(obstacle_start, n, len(pts), "obstacle_start")
    dsc_start = offsets(disc_start, n, len(dsc), "disc_start")
    cfg = [float(getattr(params, name)) for name in _CFG] + [float(params.knot_steps)]
    cfg += [limits.max_speed_mps, limits.max_reverse_mps, limits.max_yaw_rate_radps]
    packed = np.array([*cfg, limits.max_accel_mps2, limits.max_yaw_accel_radps2])
    out = np.zeros((n, 3))

    def decide(a: int, b: int) -> None:
        # the offsets stay absolute: a slice of robots reads its own points and discs
        pieces = (rows[a:b], nominal[a:b], draws[a:b], pts, pts_start[a : b + 1], dsc)
        _mppi(*pieces, dsc_start[a : b + 1], packed, out[a:b])

    slices(n, decide)
    return MppiResult(out[:, 0].copy(), out[:, 1].copy(), out[:, 2] > 0.5)
