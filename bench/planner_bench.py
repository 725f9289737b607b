"""Global planning on the fleet50 hall: static costmap build, obstacle stamping, A* plans."""

from __future__ import annotations

import json
import math
import statistics
import time
from collections.abc import Callable
from functools import partial
from typing import Any, TypeVar

import numpy as np

from models.navigation.costmap import INSCRIBED, CostmapParams, StaticCostmap, with_obstacles
from models.navigation.planner import PlanResult, plan, prune_path, shortest_path_length_m
from models.world.warehouse import WarehouseSpec, generate_warehouse, ground_truth_grid

Result = dict[str, Any]
T = TypeVar("T")

RESOLUTION_M = 0.05
ROBOT_RADIUS_M = 0.33
SCAN_POINTS = 360
SCAN_RANGE_M = 4.0
RANDOM_PAIRS = 5


def _median_ms(call: Callable[[], T], repeat: int) -> tuple[float, T]:
    out = call()  # JIT compile or cache load, then warm
    walls = []
    for _ in range(repeat):
        start = time.perf_counter()
        out = call()
        walls.append(time.perf_counter() - start)
    return round(statistics.median(walls) * 1e3, 3), out


def _free_cells(static: StaticCostmap, rng: np.random.Generator, count: int) -> np.ndarray:
    free = np.argwhere(static.cost < INSCRIBED)  # (iy, ix)
    return free[rng.choice(len(free), size=count, replace=False)][:, ::-1]


def _plan(
    static: StaticCostmap, start: tuple[int, int], goal: tuple[int, int], weight: float
) -> PlanResult:
    return plan(static.cost, start, goal, cost_weight=weight, resolution_m=RESOLUTION_M)


def planner_ms(repeat: int) -> Result:
    """Median times (ms) of the costmap and planner on the fleet50 hall at 0.05 m."""
    spec = WarehouseSpec(layout="all_rows", shelf_count=72, robot_count=50)
    world = generate_warehouse(spec, np.random.default_rng(1))
    grid = ground_truth_grid(world, RESOLUTION_M)
    params = CostmapParams(robot_radius_m=ROBOT_RADIUS_M)
    build_ms, static = _median_ms(lambda: StaticCostmap.from_grid(grid, params), repeat)

    angles = np.linspace(-math.pi, math.pi, SCAN_POINTS, endpoint=False)
    centre = np.array(world.size_m) / 2
    scan = centre + SCAN_RANGE_M * np.column_stack([np.cos(angles), np.sin(angles)])
    stamp_ms, _ = _median_ms(lambda: with_obstacles(static, scan), repeat)
    discs = np.column_stack([world.starts[:, :2], np.full(len(world.starts), ROBOT_RADIUS_M)])
    discs_ms, _ = _median_ms(lambda: with_obstacles(static, scan, discs=discs), repeat)

    width, height = world.size_m
    corner = (0.5, 0.5)  # dock corner, 0.5 m from both walls
    far = (width - 0.5, height - 0.5)
    pairs = [(static.world_to_cell(corner), static.world_to_cell(far))]
    cells = _free_cells(static, np.random.default_rng(7), 2 * RANDOM_PAIRS)
    pairs += [
        ((int(a[0]), int(a[1])), (int(b[0]), int(b[1])))
        for a, b in zip(cells[0::2], cells[1::2], strict=True)
    ]
    cases: list[Result] = []
    plan_ms: list[float] = []
    for weight in (1.0, 0.0):
        for start, goal in pairs:
            ms, result = _median_ms(partial(_plan, static, start, goal, weight), repeat)
            assert result.found
            plan_ms.append(ms)
            prune, waypoints = _median_ms(partial(prune_path, static.cost, result.cells), repeat)
            cases.append(
                {
                    "start_cell": list(start),
                    "goal_cell": list(goal),
                    "cost_weight": weight,
                    "plan_ms_median": ms,
                    "expansions": result.expansions,
                    "length_m": round(result.length_m, 3),
                    "path_cells": len(result.cells),
                    "prune_ms_median": prune,
                    "waypoints": len(waypoints),
                }
            )
    shortest_ms, shortest = _median_ms(lambda: shortest_path_length_m(static, corner, far), repeat)
    corner_case = cases[0]
    return {
        "hall_m": list(world.size_m),
        "shelves": len(world.shelves),
        "grid_cells": [static.width, static.height],
        "resolution_m": RESOLUTION_M,
        "static_costmap_build_ms_median": build_ms,
        "stamp_360_points_ms_median": stamp_ms,
        "stamp_360_points_50_discs_ms_median": discs_ms,
        "corner_to_corner_plan_ms_median": corner_case["plan_ms_median"],
        "corner_to_corner_expansions": corner_case["expansions"],
        "plan_ms_median_over_cases": statistics.median(plan_ms),
        "plan_ms_max_over_cases": max(plan_ms),
        "shortest_path_length_m_corner": round(shortest, 3),
        "shortest_path_length_ms_median": shortest_ms,
        "cases": cases,
        "repeat": repeat,
        "single_thread": True,
    }


if __name__ == "__main__":
    print(json.dumps(planner_ms(20), indent=2))
