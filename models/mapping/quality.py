"""How good a map and a trajectory are, against ground truth.

Maps are compared cell by cell with the ground-truth occupancy on the same grid:

- ``coverage``: the share of *observable* cells the map classifies (free or occupied).
  Observable are the free cells of the room and the occupied cells bordering them (the
  faces of walls and shelves); the inside of a shelf is never seen and does not count.
- ``iou``: intersection over union of the occupied cells, over the cells the map knows
  (the explored area), with one cell of tolerance: a mapped obstacle cell is right when
  a real one lies in its 8-neighbourhood, and a real obstacle cell is found when a
  mapped one does. A face lying on a cell boundary belongs to the cells on both sides,
  and the rasterized truth gives it to one: with exact poses and 1 cm range noise the
  strict IoU of a 5 cm map of the warehouse is 0.68, the tolerant one 0.998 (measured).
  ``iou_strict`` is the cell-exact value.
- ``accuracy``: the share of known cells whose class (free, occupied) is right.

Trajectories: the absolute trajectory error, the root mean square of position errors
(m), after the best rigid SE(2) alignment when the frames differ (Umeyama's method
without scale, as evo computes ATE).
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numba
import numpy as np
import numpy.typing as npt

from models.arrays import FloatArray
from models.geometry.occupancy import FREE, OCCUPIED, UNKNOWN

Int8Array = npt.NDArray[np.int8]
BoolArray = npt.NDArray[np.bool_]


class MapScores(NamedTuple):
    """Coverage, occupied IoU (tolerant, strict) and accuracy of a map (module doc), in [0, 1]."""

    coverage: float
    iou: float
    accuracy: float
    iou_strict: float


def observable(truth: Int8Array, room: BoolArray) -> BoolArray:
    """Cells a robot can see: free cells of the room and occupied cells touching them.

    Args:
        truth: ground-truth cells (0 free, 100 occupied).
        room: cells inside the room (the walls' inner faces included).
    """
    free = (truth == FREE) & room
    faces = (truth == OCCUPIED) & dilate(free)
    result: BoolArray = free | faces
    return result


def map_scores(cells: Int8Array, truth: Int8Array, seen: BoolArray) -> MapScores:
    """Score a trinary map (100 / 0 / -1) against the truth on the same grid.

    Args:
        cells: the map.
        truth: ground-truth cells (0 free, 100 occupied).
        seen: the observable cells (:func:`observable`).
    """
    counts = np.zeros(_COUNTS, dtype=np.int64)
    _count(
        np.ascontiguousarray(cells),
        np.ascontiguousarray(truth),
        np.ascontiguousarray(seen, dtype=np.bool_),
        counts,
    )
    seen_n, known_seen, known_n, mapped_n, union, both, right, missed, correct = (
        int(v) for v in counts
    )
    coverage = known_seen / max(1, seen_n)
    strict = both / union if union else 1.0
    total = mapped_n + missed
    iou = right / total if total else 1.0
    accuracy = correct / max(1, known_n)
    return MapScores(float(coverage), float(iou), float(accuracy), float(strict))


_COUNTS = 9


def _near_py(cells: Any, value: int, iy: int, ix: int) -> bool:
    """Whether ``value`` lies in the 3 x 3 neighbourhood of cell (iy, ix) (clipped)."""
    height, width = cells.shape
    for y in range(max(0, iy - 1), min(height, iy + 2)):
        for x in range(max(0, ix - 1), min(width, ix + 2)):
            if cells[y, x] == value:
                return True
    return False


def _count_py(cells: Any, truth: Any, seen: Any, counts: Any) -> None:
    """The cell counts of :func:`map_scores`, in one pass (dilations as neighbourhoods).

    ``counts``: observable, known and observable, known, mapped (occupied), mapped or
    really occupied among the known, both, mapped near a real obstacle, real obstacles
    known with no mapped cell near, known and right.
    """
    height, width = cells.shape
    for iy in range(height):
        for ix in range(width):
            v = cells[iy, ix]
            t = truth[iy, ix]
            known = v != UNKNOWN
            mapped = v == OCCUPIED
            real = known and t == OCCUPIED
            if seen[iy, ix]:
                counts[0] += 1
                if known:
                    counts[1] += 1
            if known:
                counts[2] += 1
                if v == t:
                    counts[8] += 1
            if mapped:
                counts[3] += 1
                if _near(truth, OCCUPIED, iy, ix):
                    counts[6] += 1
            if mapped or real:
                counts[4] += 1
                if mapped and real:
                    counts[5] += 1
            if real and not _near(cells, OCCUPIED, iy, ix):
                counts[7] += 1


_near: Any = numba.njit(cache=True, nogil=True, inline="always")(_near_py)
_count: Any = numba.njit(cache=True, nogil=True)(_count_py)


def dilate(cells: BoolArray) -> BoolArray:
    """Cells with a true cell in their 8-neighbourhood (3 x 3 dilation, by shifted ORs)."""
    rows = cells.copy()
    rows[1:] |= cells[:-1]
    rows[:-1] |= cells[1:]
    out = rows.copy()
    out[:, 1:] |= rows[:, :-1]
    out[:, :-1] |= rows[:, 1:]
    return out


def align_se2(estimate: FloatArray, reference: FloatArray) -> tuple[FloatArray, FloatArray]:
    """The rotation (2, 2) and translation (2,) that best map ``estimate`` onto ``reference``.

    Least squares over corresponding points (k, 2) (Umeyama 1991, without scale).
    """
    est = np.asarray(estimate, dtype=np.float64)
    ref = np.asarray(reference, dtype=np.float64)
    mu_e, mu_r = est.mean(axis=0), ref.mean(axis=0)
    cov = (ref - mu_r).T @ (est - mu_e)
    u, _, vt = np.linalg.svd(cov)
    d = np.sign(np.linalg.det(u @ vt)) or 1.0
    rotation = u @ np.diag([1.0, d]) @ vt
    return rotation, mu_r - rotation @ mu_e


def ate_rmse(estimate: FloatArray, reference: FloatArray, *, align: bool) -> float:
    """Absolute trajectory error (m): RMS of the position errors, optionally after alignment.

    Args:
        estimate: (k, 2) estimated positions.
        reference: (k, 2) true positions at the same instants.
        align: first move ``estimate`` onto ``reference`` by :func:`align_se2` (for
            trajectories in different frames, e.g. odometry against ground truth).
    """
    est = np.asarray(estimate, dtype=np.float64).reshape(-1, 2)
    ref = np.asarray(reference, dtype=np.float64).reshape(-1, 2)
    if len(est) == 0:
        return float("nan")
    if align and len(est) >= 2:
        rotation, shift = align_se2(est, ref)
        est = est @ rotation.T + shift
    return float(np.sqrt(np.mean(np.sum((est - ref) ** 2, axis=1))))
