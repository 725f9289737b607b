"""How sure a scan match is: the covariance of its response around the best pose.

A match's score says how well a scan fits; it does not say in which directions the fit is
certain. Down a corridor the scan fits equally well a metre further on, and the best pose
along it is chance. Following Olson ("Real-time correlative scan matching", ICRA 2009,
section IV-C) and Karto's ``ComputePositionalCovariance``, the scores of the poses around
the best are read as a distribution: the poses that score within ``delta`` of the best
weigh by their score, and their spread is the match's covariance. A corridor gives a long
thin ellipse along it; a corner, a small round one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numba
import numpy as np

from models.arrays import FloatArray
from models.geometry.se2 import Pose
from models.mapping.grid import LogOddsMap


@dataclass(frozen=True)
class ResponseWindow:
    """Where the response is read, and what counts as near the best.

    Attributes:
        half_cells: translations up to this many cells each way (the window is square).
        rotation_steps: rotations up to this many steps each way.
        rotation_step_rad: the step between rotations (rad).
        delta: poses scoring at least the best minus this take part.
        floor_m: a translational standard deviation never below this (m): cells are
            discrete.
        floor_rad: a rotational standard deviation never below this (rad).
    """

    half_cells: int = 12
    rotation_steps: int = 6
    rotation_step_rad: float = 0.01
    delta: float = 0.05
    floor_m: float = 0.02
    floor_rad: float = 0.005


def match_covariance(
    grid: LogOddsMap, pose: Pose, points: FloatArray, window: ResponseWindow
) -> FloatArray:
    """The 3 x 3 covariance (x m, y m, yaw rad; ``map`` axes) of a match at ``pose``.

    Args:
        grid: the map the scan was matched against.
        pose: the best pose found (``map``).
        points: the scan's points in the sensor frame (m), as matched.
        window: the window of poses read.
    """
    g = grid.geometry
    res = g.resolution_m
    response = _response(
        grid.score,
        g.origin_xy_m[0],
        g.origin_xy_m[1],
        res,
        np.ascontiguousarray(points[:, 0]),
        np.ascontiguousarray(points[:, 1]),
        float(pose[0]),
        float(pose[1]),
        float(pose[2]),
        window.half_cells,
        window.rotation_steps,
        window.rotation_step_rad,
    )
    best = float(response.max())
    a, j, i = np.nonzero(response >= best - window.delta)
    weights = response[a, j, i]
    offsets = np.stack(
        [
            (i - window.half_cells) * res,
            (j - window.half_cells) * res,
            (a - window.rotation_steps) * window.rotation_step_rad,
        ],
        axis=1,
    )
    total = float(weights.sum())
    if total <= 0:
        spread = np.diag([window.half_cells * res, window.half_cells * res, 1.0]) ** 2
        return np.asarray(spread, dtype=np.float64)
    mean = (weights[:, None] * offsets).sum(axis=0) / total
    centred = offsets - mean
    covariance: FloatArray = np.einsum("k,ki,kj->ij", weights, centred, centred) / total
    covariance += np.diag([window.floor_m**2, window.floor_m**2, window.floor_rad**2])
    return covariance


def _response_py(
    score: Any,
    ox: float,
    oy: float,
    res: float,
    px: Any,
    py: Any,
    x0: float,
    y0: float,
    yaw0: float,
    half: int,
    rot_half: int,
    rot_step: float,
) -> Any:
    """Mean fine score of the points at every pose of the window (rotation, y, x)."""
    height, width = score.shape
    n = px.shape[0]
    out = np.zeros((2 * rot_half + 1, 2 * half + 1, 2 * half + 1))
    if n == 0:
        return out
    for a in range(2 * rot_half + 1):
        yaw = yaw0 + (a - rot_half) * rot_step
        c = math.cos(yaw)
        s = math.sin(yaw)
        for k in range(n):
            wx = c * px[k] - s * py[k]
            wy = s * px[k] + c * py[k]
            bx = math.floor((x0 + wx - ox) / res) - half
            by = math.floor((y0 + wy - oy) / res) - half
            for j in range(2 * half + 1):
                cy = by + j
                if cy < 0 or cy >= height:
                    continue
                for i in range(2 * half + 1):
                    cx = bx + i
                    if 0 <= cx < width:
                        out[a, j, i] += score[cy, cx]
    return out / (255.0 * n)


_response: Any = numba.njit(cache=True, nogil=True)(_response_py)
