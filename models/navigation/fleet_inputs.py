"""What every batched local controller checks and packs before its compiled kernel runs.

The controllers of :mod:`models.navigation` (``dwa``, ``pure_pursuit``, ``orca``, ``mppi``)
take the same fleet arrays (one row per robot, ``map`` frame, m and rad) and the same
CSR-packed lidar hits and discs (robot ``i`` owns rows ``start[i]:start[i + 1]``). Their
kernels read one flat float64 row per robot and one flat vector of parameters; this module
builds those once, with the errors naming the array that is wrong.
"""

from __future__ import annotations

from dataclasses import astuple
from functools import lru_cache
from typing import Any

import numpy as np

from models.arrays import FloatArray, IntArray
from models.errors import ModelError
from models.fleet.kinematics import DriveLimits
from models.slicing import Slices


def fleet_rows(
    poses: FloatArray,
    velocities: FloatArray,
    radius_m: FloatArray,
    carrots: FloatArray,
    goals: FloatArray,
) -> FloatArray:
    """(n, 10) C-contiguous rows ``x, y, yaw, v, w, radius, carrot x, y, goal x, y``.

    Raises:
        ValueError: an array is not of its shape: (n, 3), (n, 2), (n,), (n, 2), (n, 2).
    """
    given = {"poses": poses, "velocities": velocities, "radius_m": radius_m}
    given |= {"carrots": carrots, "goals": goals}
    n = len(poses)
    for (name, array), width in zip(given.items(), (3, 2, 0, 2, 2), strict=True):
        shape = (n, width) if width else (n,)
        if np.shape(array) != shape:
            raise ValueError(f"{name} must be {shape}, got {np.shape(array)}")
    rows = np.column_stack([np.asarray(a, dtype=np.float64) for a in given.values()])
    return np.ascontiguousarray(rows)


def offsets(start: IntArray, count: int, items: int, name: str) -> IntArray:
    """``start`` as int64 CSR offsets of ``count`` robots over ``items`` rows.

    Raises:
        ValueError: not (count + 1,), or not rising from 0 to ``items``.
    """
    found = np.ascontiguousarray(start, dtype=np.int64)
    if found.shape != (count + 1,):
        raise ValueError(f"{name} must be ({count + 1},), got {found.shape}")
    if found[0] != 0 or found[-1] != items or np.any(np.diff(found) < 0):
        raise ValueError(f"{name} must rise from 0 to {items}, got {found.tolist()}")
    return found


def points(values: FloatArray, width: int) -> FloatArray:
    """``values`` as C-contiguous float64 rows of ``width`` (hits: 2, discs: 3)."""
    return np.ascontiguousarray(values, dtype=np.float64).reshape(-1, width)


def check_limits(limits: DriveLimits, *keys: str) -> None:
    """Refuse drive limits a kernel divides by: ``max_speed_mps`` and any of ``keys`` <= 0.

    Raises:
        ModelError: naming ``robots.<key>``.
    """
    for key in ("max_speed_mps", *keys):
        value = getattr(limits, key)
        if not value > 0.0:
            raise ModelError(f"robots.{key}", value, "a number > 0")


@lru_cache(maxsize=32)
def packed(params: Any, limits: DriveLimits) -> FloatArray:
    """The kernel's flat parameter vector: ``params``' fields in order, then ``limits``'.

    Built once per (frozen) parameters: ``astuple`` copies deeply at every call. Shared
    between calls: the kernels only read it.
    """
    return np.array(astuple(params) + astuple(limits), dtype=np.float64)


def decide_sliced(
    kernel: Any,
    slices: Slices,
    rows: FloatArray,
    hits: FloatArray,
    hit_start: IntArray,
    others: FloatArray,
    other_start: IntArray,
    config: FloatArray,
    out: FloatArray,
) -> None:
    """Run a controller's kernel over ``slices`` of the robots, each writing its rows of ``out``.

    The kernel is called as ``kernel(rows, hits, hit_start, others, other_start, config,
    out)`` on a slice's rows. The offsets stay absolute: a slice of robots reads its own
    hits and others (discs, neighbours) out of the whole arrays, so each robot's command
    is the same whatever the cut.
    """

    def decide(first: int, stop: int) -> None:
        kernel(
            rows[first:stop],
            hits,
            hit_start[first : stop + 1],
            others,
            other_start[first : stop + 1],
            config,
            out[first:stop],
        )

    slices(len(rows), decide)
