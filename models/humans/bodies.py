"""Bodies of SUMO's movers as the discs that lidars and collision checks see (frame ``map``).

SUMO reports a vehicle's position at the centre of its front bumper. A forklift's body,
``length x width``, is covered exactly by two discs: one per half, each centred in its half
with the half's half-diagonal as radius.
"""

from __future__ import annotations

import numpy as np

from models.arrays import FloatArray
from models.world.warehouse import box_distance


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


def push_out(points: FloatArray, radius_m: float, boxes: FloatArray) -> tuple[FloatArray, int]:
    """Discs of ``radius_m`` at ``points`` (n, 2) moved out of the boxes (k, 4) they overlap.

    SUMO's pedestrians keep to their lane, whose edge may run along a shelf's face; a
    person there would reach into the shelf. Each overlapping disc is moved straight away
    from the nearest point of the nearest box (out through the nearest face when its centre
    is inside) until it just touches it. One box at a time: a disc pushed into another box
    stays there (aisles are wider than a person).

    Returns:
        The moved points (a new array) and how many were moved.
    """
    pts = np.array(points, dtype=float).reshape(-1, 2)
    if len(pts) == 0 or len(boxes) == 0:
        return pts, 0
    gap = box_distance(pts, boxes)
    nearest = gap.argmin(axis=1)
    rows = np.flatnonzero(gap[np.arange(len(pts)), nearest] < radius_m)
    for i in rows.tolist():
        x0, y0, x1, y1 = boxes[nearest[i]]
        px, py = pts[i]
        cx, cy = min(max(px, x0), x1), min(max(py, y0), y1)
        if (cx, cy) == (px, py):  # centre inside: out through the nearest face
            faces = np.array([px - x0, x1 - px, py - y0, y1 - py])
            k = int(faces.argmin())
            direction = [(-1.0, 0.0), (1.0, 0.0), (0.0, -1.0), (0.0, 1.0)][k]
            cx, cy = [(x0, py), (x1, py), (px, y0), (px, y1)][k]
        else:
            d = float(np.hypot(px - cx, py - cy))
            direction = ((px - cx) / d, (py - cy) / d)
        pts[i] = (cx + direction[0] * radius_m, cy + direction[1] * radius_m)
    return pts, len(rows)
