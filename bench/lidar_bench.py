"""Lidar ray casting throughput: the grid caster (one core) against the numpy reference."""

from __future__ import annotations

import json
import math
import statistics
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from models.errors import ModelError
from models.sensing.lidar import cast_reference
from models.sensing.raycast import StaticScene, cast_batch, scene_cell_m
from models.world.warehouse import Warehouse, WarehouseSpec, generate_warehouse

Result = dict[str, Any]

BEAMS = 360
RANGE_MAX_M = 10.0
ROBOT_RADIUS_M = 0.33


def _full_hall(size_m: float, robots: int, upper: int) -> tuple[Warehouse, int]:
    """An all_rows hall with as many shelves as fit (bisection on the shelf count)."""

    def build(shelves: int) -> Warehouse | None:
        spec = WarehouseSpec(
            size_m=(size_m, size_m),
            layout="all_rows",
            shelf_count=shelves,
            robot_count=robots,
            placement="random",
        )
        try:
            return generate_warehouse(spec, np.random.default_rng(1))
        except ModelError:
            return None

    lo, hi = 0, upper
    while lo < hi:
        mid = (lo + hi + 1) // 2
        if build(mid) is None:
            hi = mid - 1
        else:
            lo = mid
    world = build(lo)
    assert world is not None
    return world, lo


def _median_rate(call: Callable[[], object], rays: int, repeat: int) -> tuple[float, list[float]]:
    walls = []
    for _ in range(repeat):
        start = time.perf_counter()
        call()
        walls.append(time.perf_counter() - start)
    return rays / statistics.median(walls), walls


def _scene_case(size_m: float, robots: int, upper: int, repeat: int) -> tuple[Result, Any]:
    world, shelves = _full_hall(size_m, robots, upper)
    segments = world.segments()
    start = time.perf_counter()
    cell_m = scene_cell_m(segments)  # as the lidar adapter chooses it
    scene = StaticScene(segments, cell_m=cell_m)
    build_s = time.perf_counter() - start
    origins = np.ascontiguousarray(world.starts[:, :2])
    yaws = np.ascontiguousarray(world.starts[:, 2])
    beams = -math.pi + 2 * math.pi / BEAMS * np.arange(BEAMS, dtype=np.float64)
    circles = np.column_stack([origins, np.full(robots, ROBOT_RADIUS_M)])
    exclude = np.arange(robots, dtype=np.int64)

    def call() -> np.ndarray:
        return cast_batch(scene, origins, yaws, beams, circles, exclude, RANGE_MAX_M)

    start = time.perf_counter()
    ranges = call()  # JIT compile or cache load, then warm
    first_s = time.perf_counter() - start
    rate, walls = _median_rate(call, robots * BEAMS, repeat)
    result = {
        "hall_m": [size_m, size_m],
        "layout": "all_rows",
        "shelves": shelves,
        "segments": len(segments),
        "robots": robots,
        "beams": BEAMS,
        "range_max_m": RANGE_MAX_M,
        "cell_m": round(cell_m, 3),
        "hit_fraction": round(float(np.isfinite(ranges).mean()), 4),
        "scene_build_s": round(build_s, 5),
        "first_call_s": round(first_s, 4),
        "rays_per_s_median": round(rate),
        "call_s_median": round(statistics.median(walls), 6),
        "repeat": repeat,
    }
    return result, (origins, yaws, beams, segments, circles, exclude, ranges)


def lidar_rays_per_second(repeat: int) -> Result:
    """Rays per second of the grid caster on the fleet50 hall and a 1,000-robot hall."""
    fleet50, (origins, yaws, beams, segments, circles, exclude, ranges) = _scene_case(
        30.0, 50, 200, repeat
    )
    ref_repeat = max(1, min(repeat, 3))
    holder: list[np.ndarray] = []
    ref_rate, _ = _median_rate(
        lambda: holder.append(
            cast_reference(origins, yaws, beams, segments, circles, RANGE_MAX_M, exclude)
        ),
        len(origins) * BEAMS,
        ref_repeat,
    )
    want = holder[-1]
    both = np.isfinite(want) & np.isfinite(ranges)
    big, _ = _scene_case(100.0, 1000, 3000, repeat)
    return {
        "fleet50": fleet50,
        "fleet1000": big,
        "numpy_reference_fleet50": {
            "rays_per_s_median": round(ref_rate),
            "repeat": ref_repeat,
            "max_abs_diff_m": float(np.abs(want[both] - ranges[both]).max(initial=0.0)),
            "inf_mismatches": int((np.isfinite(want) != np.isfinite(ranges)).sum()),
        },
        "speedup_vs_reference": round(fleet50["rays_per_s_median"] / ref_rate, 1),
        "single_thread": True,
    }


if __name__ == "__main__":
    print(json.dumps(lidar_rays_per_second(20), indent=2))
