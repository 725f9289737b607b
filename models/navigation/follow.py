"""Following global paths: the carrot ahead, progress along the path, for a fleet at once.

Paths are stored batched: ``paths`` (n, P, 2) waypoints in ``map`` (m), ``lengths`` (n,)
the number of valid waypoints per robot, ``segment`` (n,) the path segment each robot
was last projected on. Projection only moves forward along the path, so a path that
comes back near itself does not make the robot jump ahead or back.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numba
import numpy as np
import numpy.typing as npt

from models.arrays import FloatArray, IntArray

SEARCH_SEGMENTS = 8
"""Segments ahead of the last one searched when projecting (bounds the work per robot)."""


def _follow_py(
    paths: FloatArray,
    lengths: IntArray,
    segment: IntArray,
    x: FloatArray,
    y: FloatArray,
    lookahead: float,
    carrots: FloatArray,
    remaining: FloatArray,
) -> None:
    for r in range(paths.shape[0]):
        n = lengths[r]
        if n == 0:
            carrots[r, 0] = x[r]
            carrots[r, 1] = y[r]
            remaining[r] = 0.0
            continue
        if n == 1:
            carrots[r, 0] = paths[r, 0, 0]
            carrots[r, 1] = paths[r, 0, 1]
            remaining[r] = math.hypot(paths[r, 0, 0] - x[r], paths[r, 0, 1] - y[r])
            continue
        # project on the nearest of the next few segments
        best_d = np.inf
        best_s = segment[r]
        best_t = 0.0
        last = min(n - 1, segment[r] + SEARCH_SEGMENTS)
        for s in range(segment[r], last):
            ax, ay = paths[r, s, 0], paths[r, s, 1]
            ex, ey = paths[r, s + 1, 0] - ax, paths[r, s + 1, 1] - ay
            ll = ex * ex + ey * ey
            t = 0.0 if ll == 0.0 else ((x[r] - ax) * ex + (y[r] - ay) * ey) / ll
            t = min(max(t, 0.0), 1.0)
            d = math.hypot(ax + t * ex - x[r], ay + t * ey - y[r])
            if d < best_d:
                best_d, best_s, best_t = d, s, t
        segment[r] = best_s
        # walk the lookahead distance along the path from the projection
        ax, ay = paths[r, best_s, 0], paths[r, best_s, 1]
        bx, by = paths[r, best_s + 1, 0], paths[r, best_s + 1, 1]
        px, py = ax + best_t * (bx - ax), ay + best_t * (by - ay)
        left = lookahead
        cx, cy = bx, by
        s = best_s
        seg_rest = math.hypot(bx - px, by - py)
        total = seg_rest
        found = False
        if seg_rest >= left:
            f = left / seg_rest if seg_rest > 0 else 0.0
            cx, cy = px + f * (bx - px), py + f * (by - py)
            found = True
        else:
            left -= seg_rest
        for k in range(s + 1, n - 1):
            qx, qy = paths[r, k, 0], paths[r, k, 1]
            wx, wy = paths[r, k + 1, 0], paths[r, k + 1, 1]
            seg = math.hypot(wx - qx, wy - qy)
            total += seg
            if not found:
                if seg >= left:
                    f = left / seg if seg > 0 else 0.0
                    cx, cy = qx + f * (wx - qx), qy + f * (wy - qy)
                    found = True
                else:
                    left -= seg
                    cx, cy = wx, wy
        carrots[r, 0] = cx
        carrots[r, 1] = cy
        remaining[r] = total + best_d


_follow: Any = numba.njit(cache=True, nogil=True)(_follow_py)


@dataclass
class PathBook:
    """The current global path of every robot, in one padded array.

    Args:
        robots: number of robots.
        capacity: maximum waypoints per path.
    """

    robots: int
    capacity: int = 512

    def __post_init__(self) -> None:
        self.paths = np.zeros((self.robots, self.capacity, 2))
        self.lengths = np.zeros(self.robots, dtype=np.int64)
        self.segment = np.zeros(self.robots, dtype=np.int64)

    def set(self, robot: int, waypoints: FloatArray) -> None:
        """Give ``robot`` a new path of (k, 2) waypoints in ``map`` (m).

        Raises:
            ValueError: if the path has more waypoints than the capacity.
        """
        k = len(waypoints)
        if k > self.capacity:
            raise ValueError(f"path of {k} waypoints exceeds the capacity {self.capacity}")
        self.paths[robot, :k] = waypoints
        self.lengths[robot] = k
        self.segment[robot] = 0

    def clear(self, robot: int) -> None:
        """Forget ``robot``'s path."""
        self.lengths[robot] = 0
        self.segment[robot] = 0

    def waypoints(self, robot: int) -> FloatArray:
        """The (k, 2) waypoints of ``robot``'s path."""
        return self.paths[robot, : self.lengths[robot]]

    def follow(
        self, x: FloatArray, y: FloatArray, lookahead_m: float
    ) -> tuple[FloatArray, FloatArray]:
        """Carrot points ``lookahead_m`` ahead along each path, and the remaining lengths (m).

        A robot without a path gets its own position and 0.
        """
        carrots = np.zeros((self.robots, 2))
        remaining = np.zeros(self.robots)
        _follow(
            self.paths, self.lengths, self.segment, x, y, float(lookahead_m), carrots, remaining
        )
        return carrots, remaining

    def follow_one(self, robot: int, x_m: float, y_m: float) -> float:
        """The remaining length (m) of ``robot``'s path from ``(x_m, y_m)``, as :meth:`follow`.

        Does not move the robot's projection along its path.
        """
        one = slice(robot, robot + 1)
        carrots = np.zeros((1, 2))
        remaining = np.zeros(1)
        _follow(
            self.paths[one],
            self.lengths[one],
            self.segment[one].copy(),
            np.array([x_m]),
            np.array([y_m]),
            0.0,
            carrots,
            remaining,
        )
        return float(remaining[0])


