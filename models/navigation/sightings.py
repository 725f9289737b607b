"""Sightings of moving things kept over time: cells and the first sighting of each.

A robot's obstacle memory holds, for a few seconds, every lidar hit that no static obstacle
explains; marking a costmap cell twice changes nothing, so a recall keeps the first
sighting of each cell. :func:`cell_keys` names a cell by one integer (a 1-D key is far
cheaper to compare than a row), :func:`first_per_cell` keeps the first sighting of each
cell, in order, in one compiled pass with a hash set
(a sort-based ``np.unique`` made a recall ~0.2 ms in ``fleet50``).
"""

from __future__ import annotations

from typing import Any

import numba
import numpy as np

from models.arrays import FloatArray, IntArray


def cell_keys(points: FloatArray, cell_m: float) -> IntArray:
    """One integer per ``cell_m`` cell of each (x, y) point (m): ``cx * 2^32 + (cy mod 2^32)``."""
    cells = np.floor(np.asarray(points) / cell_m).astype(np.int64).reshape(-1, 2)
    keys: IntArray = (cells[:, 0] << 32) + (cells[:, 1] & 0xFFFFFFFF)
    return keys


def first_per_cell(points: FloatArray, keys: IntArray) -> FloatArray:
    """The first point of each cell, in order.

    Args:
        points: (m, 2) sightings (m).
        keys: (m,) the cell key of each sighting (:func:`cell_keys`).

    Returns:
        (k, 2) the first sighting of each distinct key, in the order of ``points``.
    """
    total = len(points)
    if total == 0:
        return np.zeros((0, 2))
    bits = max(4, int(2 * total - 1).bit_length())  # table at least twice the sightings
    out = np.empty((total, 2))
    count = _first_per_cell(np.asarray(points, dtype=np.float64), np.asarray(keys), bits, out)
    return out[:count].copy()


def _first_per_cell_py(points: FloatArray, keys: IntArray, bits: int, out: FloatArray) -> int:
    size = 1 << bits
    mask = size - 1
    table = np.empty(size, dtype=np.int64)
    used = np.zeros(size, dtype=np.bool_)
    k = 0
    for p in range(points.shape[0]):
        key = keys[p]
        # Fibonacci hashing of the key's bits; linear probing
        h = (np.uint64(key) * np.uint64(0x9E3779B97F4A7C15)) >> np.uint64(64 - bits)
        slot = np.int64(h)
        while used[slot] and table[slot] != key:
            slot = (slot + 1) & mask
        if not used[slot]:
            used[slot] = True
            table[slot] = key
            out[k, 0] = points[p, 0]
            out[k, 1] = points[p, 1]
            k += 1
    return k


_first_per_cell: Any = numba.njit(cache=True, nogil=True)(_first_per_cell_py)
