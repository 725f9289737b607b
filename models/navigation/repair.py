"""Local path repair: replan only the stretch of a path near the robot.

A robot replans when something moving appears on its path ahead. What changed is local
(the moving things a robot remembers lie within a few metres of it), so instead of
searching the whole floor again, the stretch from the robot to a point ``ahead_m`` along
its path is replanned inside a window around that stretch, and the rest of the path is
kept. This is D* Lite's and Nav2's "replan only what changed" idea reduced to a window:
the repaired path equals a full replan whenever the best detour stays inside the window
(and both pass the moving things the same way); when no path exists inside it, the
caller replans in full. On the 100 m x 100 m floor a full replan copies and searches
10^6 cells; a repair a few thousand.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from models.arrays import FloatArray, IntArray, UInt8Array
from models.errors import ModelError
from models.navigation.costmap import StaticCostmap, with_obstacles
from models.navigation.planner import plan, prune_path


@dataclass(frozen=True)
class RepairParams:
    """How far a repair reaches.

    Attributes:
        ahead_m: the repaired stretch ends this far along the path from the robot's
            projection on it (m), or at the path's end if nearer.
        margin_m: the window reaches this far beyond the stretch on every side (m).
    """

    ahead_m: float = 8.0
    margin_m: float = 3.0

    def __post_init__(self) -> None:
        for name in ("ahead_m", "margin_m"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ModelError(f"repair.{name}", value, "a finite distance > 0 (m)")


@dataclass(frozen=True, eq=False)
class Repair:
    """A repaired path.

    Attributes:
        waypoints: (k, 2) the whole new path in ``map`` (m): the repaired stretch, then
            the kept rest of the old path.
        length_m: its length from the robot's cell centre to the end (m).
        window: the cells ``(ix0, iy0, ix1, iy1)`` searched (half-open).
    """

    waypoints: FloatArray
    length_m: float
    window: tuple[int, int, int, int]


def split_ahead(
    waypoints: FloatArray, segment: int, xy: FloatArray, ahead_m: float
) -> tuple[FloatArray, FloatArray]:
    """Cut a path ``ahead_m`` along it from a point's projection on segment ``segment``.

    Args:
        waypoints: (k, 2) the path in ``map`` (m), k >= 2.
        segment: the segment the point projects on (waypoints ``segment`` to ``segment+1``).
        xy: the point (m), e.g. the robot's position.
        ahead_m: distance along the path from the projection (m).

    Returns:
        ``(stretch, rest)``: the projection, the waypoints passed and the cut point; and
        the cut point followed by the remaining waypoints (just the cut point when the
        path ends within ``ahead_m``).
    """
    a, b = waypoints[segment], waypoints[segment + 1]
    e = b - a
    ll = float(e @ e)
    t = 0.0 if ll == 0.0 else min(max(float((xy - a) @ e) / ll, 0.0), 1.0)
    here = a + t * e
    stretch = [here]
    left = ahead_m
    point = here
    for k in range(segment + 1, len(waypoints)):
        nxt = waypoints[k]
        step = float(np.hypot(*(nxt - point)))
        if step >= left:
            cut = point + (nxt - point) * (left / step if step > 0 else 0.0)
            stretch.append(cut)
            return np.array(stretch), np.vstack([cut, waypoints[k:]])
        left -= step
        stretch.append(nxt)
        point = nxt
    return np.array(stretch), np.array([waypoints[-1]])


WindowSearch = Callable[
    [UInt8Array, tuple[int, int], tuple[int, int], float, "UInt8Array | None", float],
    "IntArray | None",
]
"""A search inside a repair's window: ``(cost, start, goal, resolution_m, lanes, against)``
to the path's cells ``(k, 2)`` ``ix, iy`` in the window (start first, goal last, corners
only), or None when it finds none. The window's own costs, lanes and cell coordinates."""


def astar_cells(
    cost: UInt8Array,
    start: tuple[int, int],
    goal: tuple[int, int],
    resolution_m: float,
    lanes: UInt8Array | None,
    against: float,
) -> IntArray | None:
    """A* in the window (:func:`models.navigation.planner.plan`), pruned to its corners."""
    result = plan(cost, start, goal, resolution_m=resolution_m, lanes=lanes, against=against)
    return prune_path(cost, result.cells) if result.found else None


def repair_path(
    static: StaticCostmap,
    points_xy: FloatArray,
    discs: FloatArray | None,
    waypoints: FloatArray,
    segment: int,
    start_xy: FloatArray,
    params: RepairParams,
    *,
    lanes: UInt8Array | None = None,
    against: float = 1.0,
    search: WindowSearch = astar_cells,
) -> Repair | None:
    """Replan the stretch of a path ahead of the robot inside a window around it.

    Args:
        static: the static costmap the path was planned on.
        points_xy: (m, 2) moving obstacle points in ``map`` (m), stamped as in a full plan.
        discs: optional (q, 3) discs ``x, y, radius`` (m) stamped as in a full plan.
        waypoints: (k, 2) the current path (m), k >= 2.
        segment: the segment of the path the robot is on.
        start_xy: the robot's position (m).
        params: the repair's reach.
        lanes: optional one-way directions of the grid's cells, as for
            :func:`models.navigation.planner.plan`.
        against: cost factor of a step against a lane.
        search: the search inside the window (A* by default; a planner plugs in its own).

    Returns:
        The repaired path, or None when no path inside the window reaches the cut point
        (the caller then replans in full).
    """
    stretch, rest = split_ahead(waypoints, segment, start_xy, params.ahead_m)
    res = static.resolution_m
    corners = np.vstack([stretch, np.asarray(start_xy, dtype=float)[None, :2]])
    origin = np.asarray(static.origin_xy_m)
    lo = np.floor((corners.min(axis=0) - params.margin_m - origin) / res).astype(int)
    hi = np.floor((corners.max(axis=0) + params.margin_m - origin) / res).astype(int) + 1
    ix0, iy0 = max(int(lo[0]), 0), max(int(lo[1]), 0)
    ix1, iy1 = min(int(hi[0]), static.width), min(int(hi[1]), static.height)
    s_cell = static.world_to_cell(start_xy)
    g_cell = static.world_to_cell(rest[0])
    inside = all(ix0 <= c[0] < ix1 and iy0 <= c[1] < iy1 for c in (s_cell, g_cell))
    if not inside:
        return None
    window = (ix0, iy0, ix1, iy1)
    cost = with_obstacles(static, points_xy, discs=discs, window=window)
    local = (s_cell[0] - ix0, s_cell[1] - iy0), (g_cell[0] - ix0, g_cell[1] - iy0)
    window_lanes = None if lanes is None else lanes[iy0:iy1, ix0:ix1]
    found = search(cost, local[0], local[1], res, window_lanes, against)
    if found is None:
        return None
    cells = found + np.array([ix0, iy0])
    head = origin + (cells + 0.5) * res
    head[-1] = rest[0]
    tail = rest[1:]
    new = np.vstack([head, tail])
    # a cut on a waypoint (or a robot repairing from where it stands) repeats a point:
    # zero-length segments would hide the path ahead from the follower's projection
    new = new[np.r_[True, (np.diff(new, axis=0) != 0).any(axis=1)]]
    length = float(np.hypot(*np.diff(new, axis=0).T).sum())
    return Repair(new, length, window)


__all__ = ["Repair", "RepairParams", "WindowSearch", "astar_cells", "repair_path", "split_ahead"]
