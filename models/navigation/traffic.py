"""Traffic rules between robots that see each other only through their lidars.

Hits that no static obstacle explains are other robots or people ("moving points"). Two
rules use them, vectorized over the fleet:

* keep right: a robot with something moving ahead aims to the right of its path, so that
  two robots meeting head-on in an aisle pass each other instead of stalling nose to nose
  (both apply it, so they move apart);
* slow down: a robot's speed is capped by the free distance to the nearest moving thing in
  a cone ahead, as Nav2's collision monitor does with its slowdown zone. The local
  controller plans against a snapshot; a robot crossing from the side is not in it until
  too late, and the cap makes two robots converging at any angle slow down together.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, NamedTuple

import numba
import numpy as np
import numpy.typing as npt

from models.arrays import BoolArray, FloatArray, IntArray


class MovingPoints(NamedTuple):
    """Lidar hits that no static obstacle explains.

    Attributes:
        owner: (k,) the robot that saw each hit.
        points: (k, 2) the hits in ``map`` (m).
        ahead: (k,) x of each hit in its owner's ``base_link`` (m, forward).
        side: (k,) y of each hit in its owner's ``base_link`` (m, left).
    """

    owner: IntArray
    points: FloatArray
    ahead: FloatArray
    side: FloatArray


@dataclass(frozen=True)
class TrafficParams:
    """Parameters of the traffic rules.

    Attributes:
        static_margin_m: a hit within this of a static obstacle belongs to it (m).
        keep_right_range_m: moving things closer than this ahead make a robot keep right (m).
        keep_right_cone: half-width of the keep-right cone per metre ahead.
        keep_right_offset_m: how far right of its carrot the robot aims (m).
        slowdown_cone: half-width growth of the slowdown cone per metre ahead (about +-50
            deg), widened by the footprint so robots driving alongside do not slow down.
        slowdown_range_m: free distance below which a robot slows down (m).
        slowdown_stop_m: free distance at which the cap reaches the crawl speed (m).
        crawl_mps: slowest cap; the local controller still decides to stop (m/s).
    """

    static_margin_m: float = 0.2
    keep_right_range_m: float = 3.0
    keep_right_cone: float = 0.7
    keep_right_offset_m: float = 0.7
    slowdown_cone: float = 1.2
    slowdown_range_m: float = 1.5
    slowdown_stop_m: float = 0.15
    crawl_mps: float = 0.05


def moving_points(
    points: FloatArray,
    start: IntArray,
    poses: FloatArray,
    static_distance_m: npt.NDArray[np.floating],
    origin_xy_m: tuple[float, float],
    resolution_m: float,
    params: TrafficParams,
) -> MovingPoints:
    """The hits that lie away from every static obstacle, in their owners' frames.

    Args:
        points: (m, 2) hits in ``map`` (m), CSR-packed by robot.
        start: (n + 1,) CSR offsets of ``points``.
        poses: (n, 3) robot poses ``x, y, yaw`` in ``map``.
        static_distance_m: (rows, cols) distance to the nearest static obstacle (m), or
            (n, rows, cols): each robot's own (robots planning on their own maps).
        origin_xy_m: ``map`` position of the grid's lower-left corner (m).
        resolution_m: grid cell size (m).
        params: the rules' parameters.
    """
    owner = np.repeat(np.arange(len(start) - 1), np.diff(start))
    grids = static_distance_m if static_distance_m.ndim == 3 else static_distance_m[None]
    yaw = poses[:, 2]
    clear = np.empty(len(points), dtype=np.bool_)
    ahead = np.empty(len(points))
    side = np.empty(len(points))
    count = _moving(
        np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 2),
        owner,
        np.ascontiguousarray(poses[:, 0]),
        np.ascontiguousarray(poses[:, 1]),
        np.cos(yaw),
        np.sin(yaw),
        grids,
        static_distance_m.ndim == 3,
        float(origin_xy_m[0]),
        float(origin_xy_m[1]),
        float(resolution_m),
        # compared in the grid's float type, as numpy compares a float32 grid with a float
        grids.dtype.type(params.static_margin_m),
        clear,
        ahead,
        side,
    )
    return MovingPoints(owner[clear], points[clear], ahead[:count], side[:count])


def _moving_py(
    points: FloatArray,
    owner: IntArray,
    x: FloatArray,
    y: FloatArray,
    cos_yaw: FloatArray,
    sin_yaw: FloatArray,
    grids: npt.NDArray[np.floating],
    per_robot: bool,
    origin_x: float,
    origin_y: float,
    resolution_m: float,
    margin: np.floating,
    clear: BoolArray,
    ahead: FloatArray,
    side: FloatArray,
) -> int:
    rows, cols = grids.shape[1], grids.shape[2]
    k = 0
    for p in range(points.shape[0]):
        ix = np.int64(np.floor((points[p, 0] - origin_x) / resolution_m))
        iy = np.int64(np.floor((points[p, 1] - origin_y) / resolution_m))
        i = owner[p]
        clear[p] = False
        if 0 <= ix < cols and 0 <= iy < rows:
            clear[p] = grids[i if per_robot else 0, iy, ix] > margin
        if clear[p]:
            dx, dy = points[p, 0] - x[i], points[p, 1] - y[i]
            ahead[k] = dx * cos_yaw[i] + dy * sin_yaw[i]
            side[k] = -dx * sin_yaw[i] + dy * cos_yaw[i]
            k += 1
    return k


_moving: Any = numba.njit(cache=True, nogil=True)(_moving_py)


def keep_right(
    carrots: FloatArray,
    moving: MovingPoints,
    poses: FloatArray,
    active: BoolArray,
    params: TrafficParams,
) -> FloatArray:
    """Carrots shifted to the right of the robots that see something moving ahead."""
    owner, _, ahead, side = moving
    front = (ahead > 0) & (ahead < params.keep_right_range_m)
    front &= np.abs(side) < ahead * params.keep_right_cone
    meeting = np.zeros(len(poses), dtype=bool)
    meeting[owner[front]] = True
    meeting &= active
    if not meeting.any():
        return carrots
    shifted = carrots.copy()
    yaw = poses[meeting, 2]
    shifted[meeting, 0] += params.keep_right_offset_m * np.sin(yaw)
    shifted[meeting, 1] -= params.keep_right_offset_m * np.cos(yaw)
    return shifted


def speed_caps(
    moving: MovingPoints,
    robots: int,
    radius_m: float,
    max_speed_mps: float,
    params: TrafficParams,
) -> FloatArray:
    """Forward speed caps (m/s): full speed unless something moving is close ahead."""
    owner, _, ahead, side = moving
    caps = np.full(robots, max_speed_mps)
    front = (ahead > 0) & (np.abs(side) < params.slowdown_cone * ahead + radius_m)
    if not front.any():
        return caps
    distance = np.hypot(ahead[front], side[front]) - radius_m
    nearest = np.full(robots, np.inf)
    np.minimum.at(nearest, owner[front], distance)
    span = params.slowdown_range_m - params.slowdown_stop_m
    scale = np.clip((nearest - params.slowdown_stop_m) / span, 0.0, 1.0)
    capped: FloatArray = np.minimum(caps, np.maximum(scale * max_speed_mps, params.crawl_mps))
    return capped
