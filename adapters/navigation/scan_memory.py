"""What each robot's navigation remembers of its lidar: the latest scan, and moving things.

:class:`ScanMemory` holds every robot's latest scan (ranges and the pose it was taken
from): the local controller takes its nearby hits, CSR-packed for one batched call.
:class:`MovingMemory` holds, for ``memory_s`` seconds, the hits that no static obstacle
explains (other robots, people) within the obstacle range: the global planner marks them,
minus those the latest scan sees through, as Nav2's obstacle layer marks and clears by
raytracing (its default ``obstacle_max_range`` is 2.5 m; static obstacles are in the static
layer already).
"""

from __future__ import annotations

from collections import deque

import numpy as np
import numpy.typing as npt

from models.arrays import FloatArray, IntArray
from models.navigation.sightings import cell_keys, first_per_cell
from models.sensing.lidar import hits_within, seen_beyond


class ScanMemory:
    """The latest scan of every robot.

    Args:
        robots: number of robots.
        beam_angles: (b,) beam angles in the sensor frame (rad).
        range_max_m: the lidar's maximum range (m).
    """

    def __init__(self, robots: int, beam_angles: FloatArray, range_max_m: float) -> None:
        self.beams = len(beam_angles)
        self.angles = np.asarray(beam_angles, dtype=float)
        self.cos_a = np.cos(beam_angles)
        self.sin_a = np.sin(beam_angles)
        self.angle_min = float(beam_angles[0]) if self.beams else 0.0
        self.increment = float(beam_angles[1] - beam_angles[0]) if self.beams > 1 else 1.0
        self.range_max_m = range_max_m
        self.ranges = np.full((robots, self.beams), np.inf, dtype=np.float32)
        self.poses = np.zeros((robots, 3))
        self.seen = np.zeros(robots, dtype=bool)

    def add(self, robot: int, pose: FloatArray, ranges: npt.NDArray[np.float32]) -> None:
        """Keep ``robot``'s scan taken from ``pose`` (x, y, yaw in ``map``)."""
        self.ranges[robot] = ranges
        self.poses[robot] = pose
        self.seen[robot] = True

    def near(self, within_m: float) -> tuple[FloatArray, IntArray]:
        """Hits of every robot's latest scan within ``within_m`` of it, CSR-packed.

        Returns:
            ``(points, start)``: (m, 2) ``map`` points; robot ``i`` owns
            ``points[start[i]:start[i + 1]]``; robots without a scan own none.
        """
        return hits_within(self.ranges, self.seen, self.poses, self.cos_a, self.sin_a, within_m)

    def seen_through(
        self, robot: int, points: FloatArray, tolerance_m: float
    ) -> npt.NDArray[np.bool_]:
        """Which points ``robot``'s latest scan sees free space beyond (by ``tolerance_m``)."""
        if not self.seen[robot]:
            return np.zeros(len(points), dtype=bool)
        return seen_beyond(
            self.poses[robot],
            self.ranges[robot],
            self.angle_min,
            self.increment,
            self.range_max_m,
            points,
            tolerance_m,
        )

    def local_points(self, robot: int) -> FloatArray:
        """Hits of ``robot``'s latest scan in its ``base_link`` frame, (k, 2) (m)."""
        ranges = self.ranges[robot].astype(np.float64)
        hit = np.isfinite(ranges) & (ranges > 0)
        if not self.seen[robot]:
            return np.zeros((0, 2))
        return np.stack([ranges[hit] * self.cos_a[hit], ranges[hit] * self.sin_a[hit]], axis=1)

    def sector_min(self, robot: int, lo: float, hi: float) -> float:
        """Smallest range (m) of ``robot``'s latest scan within beam angles [lo, hi] (rad)."""
        if not self.seen[robot]:
            return 0.0
        ranges = self.ranges[robot].astype(np.float64)
        ranges = np.where(np.isnan(ranges) | (ranges == np.inf), self.range_max_m, ranges)
        ranges = np.where(ranges == -np.inf, 0.0, ranges)
        sector = (self.angles >= lo) & (self.angles <= hi)
        return float(ranges[sector].min()) if sector.any() else self.range_max_m


class MovingMemory:
    """Moving things (robots, people) seen by each robot in the last ``memory_ns``.

    Each instant's sightings are kept CSR-packed by robot with their cell keys on the
    ``cell_m`` grid computed once; a recall (one per replan, about 40 a second in
    ``fleet50``) gathers the robot's stretch of each remembered instant and keeps the first
    sighting of each cell in one compiled pass (:func:`first_per_cell`). Each instant is
    its own pair of arrays, exactly its size: one shared buffer made the recall a little
    faster but held up to four times the sightings (1,000 robots: +300 MB peak).

    Args:
        memory_ns: how long a sighting is kept (ns).
        cell_m: cell size of the keys computed on arrival (m); a recall on another cell
            size computes its own.
    """

    def __init__(self, memory_ns: int, cell_m: float = 0.1) -> None:
        self.memory_ns = memory_ns
        self.cell_m = cell_m
        self._ticks: deque[tuple[int, list[int], IntArray, FloatArray]] = deque()

    def remember(self, now_ns: int, owner: IntArray, points: FloatArray) -> None:
        """Keep the sightings of one instant: ``points`` (k, 2) in ``map``, seen by ``owner``.

        ``owner`` must be sorted (points grouped by robot), as CSR-packed scans are.
        """
        owner = np.asarray(owner)
        top = int(owner[-1]) + 1 if len(owner) else 0
        bounds = np.searchsorted(owner, np.arange(top + 1)).tolist()
        self._ticks.append((now_ns, bounds, cell_keys(points, self.cell_m), points))
        while self._ticks and now_ns - self._ticks[0][0] > self.memory_ns:
            self._ticks.popleft()

    def recall(self, robot: int, cell_m: float) -> FloatArray:
        """Everything ``robot`` saw moving within the memory, one point per ``cell_m`` cell.

        Returns:
            (m, 2) points in ``map`` (m), the first sighting of each cell of a
            ``cell_m`` grid (marking a costmap cell twice changes nothing).
        """
        keys: list[IntArray] = []
        parts: list[FloatArray] = []
        for _, bounds, tick_keys, points in self._ticks:
            if robot + 1 < len(bounds):
                lo, hi = bounds[robot], bounds[robot + 1]
                if hi > lo:
                    keys.append(tick_keys[lo:hi])
                    parts.append(points[lo:hi])
        if not parts:
            return np.zeros((0, 2))
        every = np.concatenate(parts)
        every_keys = np.concatenate(keys) if cell_m == self.cell_m else cell_keys(every, cell_m)
        return first_per_cell(every, every_keys)
