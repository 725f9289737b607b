"""A log-odds occupancy grid built from range scans, with the score grids scan matching reads.

Cells hold the log-odds ``l = log(p / (1 - p))`` of being occupied, starting at 0 (p = 0.5,
unknown). A scan adds ``hit`` to the cell of every return and ``miss`` to every cell its
beam crosses before (each cell at most once per scan, a return winning over a crossing,
as OctoMap does), clamped to ``[clamp_min, clamp_max]``. Hit and clamping are OctoMap's
(Hornung et al., Autonomous Robots 34(3), 2013: hit 0.7, clamping 0.12/0.97); the miss is
weak, 0.48, as Cartographer's 0.49: long beams grazing a wall cross its cells far more
often than they end in them, and OctoMap's 0.4 erased the walls of a real building (the
ACES recording: walls gone, scan matching lost, 1.6 m trajectory error against 0.23 m).
A cell is occupied at p >= 0.65 (map_server's threshold) and free at p <= 0.35.

Beside the log-odds, the grid keeps what the correlative matcher scores against (Olson,
"Real-time correlative scan matching", ICRA 2009): a fine score per cell, 255 on an
occupied cell and falling off as a Gaussian of the distance to the nearest occupied cell,
and a coarse score, the maximum of the fine score over the ``COARSE`` x ``COARSE`` cells
whose lower-left corner is that cell, an upper bound for branch and bound. Both are kept
up to date cell by cell as cells become occupied or stop being so, never rebuilt.

Frame ``map``; arrays are indexed ``[iy, ix]`` with row 0 at the lowest y, as
:class:`models.geometry.occupancy.OccupancyGrid`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from models.arrays import FloatArray
from models.errors import ModelError
from models.geometry.occupancy import FREE, OCCUPIED, UNKNOWN, OccupancyGrid
from models.mapping.kernels import apply, classify, rebuild_scores, refresh_scores, traverse

COARSE = 4
"""Cells per side of the coarse score's window (the matcher's first level)."""
SCORE_REACH = 2.5
"""An occupied cell raises the fine score out to this many Gaussian widths."""
MAX_CELLS = 25_000_000
"""Largest map built (100 MB of float32 log-odds): a guard against a typo in a size."""


def logit(p: float) -> float:
    """Log-odds of a probability in (0, 1)."""
    return math.log(p / (1.0 - p))


@dataclass(frozen=True)
class LogOddsParams:
    """How scans change cells, and when a cell counts as occupied or free.

    Attributes:
        hit: log-odds added to a cell holding a return.
        miss: log-odds added to a cell a beam crosses (negative).
        clamp_min, clamp_max: bounds of a cell's log-odds.
        occupied: log-odds from which a cell is occupied.
        free: log-odds up to which a cell is free; between the two it is unknown.
        score_sigma_cells: width of the fine score's Gaussian (cells): 1.5 cells (7.5 cm
            at 5 cm) gives the refinement a slope to climb over a cell and a half, and
            made the ACES trajectory error steadier across settings than 1 cell.
    """

    hit: float = logit(0.7)
    miss: float = logit(0.48)
    clamp_min: float = logit(0.12)
    clamp_max: float = logit(0.97)
    occupied: float = logit(0.65)
    free: float = logit(0.35)
    score_sigma_cells: float = 1.5

    def __post_init__(self) -> None:
        if not (self.hit > 0 > self.miss):
            raise ModelError("mapping.hit/miss", (self.hit, self.miss), "hit > 0 > miss")
        if not (self.clamp_min <= self.free < self.occupied <= self.clamp_max):
            raise ModelError(
                "mapping thresholds",
                (self.clamp_min, self.free, self.occupied, self.clamp_max),
                "clamp_min <= free < occupied <= clamp_max",
            )


@dataclass(frozen=True)
class MapGeometry:
    """Where the grid lies in ``map``.

    Attributes:
        origin_xy_m: ``map`` position of the lower-left corner of cell (0, 0) (m).
        resolution_m: cell edge (m).
        width, height: cells along x and y.
    """

    origin_xy_m: tuple[float, float]
    resolution_m: float
    width: int
    height: int

    def __post_init__(self) -> None:
        if not (math.isfinite(self.resolution_m) and self.resolution_m > 0):
            raise ModelError("mapping.resolution_m", self.resolution_m, "a cell size > 0 (m)")
        if self.width <= 0 or self.height <= 0 or self.width * self.height > MAX_CELLS:
            raise ModelError(
                "mapping.resolution_m",
                self.resolution_m,
                f"a grid of at most {MAX_CELLS:,} cells (got {self.width} x {self.height})",
            )

    @classmethod
    def covering(
        cls, bounds: tuple[float, float, float, float], resolution_m: float, margin_m: float = 1.0
    ) -> MapGeometry:
        """A grid covering ``bounds`` (xmin, ymin, xmax, ymax in m) plus a margin all round."""
        x0, y0 = bounds[0] - margin_m, bounds[1] - margin_m
        width = math.ceil((bounds[2] + margin_m - x0) / resolution_m)
        height = math.ceil((bounds[3] + margin_m - y0) / resolution_m)
        return cls((x0, y0), resolution_m, width, height)


class Scratch:
    """Working memory of map updates, shareable by every map of one geometry.

    A cell stamped with the current scan's number was updated by it already (each cell
    changes at most once per scan); ``dirty`` marks cells whose scores need recomputing
    during an update, and is all zero between updates. Maps updated one at a time (every
    robot's map in one run) can share it instead of holding grids each.
    """

    def __init__(self, geometry: MapGeometry) -> None:
        shape = (geometry.height, geometry.width)
        self.stamp = np.zeros(shape, dtype=np.int32)
        self.dirty = np.zeros(shape, dtype=np.uint8)
        self.scan = 0


class LogOddsMap:
    """A log-odds occupancy grid with its matching scores.

    Args:
        geometry: the grid's place and size.
        params: the update rule and thresholds.
    """

    def __init__(
        self,
        geometry: MapGeometry,
        params: LogOddsParams | None = None,
        *,
        scratch: Scratch | None = None,
        track_changes: bool = False,
        hit_centroids: bool = False,
    ) -> None:
        self.geometry = geometry
        self.params = params or LogOddsParams()
        shape = (geometry.height, geometry.width)
        self.logodds = np.zeros(shape, dtype=np.float32)
        self.score = np.zeros(shape, dtype=np.uint8)
        self.coarse = np.zeros(shape, dtype=np.uint8)
        self._scratch = scratch if scratch is not None else Scratch(geometry)
        self.changes = np.zeros(shape if track_changes else (0, 0), dtype=np.float32)
        """With ``track_changes``: the log-odds this map's own scans added since
        :meth:`take_changes` (what a robot has not yet told its neighbours)."""
        h, w = shape if hit_centroids else (0, 0)
        self.hit_means = np.zeros((h, w, 2), dtype=np.uint8)
        """With ``hit_centroids``: per cell, the mean offset of its returns from its
        lower-left corner, in 255ths of a cell each way: where its surface lies within it
        (what :func:`models.mapping.walls.refine_on_walls` fits walls to)."""
        self.hit_counts = np.zeros((h, w), dtype=np.uint8)
        """With ``hit_centroids``: the returns each cell's mean holds (at most 255)."""
        self.occupied_cells = 0
        r = math.ceil(SCORE_REACH * self.params.score_sigma_cells)
        off = np.arange(-r, r + 1)
        d2 = off[None, :] ** 2 + off[:, None] ** 2
        kernel = 255.0 * np.exp(-0.5 * d2 / self.params.score_sigma_cells**2)
        self._kernel = np.where(d2 <= r * r, np.round(kernel), 0).astype(np.uint8)

    @property
    def scratch(self) -> Scratch:
        """The working memory updates of this map use (see :class:`Scratch`)."""
        return self._scratch

    @scratch.setter
    def scratch(self, scratch: Scratch) -> None:
        if scratch.dirty.shape != self.logodds.shape:
            raise ValueError(
                f"a scratch of shape {scratch.dirty.shape} for a map of {self.logodds.shape}"
            )
        self._scratch = scratch

    @property
    def empty(self) -> bool:
        """Whether no cell is occupied yet (nothing to match against)."""
        return self.occupied_cells == 0

    def integrate(
        self,
        pose: tuple[float, float, float],
        angles_rad: FloatArray,
        ranges_m: npt.NDArray[np.floating],
        *,
        range_min_m: float,
        range_max_m: float,
        clear_no_return_m: float,
    ) -> int:
        """Add one scan taken at ``pose`` (sensor pose x, y, yaw in ``map``).

        Returns beyond ``range_max_m`` or infinite are "no return": their beam clears
        cells up to ``clear_no_return_m`` only (a missing echo says little about far
        space: glass, black surfaces). NaN ranges and ranges below ``range_min_m`` are
        skipped.

        Returns:
            The number of cells whose occupied state changed (at least that many when
            more changed than are listed: the scores are then rebuilt from scratch).
        """
        scratch = self._scratch
        scratch.scan += 1
        g = self.geometry
        ranges = np.ascontiguousarray(ranges_m, dtype=np.float64)
        valid = ranges >= range_min_m
        lengths = np.where(ranges <= range_max_m, ranges, clear_no_return_m)[valid]
        # a beam crosses at most |dx| + |dy| + 2 cells: sqrt(2) * length / res + 2
        capacity = int(np.ceil(lengths * (1.5 / g.resolution_m)).sum()) + 3 * len(ranges) + 8
        cells = np.empty(capacity, dtype=np.int64)
        hits = np.empty(capacity, dtype=np.bool_)
        n = traverse(
            scratch.stamp,
            scratch.scan,
            g.origin_xy_m[0],
            g.origin_xy_m[1],
            g.resolution_m,
            float(pose[0]),
            float(pose[1]),
            float(pose[2]),
            np.ascontiguousarray(angles_rad, dtype=np.float64),
            ranges,
            range_min_m,
            range_max_m,
            clear_no_return_m,
            cells,
            hits,
            self.hit_means,
            self.hit_counts,
        )
        return self._apply(cells, hits, n)

    @property
    def has_hit_centroids(self) -> bool:
        """Whether this map keeps where in each cell its returns fell (``hit_centroids``)."""
        return self.hit_counts.size > 0

    def fit(self, pose: tuple[float, float, float], points: FloatArray) -> float:
        """How well ``points`` (sensor frame, m) at ``pose`` lie on the map: mean fine score, 0-1.

        Points off the map score 0.
        """
        if len(points) == 0:
            return 0.0
        g = self.geometry
        c, s = math.cos(pose[2]), math.sin(pose[2])
        wx = pose[0] + c * points[:, 0] - s * points[:, 1]
        wy = pose[1] + s * points[:, 0] + c * points[:, 1]
        cx = np.floor((wx - g.origin_xy_m[0]) / g.resolution_m).astype(np.int64)
        cy = np.floor((wy - g.origin_xy_m[1]) / g.resolution_m).astype(np.int64)
        height, width = self.score.shape
        inside = (cx >= 0) & (cy >= 0) & (cx < width) & (cy < height)
        total = self.score[cy[inside], cx[inside]].astype(np.float64).sum()
        return float(total / (255.0 * len(points)))

    def _apply(self, cells: npt.NDArray[np.int64], hits: npt.NDArray[np.bool_], n: int) -> int:
        p = self.params
        flips = np.empty(min(n, 4096) + 64, dtype=np.int64)
        count = apply(
            self.logodds,
            cells,
            hits,
            n,
            p.hit,
            p.miss,
            p.clamp_min,
            p.clamp_max,
            p.occupied,
            flips,
            self.changes,
        )
        if count < 0:  # more flips than the buffer holds: start the scores afresh
            self.occupied_cells = rebuild_scores(
                self.logodds, self.score, self.coarse, self._kernel, p.occupied, COARSE
            )
            return len(flips)
        if count:
            self.occupied_cells += refresh_scores(
                self.logodds,
                self.score,
                self.coarse,
                self._kernel,
                flips[:count],
                p.occupied,
                COARSE,
                self._scratch.dirty,
            )
        return int(count)

    def add_logodds(self, iy0: int, ix0: int, delta: npt.NDArray[np.float32]) -> int:
        """Add a block of log-odds (another robot's evidence) at cell ``(ix0, iy0)``, clamped.

        Returns:
            The number of cells whose occupied state changed.
        """
        p = self.params
        h, w = delta.shape
        block = self.logodds[iy0 : iy0 + h, ix0 : ix0 + w]
        before = block >= p.occupied
        np.clip(
            block + delta[: block.shape[0], : block.shape[1]], p.clamp_min, p.clamp_max, out=block
        )
        changed = np.flatnonzero((block >= p.occupied) != before)
        if not len(changed):
            return 0
        iy, ix = np.divmod(changed, block.shape[1])
        flips = (iy + iy0) * self.geometry.width + (ix + ix0)
        self.occupied_cells += refresh_scores(
            self.logodds,
            self.score,
            self.coarse,
            self._kernel,
            flips.astype(np.int64),
            p.occupied,
            COARSE,
            self._scratch.dirty,
        )
        return len(changed)

    def clear(self) -> None:
        """Forget everything: every cell unknown again (to rebuild after loop closure)."""
        self.logodds[:] = 0.0
        self.score[:] = 0
        self.coarse[:] = 0
        self.occupied_cells = 0
        if self.changes.size:
            self.changes[:] = 0.0
        self.hit_means[:] = 0
        self.hit_counts[:] = 0

    def take_changes(self) -> npt.NDArray[np.float32] | None:
        """The own evidence added since the last call, and start collecting afresh.

        None when nothing changed (or changes are not tracked).
        """
        if not self.changes.size or not self.changes.any():
            return None
        taken = self.changes.copy()
        self.changes[:] = 0.0
        return taken

    def occupancy(self) -> npt.NDArray[np.int8]:
        """Trinary cells: 100 occupied, 0 free, -1 unknown (``nav_msgs/OccupancyGrid``)."""
        p = self.params
        cells = np.empty(self.logodds.shape, dtype=np.int8)
        # compared in numpy's type for the array and the threshold (float32 for a float)
        kind = np.result_type(self.logodds, p.free, p.occupied).type
        classify(self.logodds, kind(p.free), kind(p.occupied), cells)
        return cells

    def occupancy_grid(self) -> OccupancyGrid:
        """The map as a :class:`models.geometry.occupancy.OccupancyGrid`."""
        g = self.geometry
        return OccupancyGrid(g.resolution_m, g.origin_xy_m, self.occupancy())

    def known(self) -> npt.NDArray[np.bool_]:
        """Cells the map classifies (free or occupied)."""
        p = self.params
        return (self.logodds <= p.free) | (self.logodds >= p.occupied)


def merged(maps: list[LogOddsMap]) -> OccupancyGrid:
    """The maps of one grid fused cell by cell: their log-odds summed, clamped, classified.

    Independent evidence adds in log-odds (the occupancy-grid fusion of several robots'
    maps in a common frame). Maps that already hold each other's evidence (shared scans)
    count it twice, which changes few classifications.
    """
    first = maps[0]
    p = first.params
    # added in place one map after the other: the same float32 sums, in the same order, as
    # np.sum over a stack of the maps (axis 0), without building the stack (50 maps of
    # 648 x 648 cells: 84 MB copied, 53 ms, against 9 ms)
    total = first.logodds.copy()
    for m in maps[1:]:
        total += m.logodds
    total = np.clip(total, p.clamp_min, p.clamp_max)
    cells = np.full(total.shape, UNKNOWN, dtype=np.int8)
    cells[total <= p.free] = FREE
    cells[total >= p.occupied] = OCCUPIED
    g = first.geometry
    return OccupancyGrid(g.resolution_m, g.origin_xy_m, cells)
