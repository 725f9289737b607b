"""Nav2's cost values and the compiled inner loops of the costmaps.

The costmap's arithmetic (:mod:`models.navigation.costmap`) runs here, compiled by numba:
stamping inflated obstacles (taking the maximum with a kernel, unknown below any known
cost), the squared Euclidean distance transform of an obstacle grid (Felzenszwalb and
Huttenlocher's lower envelope of parabolas, one pass per axis), and turning distances into
costs through a table.
"""

from __future__ import annotations

import math
from typing import Any

import numba
import numpy as np
import numpy.typing as npt

from models.arrays import FloatArray, IntArray, UInt8Array

LETHAL = 254
"""Cost of a cell holding an obstacle (Nav2 ``LETHAL_OBSTACLE``)."""
INSCRIBED = 253
"""Cost of a cell whose centre is within the robot radius of an obstacle (Nav2)."""
MAX_NON_OBSTACLE = 252
"""Highest cost a robot centre may occupy without touching anything (Nav2)."""
NO_INFORMATION = 255
"""Cost of an unknown cell (Nav2 ``NO_INFORMATION``)."""
FREE = 0
"""Cost of a cell beyond the inflation radius of every obstacle (Nav2 ``FREE_SPACE``)."""

_RADIUS_TOL_M = 1e-9
"""Tolerance (m) on radius comparisons, so cells exactly on a radius count as inside."""

Float32Array = npt.NDArray[np.float32]


def _combine_py(old: np.uint8, new: np.uint8) -> np.uint8:
    """The stamped value of a cell: the max, but unknown only yields to 253 and 254.

    Written as selects without branches, so that stamping loops vectorize.
    """
    higher = max(old, new)
    known = new if new >= np.uint8(INSCRIBED) else old
    return known if old == np.uint8(NO_INFORMATION) else higher


def _stamp_points_py(cost: UInt8Array, cells: IntArray, kernel: UInt8Array) -> None:
    height, width = cost.shape
    size = kernel.shape[0]
    k = size // 2
    # the kernel is a disc: stamp only each row's nonzero span
    lo = np.full(size, size, dtype=np.int64)
    hi = np.zeros(size, dtype=np.int64)
    for ky in range(size):
        for kx in range(size):
            if kernel[ky, kx] != 0:
                lo[ky] = min(lo[ky], kx)
                hi[ky] = kx + 1
    for p in range(cells.shape[0]):
        cx, cy = cells[p, 0], cells[p, 1]
        if cx < -k or cy < -k or cx >= width + k or cy >= height + k:
            continue
        for ky in range(max(0, k - cy), min(size, height + k - cy)):
            x0 = max(lo[ky], k - cx)
            x1 = min(hi[ky], width + k - cx)
            row = cost[cy - k + ky, cx - k + x0 : cx - k + x1]
            stamp = kernel[ky, x0:x1]
            for j in range(x1 - x0):
                row[j] = _combine(row[j], stamp[j])


def _stamp_discs_py(
    cost: UInt8Array,
    discs: FloatArray,
    origin_x: float,
    origin_y: float,
    res: float,
    robot_r: float,
    reach_m: float,
    scaling: float,
    ox: int,
    oy: int,
) -> None:
    # ``cost`` is the window of the grid whose cell (0, 0) is the grid's (ox, oy); cell
    # centres are computed in grid cells, so a window's stamp equals the grid's there
    height, width = cost.shape
    tol = _RADIUS_TOL_M
    for q in range(discs.shape[0]):
        px, py, pr = discs[q, 0], discs[q, 1], discs[q, 2]
        ccx = math.floor((px - origin_x) / res)
        ccy = math.floor((py - origin_y) / res)
        span = pr + reach_m + res
        x0 = max(ox, math.floor((px - span - origin_x) / res))
        x1 = min(ox + width - 1, math.floor((px + span - origin_x) / res))
        y0 = max(oy, math.floor((py - span - origin_y) / res))
        y1 = min(oy + height - 1, math.floor((py + span - origin_y) / res))
        for iy in range(y0, y1 + 1):
            dy = origin_y + (iy + 0.5) * res - py
            for ix in range(x0, x1 + 1):
                dx = origin_x + (ix + 0.5) * res - px
                d = math.sqrt(dx * dx + dy * dy) - pr
                if d <= tol or (ix == ccx and iy == ccy):
                    v = LETHAL
                elif d <= robot_r + tol:
                    v = INSCRIBED
                elif d <= reach_m + tol:
                    v = math.floor(MAX_NON_OBSTACLE * math.exp(-scaling * (d - robot_r)))
                else:
                    continue
                if v != 0:
                    cost[iy - oy, ix - ox] = _combine(cost[iy - oy, ix - ox], np.uint8(v))


