"""What mapping costs: a map update and a scan match per scan, a fleet mapping, a real recording.

Targets (issue 12): ``fleet50`` with mapping and navigation >= 10x real time on one core;
``cosim map`` on the shared building recordings >= 100x their real time with loop closure
(issue 33; issue 12 asked 20x).
"""

from __future__ import annotations

import math
import statistics
import time
from pathlib import Path
from typing import Any

import numpy as np

import cosim
from adapters.world.warehouse import scenario_warehouse
from cosim.runner.execute import execute
from models.mapping.grid import LogOddsMap, MapGeometry
from models.mapping.matcher import MatcherParams, match, scan_points
from models.sensing.lidar import ScanGeometry
from models.sensing.raycast import StaticScene, cast_batch

Result = dict[str, Any]
SHARED = Path(__file__).resolve().parents[2] / "shared" / "data"


def _scans(
    count: int,
) -> tuple[list[tuple[float, float, float]], list[np.ndarray], np.ndarray, Any]:
    """Exact 360-beam scans along a line through the warehouse-random hall."""
    world = scenario_warehouse(cosim.load_scenario("warehouse-random"))
    geometry = ScanGeometry(360, 2 * math.pi, 0.1, 10.0)
    angles = geometry.angles()
    scene = StaticScene(world.segments(), cell_m=1.0)
    poses = [(2.0 + 0.5 * k % 26.0, 5.0 + 0.37 * k % 20.0, 0.3 * k) for k in range(count)]
    poses = [p for p in poses if world.is_free(np.array([p[:2]]), 0.4)[0]]
    ranges = [
        cast_batch(
            scene, np.array([p[:2]]), np.array([p[2]]), angles, np.zeros((0, 3)),
            np.zeros(0, dtype=np.int64), 10.0,
        )[0].astype(np.float32)
        for p in poses
    ]  # fmt: skip
    return poses, ranges, angles, world


def per_scan_costs(repeat: int) -> Result:
    """Median cost of one map update (360 beams, 10 m) and one scan match, in the 30 m hall."""
    poses, ranges, angles, world = _scans(200)
    geometry = MapGeometry.covering(world.bounds, 0.05, 1.0)
    update_us, match_us = [], []
    for _ in range(max(repeat, 3)):
        grid = LogOddsMap(geometry)
        for pose, r in zip(poses, ranges, strict=True):
            start = time.perf_counter()
            grid.integrate(
                pose, angles, r, range_min_m=0.1, range_max_m=10.0, clear_no_return_m=3.0
            )
            update_us.append((time.perf_counter() - start) * 1e6)
        params = MatcherParams()
        for pose, r in zip(poses, ranges, strict=True):
            points = scan_points(angles, r, 0.1, 10.0, params.max_points)
            prior = (pose[0] + 0.13, pose[1] - 0.09, pose[2] + 0.04)
            start = time.perf_counter()
            match(grid, prior, points, params)
            match_us.append((time.perf_counter() - start) * 1e6)
    return {
        "map_update_us_median": round(statistics.median(update_us), 1),
        "scan_match_us_median": round(statistics.median(match_us), 1),
        "scan_match_us_p95": round(float(np.percentile(match_us, 95)), 1),
        "scans": len(poses),
        "window": "+-0.3 m, +-0.12 rad, 240 points, refined",
    }


def fleet50_mapping(repeat: int) -> Result:
    """fleet50 with navigation, with and without mapping (drift 0.02), 30 s, same run."""
    base = {"scenario.duration_s": 30.0, "navigation.traffic": "none"}  # every robot plans
    plain = cosim.load_scenario("fleet50", base)
    mapped = cosim.load_scenario(
        "fleet50", {**base, "mapping.enabled": True, "odometry.drift": 0.02}
    )
    execute(mapped.with_duration(2.0))  # JIT caches warm
    walls: dict[str, list[float]] = {"navigation": [], "navigation_mapping": []}
    last: dict[str, Any] = {}
    for _ in range(max(1, repeat - 1)):
        for name, scenario in (("navigation", plain), ("navigation_mapping", mapped)):
            result = execute(scenario)
            walls[name].append(result.summary["wall_time_s"])
            last[name] = result.summary
    rtf = {name: round(30.0 / statistics.median(w), 2) for name, w in walls.items()}
    s = last["navigation_mapping"]
    return {
        "real_time_factor_navigation": rtf["navigation"],
        "real_time_factor_navigation_mapping": rtf["navigation_mapping"],
        "target_real_time_factor": 10.0,
        "met": rtf["navigation_mapping"] >= 10.0,
        "map_ate_m": s["map_ate_m"],
        "map_ate_odom_m": s["map_ate_odom_m"],
        "collisions": s["collisions"],
        "wall_s_all": walls,
    }


RECORDINGS = ("aces_lidar", "aces_lidar_s12", "aces_lidar_s13", "fr079_lidar")


def recordings_mapping(repeat: int) -> Result:
    """`cosim map` on every shared building recording: speed and error, with and without loops.

    Target (issue 33): >= 100x the recording's real time with loop closure, and loop
    closure never more than 1 cm worse than scan-to-map alone.
    """
    from adapters.mapping.bagmap import map_scans
    from adapters.mapping.recording import read_recording
    from models.mapping.quality import ate_rmse

    out: Result = {"target_real_time_factor": 100.0}
    for name in RECORDINGS:
        bag = SHARED / name
        if not bag.is_dir():
            out[name] = {"skipped": f"{bag} is not beside this clone"}
            continue
        recording = read_recording(bag, reference_topic="/ground_truth")
        assert recording.reference is not None
        reference = recording.reference[:, :2]
        row: Result = {
            "recording_s": round(float(recording.stamps_ns[-1] - recording.stamps_ns[0]) / 1e9, 1),
            "ate_odom_m": round(ate_rmse(recording.odometry[:, :2], reference, align=True), 4),
        }
        for loops in (True, False):
            key = "loop_closure" if loops else "scan_to_map_only"
            rtfs = []
            for _ in range(max(1, repeat - 1)):
                mapped = map_scans(
                    recording.stamps_ns, recording.ranges_m, recording.odometry,
                    recording.angles_rad, range_min_m=recording.range_min_m,
                    range_max_m=recording.range_max_m, loop_closure=loops,
                )  # fmt: skip
                rtfs.append(mapped.span_s / mapped.wall_s)
            loops_used = mapped.mapper.loops
            row[key] = {
                "real_time_factor_median": round(statistics.median(rtfs), 1),
                "ate_m": round(ate_rmse(mapped.estimate_xy_m(), reference, align=True), 4),
                "loop_closures": loops_used.closures if loops_used is not None else 0,
            }
        row["met"] = (
            row["loop_closure"]["real_time_factor_median"] >= 100.0
            and row["loop_closure"]["ate_m"] <= row["scan_to_map_only"]["ate_m"] + 0.01
        )
        out[name] = row
    return out
