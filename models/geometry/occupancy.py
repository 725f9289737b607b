"""Occupancy grids (frame ``map``) and the rasterization of box obstacles into them.

The grid follows ``nav_msgs/OccupancyGrid``: cell values are 0 (free), 100 (occupied) and
-1 (unknown); the array is indexed ``[row, col]`` with row 0 at the lowest y and column 0
at the lowest x; ``origin_xy_m`` is the lower-left corner of cell (0, 0) in ``map``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numba
import numpy as np
import numpy.typing as npt

from models.arrays import FloatArray, IntArray
from models.errors import ModelError

FREE = 0
"""Cell value of a free cell (ROS convention)."""
OCCUPIED = 100
"""Cell value of an occupied cell (ROS convention)."""
UNKNOWN = -1
"""Cell value of an unknown cell (ROS convention)."""

MAX_CELLS = 100_000_000
"""Largest grid :func:`rasterize_boxes` builds (100 MB of int8): a guard against typos."""

_SNAP_CELLS = 1e-6
"""Box edges closer than this (in cells) to a cell boundary are taken to lie on it."""

Int8Array = npt.NDArray[np.int8]


@dataclass(frozen=True, eq=False)
class OccupancyGrid:
    """A 2-D occupancy grid in ``map``, laid out as ``nav_msgs/OccupancyGrid``.

    Attributes:
        resolution_m: cell edge length (m/cell), > 0.
        origin_xy_m: ``map`` position (x, y) of the lower-left corner of cell (0, 0) (m).
        data: (rows, cols) int8 cell values, row 0 at the lowest y: 0 free, 100 occupied,
            -1 unknown. Read-only.
    """

    resolution_m: float
    origin_xy_m: tuple[float, float]
    data: Int8Array

    def __post_init__(self) -> None:
        if not (math.isfinite(self.resolution_m) and self.resolution_m > 0):
            raise ModelError("resolution_m", self.resolution_m, "a finite cell size > 0 (m)")
        if self.data.ndim != 2 or self.data.dtype != np.int8:
            raise ModelError(
                "data", f"{self.data.dtype} array of shape {self.data.shape}", "a 2-D int8 array"
            )
        # a frozen grid must not change under a caller who kept a reference to its array
        data = self.data.copy()
        data.setflags(write=False)
        object.__setattr__(self, "data", data)

    @property
    def width(self) -> int:
        """Number of columns (cells along x)."""
        return int(self.data.shape[1])

    @property
    def height(self) -> int:
        """Number of rows (cells along y)."""
        return int(self.data.shape[0])

    @property
    def extent(self) -> tuple[float, float, float, float]:
        """Area covered in ``map``: xmin, ymin, xmax, ymax (m)."""
        x0, y0 = self.origin_xy_m
        r = self.resolution_m
        return (x0, y0, x0 + self.width * r, y0 + self.height * r)

    def cells_of(self, points: FloatArray) -> tuple[IntArray, IntArray]:
        """Row and column indices of the cells containing ``map`` points (k, 2) in m.

        Indices are not clipped: points outside the grid give indices outside
        ``[0, height) x [0, width)``.
        """
        pts = np.atleast_2d(np.asarray(points, dtype=float))
        cols = np.floor((pts[:, 0] - self.origin_xy_m[0]) / self.resolution_m).astype(np.int64)
        rows = np.floor((pts[:, 1] - self.origin_xy_m[1]) / self.resolution_m).astype(np.int64)
        return rows, cols

    def values_at(self, points: FloatArray) -> Int8Array:
        """Cell values at ``map`` points (k, 2) in m; -1 (unknown) outside the grid."""
        rows, cols = self.cells_of(points)
        inside = (rows >= 0) & (rows < self.height) & (cols >= 0) & (cols < self.width)
        values = np.full(rows.shape, UNKNOWN, dtype=np.int8)
        values[inside] = self.data[rows[inside], cols[inside]]
        return values

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, OccupancyGrid):
            return NotImplemented
        return (
            self.resolution_m == other.resolution_m
            and tuple(self.origin_xy_m) == tuple(other.origin_xy_m)
            and np.array_equal(self.data, other.data)
        )


def _cell_span(
    lo: FloatArray, hi: FloatArray, origin: float, res: float
) -> tuple[IntArray, IntArray]:
    """First and one-past-last cell index whose open interval overlaps ``(lo, hi)``.

    Cell ``i`` spans ``[origin + i*res, origin + (i+1)*res]``; it overlaps with positive
    length iff ``i > lo' - 1`` and ``i < hi'`` where ``lo', hi'`` are in cells.
    """
    lo_c = (lo - origin) / res
    hi_c = (hi - origin) / res
    # decimal box edges on cell boundaries (0.3 m at 0.1 m/cell = 2.9999999999999996)
    # must not spill into the neighbouring cell through binary rounding
    lo_c = np.where(np.abs(lo_c - np.round(lo_c)) < _SNAP_CELLS, np.round(lo_c), lo_c)
    hi_c = np.where(np.abs(hi_c - np.round(hi_c)) < _SNAP_CELLS, np.round(hi_c), hi_c)
    return np.floor(lo_c).astype(np.int64), np.ceil(hi_c).astype(np.int64)


def rasterize_boxes(
    boxes: FloatArray,
    bounds: tuple[float, float, float, float],
    resolution_m: float,
) -> OccupancyGrid:
    """Rasterize axis-aligned boxes into a grid whose known cells are free or occupied.

    Conservative: a cell is occupied when its square overlaps a box with positive area,
    so a box only touching a cell along an edge or at a corner leaves it free.

    Args:
        boxes: (n, 4) boxes ``xmin, ymin, xmax, ymax`` in ``map`` (m).
        bounds: area to cover ``xmin, ymin, xmax, ymax`` in ``map`` (m); the grid origin is
            its lower-left corner and the grid extends up to one cell past its upper edges
            when they do not fall on a cell boundary.
        resolution_m: cell edge length (m/cell).

    Raises:
        ModelError: for a resolution that is not a finite number > 0 or gives more than
            :data:`MAX_CELLS` cells, or for empty bounds.
    """
    if not (math.isfinite(resolution_m) and resolution_m > 0):
        raise ModelError("resolution_m", resolution_m, "a finite cell size > 0 (m)")
    xmin, ymin, xmax, ymax = (float(b) for b in bounds)
    if not (xmax > xmin and ymax > ymin and all(map(math.isfinite, bounds))):
        raise ModelError("bounds", list(bounds), "finite bounds with xmax > xmin, ymax > ymin")
    width_c = (xmax - xmin) / resolution_m
    height_c = (ymax - ymin) / resolution_m
    if width_c * height_c > MAX_CELLS:
        raise ModelError(
            "resolution_m",
            resolution_m,
            f"a cell size giving at most {MAX_CELLS:.0e} cells over "
            f"{xmax - xmin:g} m x {ymax - ymin:g} m",
        )
    # the same snapping as for box edges, so bounds of 30.4 m at 0.1 m give 304 cells
    cols = max(1, math.ceil(width_c - _SNAP_CELLS))
    rows = max(1, math.ceil(height_c - _SNAP_CELLS))
    data = np.zeros((rows, cols), dtype=np.int8)
    b = np.asarray(boxes, dtype=float).reshape(-1, 4)
    if len(b):
        c0, c1 = _cell_span(b[:, 0], b[:, 2], xmin, resolution_m)
        r0, r1 = _cell_span(b[:, 1], b[:, 3], ymin, resolution_m)
        c0, c1 = np.clip(c0, 0, cols), np.clip(c1, 0, cols)
        r0, r1 = np.clip(r0, 0, rows), np.clip(r1, 0, rows)
        # a box without area overlaps nothing with positive area, even off the cell lines
        flat = (b[:, 2] <= b[:, 0]) | (b[:, 3] <= b[:, 1])
        c1 = np.where(flat, c0, c1)
        for i in range(len(b)):
            # one slice assignment per box; an empty slice (degenerate or outside) is a no-op
            data[r0[i] : r1[i], c0[i] : c1[i]] = OCCUPIED
    return OccupancyGrid(resolution_m=resolution_m, origin_xy_m=(xmin, ymin), data=data)


def resample(grid: OccupancyGrid, resolution_m: float) -> OccupancyGrid:
    """The grid at another cell size, keeping obstacles.

    A new cell is occupied when any old cell whose centre it holds is, else free when any
    of them is free, else unknown. The origin stays; the new grid covers the old one.

    Raises:
        ModelError: for a resolution that is not a finite number > 0.
    """
    if not (math.isfinite(resolution_m) and resolution_m > 0):
        raise ModelError("resolution_m", resolution_m, "a finite cell size > 0 (m)")
    rows, cols = grid.data.shape
    ratio = grid.resolution_m / resolution_m
    height, width = _resampled_shape(grid.data.shape, ratio)
    # rank: occupied 2 > free 1 > unknown 0; the highest rank of a cell's sources wins
    rank = np.where(grid.data >= OCCUPIED, 2, np.where(grid.data == FREE, 1, 0)).astype(np.int8)
    k = _block(ratio)
    if k is not None:  # whole blocks of k x k cells: one reshape
        padded = np.zeros((height * k, width * k), dtype=np.int8)
        padded[:rows, :cols] = rank
        best = padded[0::k, 0::k].copy()
        for dy in range(k):
            for dx in range(k):
                np.maximum(best, padded[dy::k, dx::k], out=best)
    else:
        col_of = np.minimum(((np.arange(cols) + 0.5) * ratio).astype(np.int64), width - 1)
        row_of = np.minimum(((np.arange(rows) + 0.5) * ratio).astype(np.int64), height - 1)
        best = np.zeros((height, width), dtype=np.int8)
        np.maximum.at(best, (row_of[:, None], col_of[None, :]), rank)
    data = np.select([best == 2, best == 1], [OCCUPIED, FREE], UNKNOWN).astype(np.int8)
    return OccupancyGrid(resolution_m, grid.origin_xy_m, data)


def _resampled_shape(shape: tuple[int, ...], ratio: float) -> tuple[int, int]:
    """Rows and columns of a grid of ``shape`` resampled by ``ratio`` (old / new cell size)."""
    rows, cols = shape
    return (
        max(1, math.ceil(rows * ratio - _SNAP_CELLS)),
        max(1, math.ceil(cols * ratio - _SNAP_CELLS)),
    )


def _block(ratio: float) -> int | None:
    """The block edge k (cells) when a new cell is exactly k x k old ones, else None."""
    k = round(1.0 / ratio)
    return k if k >= 1 and abs(k * ratio - 1.0) < 1e-9 else None


def resampled_obstacles(
    data: Int8Array, from_resolution_m: float, resolution_m: float
) -> npt.NDArray[np.bool_] | None:
    """The occupied cells of :func:`resample` of a grid's cells, without resampling it.

    A new cell is occupied when any old cell whose centre it holds is (free and unknown
    cells are not told apart). Only when a new cell is exactly k x k old cells, else None
    (then call :func:`resample`).

    Args:
        data: (rows, cols) int8 cell values of the grid, any layout.
        from_resolution_m: the grid's cell size (m/cell).
        resolution_m: the new cell size (m/cell).
    """
    ratio = from_resolution_m / resolution_m
    k = _block(ratio)
    if k is None:
        return None
    height, width = _resampled_shape(data.shape, ratio)
    occupied = np.zeros((height, width), dtype=np.bool_)
    _occupied_blocks(np.ascontiguousarray(data), k, occupied)
    return occupied


def _occupied_blocks_py(data: Int8Array, k: int, occupied: npt.NDArray[np.bool_]) -> None:
    rows = min(data.shape[0], occupied.shape[0] * k)
    cols = min(data.shape[1], occupied.shape[1] * k)
    for r in range(rows):
        for c in range(cols):
            if data[r, c] >= OCCUPIED:
                occupied[r // k, c // k] = True


_occupied_blocks: Any = numba.njit(cache=True, nogil=True)(_occupied_blocks_py)
