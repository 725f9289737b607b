"""Dynamic Window Approach: microseconds per robot per call, 50 robots, one core.

The scene is the fleet50 hall (30 m x 30 m, all_rows, 72 shelves, 50 robots placed at
random); each robot's obstacle points come from a real 360-beam, 10 m scan of it (walls,
shelves and the other robots), with points beyond 3 m dropped as a caller would, and the
other robots within 3 m are also given as discs, as if known through the network.
"""

from __future__ import annotations

import json
import math
import statistics
import time
from typing import Any

import numpy as np

from models.fleet.kinematics import DriveLimits
from models.navigation.dwa import DwaParams, dwa_batch
from models.sensing.raycast import StaticScene, cast_batch
from models.world.warehouse import WarehouseSpec, generate_warehouse

Result = dict[str, Any]

ROBOTS = 50
BEAMS = 360
RANGE_MAX_M = 10.0
KEEP_M = 3.0
RADIUS_M = 0.33
LIMITS = DriveLimits(1.0, 0.3, 2.0, 2.0, 3.0)
CALLS_PER_REPEAT = 20


def fleet_scene(seed: int = 1) -> dict[str, Any]:
    """The arguments of :func:`dwa_batch` for the 50-robot hall, plus scene statistics."""
    spec = WarehouseSpec(layout="all_rows", shelf_count=72, robot_count=ROBOTS, placement="random")
    world = generate_warehouse(spec, np.random.default_rng(seed))
    poses = np.ascontiguousarray(world.starts)
    beams = -math.pi + 2 * math.pi / BEAMS * np.arange(BEAMS, dtype=np.float64)
    circles = np.column_stack([poses[:, :2], np.full(ROBOTS, RADIUS_M)])
    ranges = cast_batch(
        StaticScene(world.segments()),
        np.ascontiguousarray(poses[:, :2]),
        np.ascontiguousarray(poses[:, 2]),
        beams,
        circles,
        np.arange(ROBOTS, dtype=np.int64),
        RANGE_MAX_M,
    )
    points, counts, discs, disc_counts = [], [], [], []
    for i in range(ROBOTS):
        keep = ranges[i] <= KEEP_M
        angle = poses[i, 2] + beams[keep]
        r = ranges[i, keep]
        points.append(poses[i, :2] + np.column_stack([r * np.cos(angle), r * np.sin(angle)]))
        counts.append(int(keep.sum()))
        near = np.hypot(*(poses[:, :2] - poses[i, :2]).T) <= KEEP_M
        near[i] = False
        discs.append(circles[near])
        disc_counts.append(int(near.sum()))
    rng = np.random.default_rng(seed)
    # moving robots with carrots ahead-ish on their paths and goals farther on
    bearing = poses[:, 2] + rng.uniform(-1.0, 1.0, ROBOTS)
    carrots = poses[:, :2] + 1.5 * np.column_stack([np.cos(bearing), np.sin(bearing)])
    goals = poses[:, :2] + 6.0 * np.column_stack([np.cos(bearing), np.sin(bearing)])
    return {
        "args": (
            poses,
            np.column_stack([rng.uniform(0.0, 1.0, ROBOTS), rng.uniform(-0.5, 0.5, ROBOTS)]),
            LIMITS,
            np.full(ROBOTS, RADIUS_M),
            carrots,
            goals,
            np.vstack(points),
            np.concatenate([[0], np.cumsum(counts)]).astype(np.int64),
            np.vstack(discs),
            np.concatenate([[0], np.cumsum(disc_counts)]).astype(np.int64),
            DwaParams(),
        ),
        "points_per_robot_mean": round(float(np.mean(counts)), 1),
        "discs_per_robot_mean": round(float(np.mean(disc_counts)), 2),
    }


def dwa_us_per_robot(repeat: int) -> Result:
    """Median microseconds per robot of one :func:`dwa_batch` call over 50 robots."""
    scene = fleet_scene()
    args = scene["args"]
    start = time.perf_counter()
    first = dwa_batch(*args)  # JIT compile or cache load
    first_s = time.perf_counter() - start
    per_robot = []
    for _ in range(max(repeat, 1)):
        start = time.perf_counter()
        for _ in range(CALLS_PER_REPEAT):
            dwa_batch(*args)
        elapsed = (time.perf_counter() - start) / CALLS_PER_REPEAT
        per_robot.append(elapsed / ROBOTS * 1e6)
    return {
        "robots": ROBOTS,
        "beams": BEAMS,
        "kept_within_m": KEEP_M,
        "points_per_robot_mean": scene["points_per_robot_mean"],
        "discs_per_robot_mean": scene["discs_per_robot_mean"],
        "samples_per_robot": DwaParams().v_samples * DwaParams().w_samples,
        "blocked": int(first.blocked.sum()),
        "first_call_s": round(first_s, 4),
        "us_per_robot_median": round(statistics.median(per_robot), 2),
        "us_per_robot_all": [round(x, 2) for x in per_robot],
        "target_us_per_robot": 25.0,
        "single_thread": True,
        "repeat": repeat,
    }


if __name__ == "__main__":
    print(json.dumps(dwa_us_per_robot(20), indent=2))