def _blocking_py(
    paths: FloatArray,
    lengths: IntArray,
    segment: IntArray,
    owner: IntArray,
    points: FloatArray,
    clearance: float,
    segments_ahead: int,
    out: npt.NDArray[np.bool_],
) -> None:
    for k in range(points.shape[0]):
        r = owner[k]
        if out[r] or lengths[r] < 2:
            continue
        px, py = points[k, 0], points[k, 1]
        last = min(lengths[r] - 1, segment[r] + segments_ahead)
        for s in range(segment[r], last):
            ax, ay = paths[r, s, 0], paths[r, s, 1]
            ex, ey = paths[r, s + 1, 0] - ax, paths[r, s + 1, 1] - ay
            ll = ex * ex + ey * ey
            t = 0.0 if ll == 0.0 else ((px - ax) * ex + (py - ay) * ey) / ll
            t = min(max(t, 0.0), 1.0)
            if math.hypot(ax + t * ex - px, ay + t * ey - py) < clearance:
                out[r] = True
                break


_blocking: Any = numba.njit(cache=True, nogil=True)(_blocking_py)


def paths_blocked(
    book: PathBook,
    owner: IntArray,
    points: FloatArray,
    clearance_m: float,
    segments_ahead: int = 4,
) -> npt.NDArray[np.bool_]:
    """Which robots see an obstacle point within ``clearance_m`` of their path ahead.

    Args:
        book: the robots' paths (their projection segments as last followed).
        owner: (k,) robot index of each point.
        points: (k, 2) obstacle points in ``map`` (m).
        clearance_m: distance from the path's centre line that counts as blocking (m).
        segments_ahead: how many path segments from the current one are checked.
    """
    out = np.zeros(book.robots, dtype=bool)
    if len(points):
        _blocking(
            book.paths,
            book.lengths,
            book.segment,
            np.asarray(owner, dtype=np.int64),
            np.asarray(points, dtype=np.float64),
            float(clearance_m),
            int(segments_ahead),
            out,
        )
    return out
