"""Pick stations: where a robot stands to serve a shelf.

A station faces the middle of a shelf's long side, ``offset_m`` of free space between the
robot's footprint and the shelf face (frame ``map``). Stations a robot could not stand at
(another shelf, a wall, an obstacle too close) are dropped.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import numpy.typing as npt

from models.arrays import FloatArray


def pick_stations(
    shelves: FloatArray,
    radius_m: float,
    offset_m: float,
    is_free: Callable[[FloatArray], npt.NDArray[np.bool_]],
) -> FloatArray:
    """Stations on both long sides of every shelf.

    Args:
        shelves: (n, 4) shelf boxes ``xmin, ymin, xmax, ymax`` in ``map`` (m).
        radius_m: robot footprint radius (m).
        offset_m: free space between the footprint and the shelf face (m).
        is_free: tells for (k, 2) points whether a robot can stand there.

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
    return stations[is_free(stations[:, :2])]
