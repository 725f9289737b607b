"""Bodies of SUMO's movers as the discs that lidars and collision checks see (frame ``map``).

SUMO reports a vehicle's position at the centre of its front bumper. A forklift's body,
``length x width``, is covered exactly by two discs: one per half, each centred in its half
with the half's half-diagonal as radius.
"""

from __future__ import annotations

import numpy as np

from models.arrays import FloatArray


def vehicle_centres(
    front_x_m: FloatArray, front_y_m: FloatArray, yaw_rad: FloatArray, length_m: float
) -> tuple[FloatArray, FloatArray]:
    """Body centres (m) of vehicles whose front-bumper centres and headings are given."""
    cx: FloatArray = front_x_m - np.cos(yaw_rad) * length_m / 2
    cy: FloatArray = front_y_m - np.sin(yaw_rad) * length_m / 2
    return cx, cy


def two_disc_cover(
    cx_m: FloatArray, cy_m: FloatArray, yaw_rad: FloatArray, length_m: float, width_m: float
) -> FloatArray:
    """(2n, 3) discs ``x, y, radius`` covering n rectangles: all front halves, then rears."""
    radius = float(np.hypot(length_m / 4, width_m / 2))
    dx = np.cos(yaw_rad) * length_m / 4
    dy = np.sin(yaw_rad) * length_m / 4
    n = len(cx_m)
    front = np.column_stack([cx_m + dx, cy_m + dy, np.full(n, radius)])
    rear = np.column_stack([cx_m - dx, cy_m - dy, np.full(n, radius)])
    return np.vstack([front, rear])
