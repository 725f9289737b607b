"""Correlative scan-to-map matching with two-level branch and bound (Olson, ICRA 2009).

The pose of a scan is searched over a window around a prior (the last estimate moved by
odometry): every rotation in the window at a step small enough that the farthest point
used moves by less than a cell, every translation in whole cells. A candidate's score is
the mean fine score (:class:`models.mapping.grid.LogOddsMap`) of the cells its points
fall in, times a mild penalty for straying from the prior (Karto's response penalty, so
that a featureless corridor keeps the odometry's position along it). Translations are
searched in blocks of ``COARSE`` x ``COARSE`` cells whose coarse score bounds every
translation inside: blocks are visited best bound first and the search stops when no
bound beats the best score found, so the result is the exact optimum of the window at
the cost of a few blocks (Olson's multi-resolution method; Karto and slam_toolbox
search the same kind of window).

Why this matcher rather than point-to-line ICP: it needs no initial guess inside the
basin of attraction (the whole window is searched), it cannot diverge, and its score
says how well a scan fits, which gates the update (``min_score``); ICP is cheaper per
iteration but can lock onto the wrong wall in aisles of identical shelves.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Literal, NamedTuple

import numba
import numpy as np
import numpy.typing as npt

from models.arrays import FloatArray
from models.errors import ModelError
from models.mapping.gauss_newton import levenberg_step, within_cell
from models.mapping.grid import COARSE, LogOddsMap
from models.mapping.walls import refine_on_walls

REFINE_STEPS = 8
"""Most Gauss-Newton steps of the refinement."""


@dataclass(frozen=True)
class MatcherParams:
    """The search window and what a match must score.

    Attributes:
        window_m: half-width of the translation window (m).
        window_rad: half-width of the rotation window (rad).
        max_range_m: points farther than this are not used (they set the angular step).
        max_points: at most this many points are used, evenly picked.
        min_score: a best score below this (0..1) is no match: the prior is kept.
        penalty: score factor lost at the window's corner (Karto's response penalty).
        margin: how much better than the prior a candidate must score to replace it. With
            good odometry a shift to a barely better cell is more often noise than a
            correction (simulated warehouse: 0.02 helps); with noisy odometry the small
            corrections matter (the ACES recording: 0 is best).
        refine: refine the best cell-sized candidate continuously.
        refine_against: what the refine fits: ``"score"``, Gauss-Newton on the bilinearly
            interpolated score (as Hector SLAM matches; robust on real recordings), or
            ``"walls"``, each point onto the wall it lies near, fitted to where the map's
            returns fell within their cells (:mod:`models.mapping.walls`; needs a map
            with ``hit_centroids``): the score's peaks sit on cell centres, and on the
            simulated warehouse's exact walls that refine let maps drift by centimetres.
    """

    window_m: float = 0.3
    window_rad: float = 0.12
    max_range_m: float = 20.0
    max_points: int = 240
    min_score: float = 0.3
    penalty: float = 0.1
    margin: float = 0.0
    refine: bool = True
    refine_against: Literal["score", "walls"] = "score"

    def __post_init__(self) -> None:
        for name in ("window_m", "window_rad", "max_range_m"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ModelError(f"mapping.{name}", value, "a finite value > 0")
        if not 0 <= self.min_score <= 1:
            raise ModelError("mapping.min_score", self.min_score, "a score in [0, 1]")
        if self.refine_against not in ("score", "walls"):
            raise ModelError("mapping.refine", self.refine_against, "'score' or 'walls'")


class Match(NamedTuple):
    """The outcome of a match.

    Attributes:
        pose: the best pose (x, y, yaw) in ``map``, or the prior without a match.
        score: its score in [0, 1] (mean fine score of the points, penalty applied).
        matched: whether the score reached ``min_score``.
        evaluated: candidate poses scored at the fine level (a measure of effort).
    """

    pose: tuple[float, float, float]
    score: float
    matched: bool
    evaluated: int


def scan_points(
    angles_rad: FloatArray,
    ranges_m: npt.NDArray[np.floating[Any]],
    range_min_m: float,
    max_range_m: float,
    limit: int,
) -> FloatArray:
    """Returns usable for matching, as (k, 2) points in the sensor frame, at most ``limit``."""
    r = np.asarray(ranges_m, dtype=np.float64)
    ok = np.isfinite(r) & (r >= range_min_m) & (r <= max_range_m)
    idx = np.flatnonzero(ok)
    if len(idx) > limit:
        idx = idx[np.linspace(0, len(idx) - 1, limit).round().astype(np.int64)]
    a = np.asarray(angles_rad, dtype=np.float64)[idx]
    return np.stack([r[idx] * np.cos(a), r[idx] * np.sin(a)], axis=1)


def match(
    grid: LogOddsMap, prior: tuple[float, float, float], points: FloatArray, params: MatcherParams
) -> Match:
    """The best pose of ``points`` (sensor frame) in ``grid`` within the window of ``prior``."""
    if len(points) == 0 or grid.empty:
        return Match(prior, 0.0, False, 0)
    g = grid.geometry
    res = g.resolution_m
    reach = float(np.hypot(points[:, 0], points[:, 1]).max())
    step = res / max(reach, res)
    n_ang = max(1, math.ceil(params.window_rad / step))
    offsets = np.arange(-n_ang, n_ang + 1) * (params.window_rad / n_ang)
    n_lin = max(1, math.ceil(params.window_m / res))
    best = _search(
        grid.score,
        grid.coarse,
        g.origin_xy_m[0],
        g.origin_xy_m[1],
        res,
        np.ascontiguousarray(points[:, 0]),
        np.ascontiguousarray(points[:, 1]),
        float(prior[0]),
        float(prior[1]),
        float(prior[2]),
        offsets,
        n_lin,
        COARSE,
        params.penalty,
        params.margin,
    )
    kx, ky, ka, score, evaluated = best
    if score < params.min_score:
        return Match(prior, float(score), False, int(evaluated))
    x, y, yaw = prior[0] + kx * res, prior[1] + ky * res, prior[2] + offsets[int(ka)]
    if params.refine and params.refine_against == "walls":
        x, y, yaw = refine_on_walls(grid, points, (x, y, yaw), REFINE_STEPS)
    elif params.refine:
        x, y, yaw = _refine(
            grid.score,
            g.origin_xy_m[0],
            g.origin_xy_m[1],
            res,
            np.ascontiguousarray(points[:, 0]),
            np.ascontiguousarray(points[:, 1]),
            x,
            y,
            yaw,
            REFINE_STEPS,
        )
    return Match((float(x), float(y), float(yaw)), float(score), True, int(evaluated))


def _sample_py(score: Any, fx: float, fy: float) -> tuple[float, float, float]:
    """Bilinear score at a point in cell units, and its gradient (per cell)."""
    height, width = score.shape
    x = fx - 0.5  # cell centres at half-integers
    y = fy - 0.5
    ix = math.floor(x)
    iy = math.floor(y)
    if ix < 0 or iy < 0 or ix + 1 >= width or iy + 1 >= height:
        return 0.0, 0.0, 0.0
    ax = x - ix
    ay = y - iy
    s00 = float(score[iy, ix])
    s01 = float(score[iy, ix + 1])
    s10 = float(score[iy + 1, ix])
    s11 = float(score[iy + 1, ix + 1])
    value = (1 - ay) * ((1 - ax) * s00 + ax * s01) + ay * ((1 - ax) * s10 + ax * s11)
    gx = (1 - ay) * (s01 - s00) + ay * (s11 - s10)
    gy = (1 - ax) * (s10 - s00) + ax * (s11 - s01)
    return value, gx, gy


def _refine_py(
    score: Any,
    ox: float,
    oy: float,
    res: float,
    px: Any,
    py: Any,
    x: float,
    y: float,
    yaw: float,
    steps: int,
) -> tuple[float, float, float]:
    """Gauss-Newton on the bilinearly interpolated score, within a cell of the start."""
    x0, y0, yaw0 = x, y, yaw
    n = px.shape[0]
    best_value = -1.0
    best = (x, y, yaw)
    for _ in range(steps):
        c = math.cos(yaw)
        s = math.sin(yaw)
        h00 = h01 = h02 = h11 = h12 = h22 = 0.0
        b0 = b1 = b2 = 0.0
        total = 0.0
        for i in range(n):
            wx = x + c * px[i] - s * py[i]
            wy = y + s * px[i] + c * py[i]
            value, gx, gy = _sample(score, (wx - ox) / res, (wy - oy) / res)
            total += value
            # residual 255 - value; d value / d (x, y) = g / res; d / d yaw through the point
            jx = gx / res
            jy = gy / res
            jt = jx * (-s * px[i] - c * py[i]) + jy * (c * px[i] - s * py[i])
            r = 255.0 - value
            h00 += jx * jx
            h01 += jx * jy
            h02 += jx * jt
            h11 += jy * jy
            h12 += jy * jt
            h22 += jt * jt
            b0 += jx * r
            b1 += jy * r
            b2 += jt * r
        if total <= best_value:
            break
        best_value = total
        best = (x, y, yaw)
        dx, dy, dt, ok = levenberg_step(h00, h01, h02, h11, h12, h22, b0, b1, b2, 1e-3, 1e-9, 1e-12)
        if not ok:
            break
        x, y, yaw = within_cell((x0, y0, yaw0), x + dx, y + dy, yaw + dt, res)
    return best


def _add4_py(
    acc: tuple[int, int, int, int], row: Any, x: int, step: int
) -> tuple[int, int, int, int]:
    """``acc`` plus ``row`` at ``x``, ``x + step``, ``x + 2 step`` and ``x + 3 step``."""
    return (
        acc[0] + int(row[x]),
        acc[1] + int(row[x + step]),
        acc[2] + int(row[x + 2 * step]),
        acc[3] + int(row[x + 3 * step]),
    )


def _put4_py(out: Any, *rows: tuple[int, int, int, int]) -> None:
    """Add four rows of four sums to ``out[:16]`` (row-major)."""
    for j in range(4):
        for k in range(4):
            out[4 * j + k] += rows[j][k]


def _search_py(
    fine: Any,
    coarse: Any,
    ox: float,
    oy: float,
    res: float,
    px: Any,
    py: Any,
    x0: float,
    y0: float,
    yaw0: float,
    offsets: Any,
    n_lin: int,
    c: int,
    penalty: float,
    margin: float,
) -> tuple[int, int, int, float, int]:
    """Branch and bound over (rotation, translation block, translation)."""
    height, width = fine.shape
    n_pts = px.shape[0]
    n_rot = offsets.shape[0]
    span = 2 * n_lin + 1
    blocks = (span + c - 1) // c
    # the cell each point falls in at zero translation, per rotation
    bx = np.empty((n_rot, n_pts), dtype=np.int64)
    by = np.empty((n_rot, n_pts), dtype=np.int64)
    for a in range(n_rot):
        ca = math.cos(yaw0 + offsets[a])
        sa = math.sin(yaw0 + offsets[a])
        for i in range(n_pts):
            bx[a, i] = math.floor((x0 + ca * px[i] - sa * py[i] - ox) / res)
            by[a, i] = math.floor((y0 + sa * px[i] + ca * py[i] - oy) / res)
    # the bound of every (rotation, block): sum of coarse scores at the block's corner,
    # point by point (the integer sums do not depend on the order): a point's samples lie
    # close together, and a point whose blocks all lie on the grid needs no checks
    n_nodes = n_rot * blocks * blocks
    bounds = np.empty(n_nodes, dtype=np.float64)
    sums = np.zeros(blocks * blocks, dtype=np.int64)
    reach = (blocks - 1) * c
    for a in range(n_rot):
        sums[:] = 0
        q0 = q1 = q2 = q3 = (0, 0, 0, 0)
        for i in range(n_pts):
            y0i = by[a, i] - n_lin
            x0i = bx[a, i] - n_lin
            if y0i >= 0 and x0i >= 0 and y0i + reach < height and x0i + reach < width:
                if blocks == 4:  # the default window: 16 running sums in registers (1.6x per match)
                    q0 = _add4(q0, coarse[y0i], x0i, c)
                    q1 = _add4(q1, coarse[y0i + c], x0i, c)
                    q2 = _add4(q2, coarse[y0i + 2 * c], x0i, c)
                    q3 = _add4(q3, coarse[y0i + 3 * c], x0i, c)
                    continue
                for bj in range(blocks):
                    for bi in range(blocks):
                        sums[bj * blocks + bi] += int(coarse[y0i + bj * c, x0i + bi * c])
                continue
            for bj in range(blocks):
                cy = y0i + bj * c
                # a window hanging over the low edge is bounded by the edge's window
                if -c < cy < 0:
                    cy = 0
                if cy < 0 or cy >= height:
                    continue
                for bi in range(blocks):
                    cx = x0i + bi * c
                    if -c < cx < 0:
                        cx = 0
                    if 0 <= cx < width:
                        sums[bj * blocks + bi] += int(coarse[cy, cx])
        if blocks == 4:
            _put4(sums, q0, q1, q2, q3)
        for k in range(blocks * blocks):
            bounds[a * blocks * blocks + k] = sums[k] / (255.0 * n_pts)
    order = np.argsort(-bounds)
    # the prior itself (no translation, middle rotation) is the first candidate: another
    # must beat it by ``margin`` to be chosen, so equal scores keep the odometry
    center = n_rot // 2
    total = 0
    for i in range(n_pts):
        cx = bx[center, i]
        cy = by[center, i]
        if 0 <= cx < width and 0 <= cy < height:
            total += int(fine[cy, cx])
    best = total / (255.0 * n_pts) + margin
    best_kx, best_ky, best_a = 0, 0, center
    evaluated = 1
    w_lin = float(n_lin) * n_lin
    w_rot = float(n_rot // 2) * (n_rot // 2) if n_rot > 1 else 1.0
    block = np.zeros((c, c), dtype=np.int64)
    for node in order:
        if bounds[node] <= best:
            break
        a = node // (blocks * blocks)
        bj = (node // blocks) % blocks
        bi = node % blocks
        da = a - n_rot // 2
        # the block's translations summed point by point, then scored in the same order
        ky0 = -n_lin + bj * c
        kx0 = -n_lin + bi * c
        ny = min(c, n_lin + 1 - ky0)
        nx = min(c, n_lin + 1 - kx0)
        block[:, :] = 0
        whole = c == 4 and ny == 4 and nx == 4
        q0 = q1 = q2 = q3 = (0, 0, 0, 0)
        for i in range(n_pts):
            y0i = by[a, i] + ky0
            x0i = bx[a, i] + kx0
            if y0i >= 0 and x0i >= 0 and y0i + ny <= height and x0i + nx <= width:
                if whole:  # as for the bounds: a whole block's sums in registers
                    q0 = _add4(q0, fine[y0i], x0i, 1)
                    q1 = _add4(q1, fine[y0i + 1], x0i, 1)
                    q2 = _add4(q2, fine[y0i + 2], x0i, 1)
                    q3 = _add4(q3, fine[y0i + 3], x0i, 1)
                    continue
                for j in range(ny):
                    for k in range(nx):
                        block[j, k] += int(fine[y0i + j, x0i + k])
                continue
            for j in range(ny):
                cy = y0i + j
                if cy < 0 or cy >= height:
                    continue
                for k in range(nx):
                    cx = x0i + k
                    if 0 <= cx < width:
                        block[j, k] += int(fine[cy, cx])
        if whole:
            _put4(block.ravel(), q0, q1, q2, q3)
        for j in range(ny):
            ky = ky0 + j
            for k in range(nx):
                kx = kx0 + k
                evaluated += 1
                d2 = 0.5 * ((kx * kx + ky * ky) / w_lin + da * da / w_rot)
                score = block[j, k] / (255.0 * n_pts) * (1.0 - penalty * d2)
                if score > best:
                    best = score
                    best_kx, best_ky, best_a = kx, ky, a
    if best_kx == 0 and best_ky == 0 and best_a == center:
        best -= margin
    return best_kx, best_ky, best_a, best, evaluated


_add4: Any = numba.njit(cache=True, nogil=True, inline="always")(_add4_py)
_put4: Any = numba.njit(cache=True, nogil=True)(_put4_py)
_search: Any = numba.njit(cache=True, nogil=True)(_search_py)
_sample: Any = numba.njit(cache=True, nogil=True)(_sample_py)
_refine: Any = numba.njit(cache=True, nogil=True)(_refine_py)
