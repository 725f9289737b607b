"""The small linear programs of ORCA: the velocity nearest a preferred one within half-planes.

The solver of van den Berg, Guy, Lin and Manocha, "Reciprocal n-Body Collision Avoidance"
(ISRR 2009, Springer Tracts in Advanced Robotics 70, 2011), section 5: ``lp1`` optimizes on
one constraint line, ``lp2`` adds the half-planes one by one in 2-D (randomized
incremental linear programming without the shuffle, so the result is deterministic), and
``lp3`` finds the velocity that violates the half-planes least when none fits. Half-planes
are rows ``(point_x, point_y, dir_x, dir_y)``: the allowed side is to the left of the
direction. Velocities in m/s (``map``). Each function has a pure-Python version (``*_py``)
and a compiled one, which :mod:`models.navigation.orca` calls.
"""

from __future__ import annotations

import math
from typing import Any

import numba

from models.arrays import FloatArray

EPS = 1e-9
"""Lines nearer parallel than this (|det| of their unit directions) count as parallel."""


def det_py(ax: float, ay: float, bx: float, by: float) -> float:
    """The 2-D cross product ``a x b``: positive when ``b`` lies left of ``a``."""
    return ax * by - ay * bx


det: Any = numba.njit(cache=True, nogil=True, inline="always")(det_py)


def half_plane_py(
    px: float, py: float, vx: float, vy: float, radius: float, horizon: float, step: float
) -> tuple[float, float, float, float]:
    """ORCA's ``u`` and line direction for relative position ``p`` and velocity ``v``.

    The velocity obstacle is ``{x : |t x - p| < radius for some t in (0, horizon]}``; ``u``
    is the smallest change of ``v`` that leaves it (within ``step`` when already
    overlapping), and the allowed side lies left of the returned unit direction.
    """
    d2, r2 = px * px + py * py, radius * radius
    if d2 > r2:
        inv = 1.0 / horizon
        wx, wy = vx - inv * px, vy - inv * py  # from the cut-off disc's centre to v
        w2, along = wx * wx + wy * wy, wx * px + wy * py
        if along < 0.0 and along * along > r2 * w2:  # nearest the cut-off disc
            wl = math.sqrt(w2)
            nx, ny = wx / wl, wy / wl
            s = radius * inv - wl
            return s * nx, s * ny, ny, -nx
        leg = math.sqrt(d2 - r2)
        if det(px, py, wx, wy) > 0.0:  # nearest the left leg
            dx, dy = (px * leg - py * radius) / d2, (px * radius + py * leg) / d2
        else:  # the right leg
            dx, dy = -(px * leg + py * radius) / d2, -(-px * radius + py * leg) / d2
        proj = vx * dx + vy * dy
        return proj * dx - vx, proj * dy - vy, dx, dy
    inv = 1.0 / step
    wx, wy = vx - inv * px, vy - inv * py
    wl = math.sqrt(wx * wx + wy * wy)
    nx, ny = (wx / wl, wy / wl) if wl > EPS else (1.0, 0.0)
    s = radius * inv - wl
    return s * nx, s * ny, ny, -nx


half_plane: Any = numba.njit(cache=True, nogil=True)(half_plane_py)


def lp1_py(
    lines: FloatArray, k: int, radius: float, ox: float, oy: float, unit: bool, res: FloatArray
) -> bool:
    """Best point of line ``k`` within the disc and lines ``0..k-1`` into ``res``, if any."""
    px, py, dx, dy = lines[k, 0], lines[k, 1], lines[k, 2], lines[k, 3]
    along = px * dx + py * dy
    disc = along * along + radius * radius - (px * px + py * py)
    if disc < 0.0:
        return False
    root = math.sqrt(disc)
    lo, hi = -along - root, -along + root
    for j in range(k):
        den = det(dx, dy, lines[j, 2], lines[j, 3])
        num = det(lines[j, 2], lines[j, 3], px - lines[j, 0], py - lines[j, 1])
        if abs(den) <= EPS:
            if num < 0.0:
                return False
            continue
        if den > 0.0:
            hi = min(hi, num / den)
        else:
            lo = max(lo, num / den)
        if lo > hi:
            return False
    if unit:  # optimize a direction: go as far along it as the line allows
        t = hi if ox * dx + oy * dy > 0.0 else lo
    else:
        t = min(max(dx * (ox - px) + dy * (oy - py), lo), hi)
    res[0], res[1] = px + t * dx, py + t * dy
    return True


lp1: Any = numba.njit(cache=True, nogil=True)(lp1_py)


def lp2_py(
    lines: FloatArray, count: int, radius: float, ox: float, oy: float, unit: bool, res: FloatArray
) -> int:
    """The point nearest ``o`` (or farthest along the unit ``o``) meeting every line.

    Returns the index of the first line that cannot be met (``res`` then meets the lines
    before it), or ``count``.
    """
    if unit:
        res[0], res[1] = ox * radius, oy * radius
    elif ox * ox + oy * oy > radius * radius:
        norm = math.sqrt(ox * ox + oy * oy)
        res[0], res[1] = ox * radius / norm, oy * radius / norm
    else:
        res[0], res[1] = ox, oy
    for k in range(count):
        violated = det(lines[k, 2], lines[k, 3], lines[k, 0] - res[0], lines[k, 1] - res[1]) > 0.0
        if violated and not lp1(lines, k, radius, ox, oy, unit, res):
            return k
    return count


lp2: Any = numba.njit(cache=True, nogil=True)(lp2_py)


def lp3_py(
    lines: FloatArray,
    count: int,
    fixed: int,
    begin: int,
    radius: float,
    res: FloatArray,
    proj: FloatArray,
) -> None:
    """From line ``begin`` on, minimize the largest violation of lines ``fixed..`` in ``res``.

    Lines ``0..fixed-1`` stay hard; ``res`` meets lines ``0..begin-1`` on entry.
    """
    worst = 0.0
    for k in range(begin, count):
        px, py, dx, dy = lines[k, 0], lines[k, 1], lines[k, 2], lines[k, 3]
        if det(dx, dy, px - res[0], py - res[1]) <= worst:
            continue
        # lines where line k's violation equals line j's, for every soft j before k
        m = fixed
        proj[:fixed] = lines[:fixed]
        for j in range(fixed, k):
            qx, qy, ex, ey = lines[j, 0], lines[j, 1], lines[j, 2], lines[j, 3]
            den = det(dx, dy, ex, ey)
            if abs(den) <= EPS:
                if dx * ex + dy * ey > 0.0:
                    continue  # parallel, same side: line j is never the worse
                ax, ay = 0.5 * (px + qx), 0.5 * (py + qy)
            else:
                s = det(ex, ey, px - qx, py - qy) / den
                ax, ay = px + s * dx, py + s * dy
            bx, by = ex - dx, ey - dy
            norm = math.sqrt(bx * bx + by * by)
            proj[m, 0], proj[m, 1], proj[m, 2], proj[m, 3] = ax, ay, bx / norm, by / norm
            m += 1
        keep_x, keep_y = res[0], res[1]
        if lp2(proj, m, radius, -dy, dx, True, res) < m:
            res[0], res[1] = keep_x, keep_y  # rounding only: keep the last good point
        worst = det(dx, dy, px - res[0], py - res[1])


lp3: Any = numba.njit(cache=True, nogil=True)(lp3_py)