def _squared_edt_py(obstacle: Any, d2: Any) -> None:
    """Squared distances (cells^2) from each cell centre to the nearest obstacle cell centre.

    Exact, in integers: a vertical pass, then per row the lower envelope of the parabolas
    ``(x - q)^2 + g(q)^2`` (Felzenszwalb and Huttenlocher 2012) with the intersections of
    two parabolas compared as fractions, never rounded. ``-1`` when there is no obstacle.
    """
    rows, cols = obstacle.shape
    far = rows + 1  # no obstacle in the column: longer than any vertical distance
    g = np.empty((rows, cols), dtype=np.int64)  # vertical distance, row by row (cache order)
    for c in range(cols):
        g[0, c] = 0 if obstacle[0, c] else far
    for r in range(1, rows):
        for c in range(cols):
            g[r, c] = 0 if obstacle[r, c] else min(g[r - 1, c] + 1, far)
    for r in range(rows - 2, -1, -1):
        for c in range(cols):
            g[r, c] = min(g[r, c], g[r + 1, c] + 1)
    v = np.empty(cols, dtype=np.int64)  # columns of the envelope's parabolas
    f = np.empty(cols, dtype=np.int64)  # their heights g^2
    h = np.empty(cols, dtype=np.int64)  # g^2 + v^2
    zn = np.empty(cols, dtype=np.int64)  # where each starts: zn / zd (zd > 0)
    zd = np.empty(cols, dtype=np.int64)
    for r in range(rows):
        k = -1
        for q in range(cols):
            gq = g[r, q]
            if gq >= far:
                continue
            hq = gq * gq + q * q
            sn = 0
            sd = 1
            while k >= 0:
                # parabola q lies below parabola v[k] from sn / sd on
                sn = hq - h[k]
                sd = 2 * (q - v[k])
                if k > 0 and sn * zd[k] <= zn[k] * sd:
                    k -= 1
                else:
                    break
            k += 1
            v[k] = q
            f[k] = gq * gq
            h[k] = hq
            zn[k] = sn
            zd[k] = sd
        if k < 0:
            for c in range(cols):
                d2[r, c] = -1
            continue
        j = 0
        for c in range(cols):
            while j < k and zn[j + 1] < c * zd[j + 1]:
                j += 1
            dc = c - v[j]
            d2[r, c] = dc * dc + f[j]


def _costs_of_py(d2: Any, resolution_m: float, table: Any, distance: Any, cost: Any) -> None:
    """Distances (m, float32) and costs (by squared distance from ``table``) of every cell."""
    rows, cols = d2.shape
    size = table.shape[0]
    for r in range(rows):
        for c in range(cols):
            e = d2[r, c]
            if e < 0:
                distance[r, c] = np.inf
                cost[r, c] = 0
            else:
                # scipy's arithmetic: the square root of the integer sum, then the scale
                distance[r, c] = math.sqrt(float(e)) * resolution_m
                cost[r, c] = table[e] if e < size else 0


_combine: Any = numba.njit(cache=True, nogil=True)(_combine_py)
_stamp_points: Any = numba.njit(cache=True, nogil=True)(_stamp_points_py)
_stamp_discs: Any = numba.njit(cache=True, nogil=True)(_stamp_discs_py)
_squared_edt: Any = numba.njit(cache=True, nogil=True)(_squared_edt_py)
_costs_of: Any = numba.njit(cache=True, nogil=True)(_costs_of_py)
