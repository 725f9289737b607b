"""Landmark bounds (ALT) for A* on halls grown with the fleet: what they save, what they cost.

For each hall of ``scale_bench.HALLS`` (0.1 m cells), fleet-like searches: from a docked
robot or a random free cell to a random free cell, the navigation adapter's full plan
(obstacle layer copy, A* at cost weight 1, pruning) and its path-length yardstick (A* at
weight 0 on the static layer, pruned), each with and without the landmark fields,
interleaved. Reports per-search times and expansions, the fields' build time and memory,
and the goals after which the build has paid for itself. The results back
``models.navigation.landmarks.ALT_MIN_CELLS``.

Run ``python bench/landmarks_bench.py [repeat]``; it prints one JSON document.
"""

from __future__ import annotations

import json
import statistics
import sys
import time
from typing import Any

import numpy as np
from scale_bench import HALLS, Hall

import cosim
from adapters.world.warehouse import spec_from_scenario
from models.navigation.costmap import INSCRIBED, CostmapParams, StaticCostmap, with_obstacles
from models.navigation.landmarks import LandmarkCache, Landmarks
from models.navigation.planner import plan, prune_path, shortest_path_length_m
from models.world.warehouse import generate_warehouse, ground_truth_grid

Result = dict[str, Any]
RESOLUTION_M = 0.1
SEARCHES = 200


def _hall(hall: Hall) -> tuple[StaticCostmap, list[tuple[tuple[int, int], tuple[int, int]]]]:
    scenario = cosim.load_scenario(
        "fleet50",
        {
            "robots.count": hall.robots,
            "world.size_m": [hall.side_m, hall.side_m],
            "world.shelf_count": hall.shelves,
        },
    )
    world = generate_warehouse(spec_from_scenario(scenario), np.random.default_rng(1))
    nav = scenario.navigation
    params = CostmapParams(scenario.robots.radius_m, nav.inflation_radius_m, nav.cost_scaling)
    static = StaticCostmap.from_grid(ground_truth_grid(world, RESOLUTION_M), params)
    rng = np.random.default_rng(11)
    free = np.argwhere(static.cost < INSCRIBED)[:, ::-1]
    docks = [static.world_to_cell(p[:2]) for p in world.starts]
    pairs = []
    for k in range(SEARCHES):
        start = docks[rng.integers(len(docks))] if k % 2 == 0 else free[rng.integers(len(free))]
        goal = free[rng.integers(len(free))]
        pairs.append(((int(start[0]), int(start[1])), (int(goal[0]), int(goal[1]))))
    return static, pairs


def _full(static: StaticCostmap, start: Any, goal: Any, marks: Landmarks | None) -> int:
    cost = with_obstacles(static, np.zeros((0, 2)))
    result = plan(cost, start, goal, resolution_m=RESOLUTION_M, landmarks=marks)
    if result.found:
        prune_path(cost, result.cells)
    return result.expansions


def _stats(values: list[float]) -> Result:
    return {
        "median": round(statistics.median(values), 3),
        "p90": round(float(np.percentile(values, 90)), 3),
        "mean": round(float(np.mean(values)), 3),
    }


def hall_figures(hall: Hall, repeat: int) -> Result:
    """Per-search figures on one hall, with and without landmarks."""
    static, pairs = _hall(hall)
    cache = LandmarkCache(static)
    plan(static.cost, pairs[0][0], pairs[0][0])  # compile or load the kernels
    start = time.perf_counter()
    marks = {1.0: cache.get(1.0)}
    build_w1 = time.perf_counter() - start
    start = time.perf_counter()
    marks[0.0] = cache.get(0.0)
    build_w0 = time.perf_counter() - start
    times: dict[str, list[float]] = {k: [] for k in ("plan", "plan_alt", "yard", "yard_alt")}
    expansions: dict[str, list[float]] = {k: [] for k in times}
    for rep in range(repeat):
        for s, g in pairs:
            a, b = static.cell_to_world(s), static.cell_to_world(g)
            for alt in (rep % 2 == 1, rep % 2 == 0):  # alternate which goes first
                tag = "_alt" if alt else ""
                full, yardstick = (marks[1.0], marks[0.0]) if alt else (None, None)
                t = time.perf_counter()
                used = _full(static, s, g, full)
                times["plan" + tag].append((time.perf_counter() - t) * 1e3)
                t = time.perf_counter()
                shortest_path_length_m(static, a, b, landmarks=yardstick)
                times["yard" + tag].append((time.perf_counter() - t) * 1e3)
                if rep == 0:
                    expansions["plan" + tag].append(used)
                    yard = plan(static.cost, s, g, cost_weight=0.0, landmarks=yardstick)
                    expansions["yard" + tag].append(yard.expansions)
    per_goal = {k: float(np.mean(v)) for k, v in times.items()}
    saved_ms = per_goal["plan"] + per_goal["yard"] - per_goal["plan_alt"] - per_goal["yard_alt"]
    build_s = build_w1 + build_w0
    return {
        "robots": hall.robots,
        "hall_m": hall.side_m,
        "grid_cells": [static.width, static.height],
        "searches": len(pairs),
        "ms": {k: _stats(v) for k, v in times.items()},
        "expansions": {k: _stats(v) for k, v in expansions.items()},
        "build_s": {"cost_weight_1": round(build_w1, 3), "cost_weight_0": round(build_w0, 3)},
        "fields_mb": round((marks[1.0].nbytes + marks[0.0].nbytes) / 2**20, 1),
        "saved_ms_per_goal": round(saved_ms, 3),
        "goals_to_break_even": round(build_s * 1e3 / saved_ms) if saved_ms > 0 else None,
    }


def landmark_savings(repeat: int) -> Result:
    """:func:`hall_figures` for every hall of the scale study."""
    return {"halls": [hall_figures(hall, repeat) for hall in HALLS], "repeat": repeat}


if __name__ == "__main__":
    print(json.dumps(landmark_savings(int(sys.argv[1]) if len(sys.argv) > 1 else 2), indent=2))
