"""Observation features of learning agents, for every agent at once (pure numpy).

Frames: ``map`` is the world frame (x east, y north, m); an agent's body frame has x
forward and y to its left (REP 103), its origin at the robot's centre.
"""

from __future__ import annotations

import numpy as np

from models.arrays import FloatArray


def to_body(
    dx_m: FloatArray, dy_m: FloatArray, yaw_rad: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """Offsets in ``map`` turned into each agent's body frame.

    Args:
        dx_m: offsets along x from each agent in ``map`` (m); shape ``(n,)`` or ``(n, k)``.
        dy_m: offsets along y, shaped as ``dx_m`` (m).
        yaw_rad: each agent's heading in ``map`` (rad), shape ``(n,)``.

    Returns:
        The offsets ahead (x) and to the left (y) of each agent (m), shaped as the input.
    """
    c, s = np.cos(yaw_rad), np.sin(yaw_rad)
    if np.ndim(dx_m) == 2:
        c, s = c[:, None], s[:, None]
    return c * dx_m + s * dy_m, -s * dx_m + c * dy_m


def sector_minima(ranges_m: FloatArray, sectors: int) -> FloatArray:
    """The nearest return in each of ``sectors`` equal sectors of every scan.

    Beams are split in order (beam ``i`` goes to sector ``i * sectors // beams``), so with
    a scan from -pi to pi sector 0 is behind the robot on its right. With more sectors
    than beams, a sector without a beam takes the nearest beam's range.

    Args:
        ranges_m: (n, beams) ranges (m), finite.
        sectors: the number of sectors, >= 1.

    Returns:
        (n, sectors) minima (m).
    """
    beams = ranges_m.shape[1]
    if beams == 0:
        raise ValueError("sector_minima needs at least one beam")
    if sectors <= beams:
        edges = (np.arange(sectors) * beams) // sectors
        return np.minimum.reduceat(ranges_m, edges, axis=1)
    nearest = np.minimum((np.arange(sectors) * beams) // sectors, beams - 1)
    return ranges_m[:, nearest]
