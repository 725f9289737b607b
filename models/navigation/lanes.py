"""One-way aisles: a direction for every narrow aisle, derived from the static map.

Two robots meeting head-on in an aisle that is too narrow to pass comfortably stall nose
to nose, and their replans push each other into ever longer detours. Warehouses with
AGVs avoid it with one-way aisles: fleet managers draw directed lanes on the building's
map (Open-RMF's traffic editor marks each lane bidirectional or not; Digani et al.,
"Ensemble coordination approach in multi-AGV systems applied to industrial warehouses",
IEEE T-ASE 12(3), 2015, route AGVs on a directed roadmap of the aisles). Here the lanes
are derived from the map: a free cell lies in a narrow aisle when the free run across it
(in a column for an aisle along x, in a row for one along y) is at most ``max_width_m``
and the run along it is longer. Neighbouring parallel aisles alternate direction: the
direction of an aisle along x is +x when an even number of obstacles lie below it in its
column, -x otherwise (and +y/-y by the obstacles to its left for aisles along y), so on
a floor of racks in rows each aisle flows opposite to the next, as a road network's
alternating one-way streets do. Junctions and open floor stay two-way.

The planner charges a step against a cell's lane ``penalty`` times more
(:func:`models.navigation.planner.plan`), so paths follow the lanes unless the way round
is far longer. Cells are ``[iy, ix]`` as in the costmaps.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from models.arrays import UInt8Array
from models.errors import ModelError

TWO_WAY = 0
"""A cell without a direction."""
EAST = 1
"""An aisle along x, driven towards +x."""
WEST = 2
"""An aisle along x, driven towards -x."""
NORTH = 3
"""An aisle along y, driven towards +y."""
SOUTH = 4
"""An aisle along y, driven towards -y."""

BoolArray = npt.NDArray[np.bool_]
IntArray = npt.NDArray[np.int64]


def _runs(obstacle: BoolArray) -> tuple[IntArray, IntArray]:
    """Free run length through each cell along axis 0, and obstacle runs before it.

    Returns:
        ``(length, before)``: per cell the number of consecutive free cells in its column
        containing it (0 on obstacles), and the number of obstacle runs below it.
    """
    rows = obstacle.shape[0]
    index = np.arange(rows)[:, None]
    below = np.maximum.accumulate(np.where(obstacle, index, -1), axis=0)
    above = np.minimum.accumulate(np.where(obstacle, index, rows)[::-1], axis=0)[::-1]
    length = np.where(obstacle, 0, above - below - 1)
    starts = obstacle & ~np.vstack([np.zeros((1, obstacle.shape[1]), dtype=bool), obstacle[:-1]])
    before = np.cumsum(starts, axis=0)
    return length, before


def aisle_lanes(obstacle: BoolArray, resolution_m: float, max_width_m: float) -> UInt8Array:
    """The one-way direction of every cell in a narrow aisle.

    Args:
        obstacle: (rows, cols) static obstacle cells, ``[iy, ix]``, row 0 at the lowest y.
        resolution_m: cell size (m).
        max_width_m: widest aisle made one-way (m): wider ones let robots pass each other.

    Returns:
        (rows, cols) uint8: :data:`EAST`, :data:`WEST`, :data:`NORTH`, :data:`SOUTH` or
        :data:`TWO_WAY`.

    Raises:
        ModelError: for a resolution or width that is not a positive finite distance.
    """
    for name, value in (("resolution_m", resolution_m), ("max_width_m", max_width_m)):
        if not (np.isfinite(value) and value > 0):
            raise ModelError(name, value, "a finite distance > 0 (m)")
    obstacle = np.asarray(obstacle, dtype=bool)
    across_x, below = _runs(obstacle)  # runs in each column: an aisle along x is narrow
    across_y_t, left_t = _runs(obstacle.T)
    across_y, left = across_y_t.T, left_t.T
    widest = int(np.floor(max_width_m / resolution_m + 1e-9))
    free = ~obstacle
    along_x = free & (across_x <= widest) & (across_y > across_x)
    along_y = free & (across_y <= widest) & (across_x > across_y)
    lanes = np.full(obstacle.shape, TWO_WAY, dtype=np.uint8)
    lanes[along_x] = np.where(below[along_x] % 2 == 0, EAST, WEST)
    lanes[along_y] = np.where(left[along_y] % 2 == 0, NORTH, SOUTH)
    return lanes


def in_lanes(
    lanes: UInt8Array,
    points: npt.NDArray[np.float64],
    origin_xy_m: tuple[float, float],
    cell_m: float,
) -> npt.NDArray[np.bool_]:
    """Which (x, y) points (m, the grid's frame) lie in a one-way cell of ``lanes``.

    Args:
        lanes: (rows, cols) lane directions (``TWO_WAY`` where none).
        points: (k, 2) points (m).
        origin_xy_m: the grid's lower-left corner (m).
        cell_m: cell size (m).

    Returns:
        (k,) True where the point's cell is one-way; points off the grid are not.
    """
    cells = np.floor((points - np.asarray(origin_xy_m)) / cell_m).astype(np.int64)
    rows, cols = lanes.shape
    inside = (cells[:, 0] >= 0) & (cells[:, 0] < cols) & (cells[:, 1] >= 0) & (cells[:, 1] < rows)
    out = np.zeros(len(points), dtype=bool)
    out[inside] = lanes[cells[inside, 1], cells[inside, 0]] != TWO_WAY
    return out


__all__ = ["EAST", "NORTH", "SOUTH", "TWO_WAY", "WEST", "aisle_lanes", "in_lanes"]
