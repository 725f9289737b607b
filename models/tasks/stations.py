"""Pick stations: where a robot stands to serve a shelf.

A station faces the middle of a shelf's long side, ``offset_m`` of free space between the
robot's footprint and the shelf face (frame ``map``). Its footprint also keeps
:data:`CLEARANCE_M` from everything else: a station squeezed between its shelf and a wall
(in ``lab-mixed`` seed 2, 1.5 cm to spare) is on the costmap's free side but out of reach
of a controller that keeps a margin (``orca`` stood 30 s short of it, alone in the room),
so it is dropped.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import numpy.typing as npt

from models.arrays import FloatArray

CLEARANCE_M = 0.05
"""Least free space between a station's footprint and any obstacle but its shelf (m)."""


def pick_stations(
    shelves: FloatArray,
    radius_m: float,
    offset_m: float,
    is_free: Callable[[FloatArray, float], npt.NDArray[np.bool_]],
) -> FloatArray:
    """Stations on both long sides of every shelf.

    Args:
        shelves: (n, 4) shelf boxes ``xmin, ymin, xmax, ymax`` in ``map`` (m).
        radius_m: robot footprint radius (m).
        offset_m: free space between the footprint and the shelf face (m).
        is_free: tells for (k, 2) points and a clearance (m) whether a disc of that
            radius at each point is clear of every obstacle.

    Returns:
        (k, 3) stations ``x_m, y_m, yaw_rad`` (the heading faces the shelf), in shelf order.
    """
    out: list[tuple[float, float, float]] = []
    gap = radius_m + offset_m
    for xmin, ymin, xmax, ymax in np.asarray(shelves, dtype=float).reshape(-1, 4):
        cx, cy = (xmin + xmax) / 2, (ymin + ymax) / 2
        if xmax - xmin >= ymax - ymin:  # long sides face south and north
            candidates = [(cx, ymin - gap, np.pi / 2), (cx, ymax + gap, -np.pi / 2)]
        else:
            candidates = [(xmin - gap, cy, 0.0), (xmax + gap, cy, np.pi)]
        out.extend(candidates)
    stations = np.array(out, dtype=float).reshape(-1, 3)
    if not len(stations):
        return stations
    # the own shelf face is ``offset_m`` from the footprint: never in the way of the test
    return stations[is_free(stations[:, :2], radius_m + min(CLEARANCE_M, 0.5 * offset_m))]


def clear_of(stations: FloatArray, taken: FloatArray, gap_m: float) -> npt.NDArray[np.bool_]:
    """Which stations are at least ``gap_m`` from every taken one (and not one of them).

    Two robots serving stations closer than their two radii plus the free space would
    stand in each other's way, so such stations never have open tasks at the same time.

    Args:
        stations: (k, 2+) stations, ``x_m, y_m`` first, in ``map``.
        taken: (m, 2) stations of the open tasks, in ``map``.
        gap_m: least distance between two stations with open tasks (m).

    Returns:
        (k,) true where a task may open.
    """
    xy = np.asarray(stations, dtype=float).reshape(len(stations), -1)[:, :2]
    used = np.asarray(taken, dtype=float).reshape(-1, 2)
    if not len(used):
        return np.ones(len(xy), dtype=bool)
    d = np.hypot(xy[:, None, 0] - used[None, :, 0], xy[:, None, 1] - used[None, :, 1])
    ok: npt.NDArray[np.bool_] = d.min(axis=1) >= gap_m
    return ok
