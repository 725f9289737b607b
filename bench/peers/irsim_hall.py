"""The fleet50 hall in IR-SIM-X (irsim-x 1.1.4): kinematics and lidar, nothing else.

Runs in a virtual environment of its own (``make bench-peers`` makes it): it imports no
cosim. It reads the hall cosim generates (walls, shelves, robot starts and goals, in m,
frame ``map``) from a JSON file, writes the IR-SIM world file, and prints one JSON line:
the wall time of ``steps`` steps of ``step_s`` each, world built before the clock starts.

The lidar: 360 beams over 2 pi minus one beam's width (IR-SIM wraps an angle range of
exactly 2 pi to 0 and then casts every beam at one angle), 10 m range, every step.
"""

from __future__ import annotations

import json
import math
import sys
import tempfile
import time
from pathlib import Path

import irsim
import numpy as np


def _box(box: list[float]) -> dict[str, object]:
    x0, y0, x1, y1 = box
    return {
        "shape": {"name": "rectangle", "length": x1 - x0, "width": y1 - y0},
        "state": [(x0 + x1) / 2, (y0 + y1) / 2, 0.0],
    }


def world_yaml(hall: dict[str, object], step_s: float) -> dict[str, object]:
    """IR-SIM's world description of the hall."""
    boxes = [_box(b) for b in hall["boxes"]]  # type: ignore[attr-defined]
    starts = hall["starts"]
    goals = hall["goals"]
    beams = int(hall["beams"])  # type: ignore[call-overload]
    return {
        "world": {
            "height": hall["size_m"][1] + 2.0,  # type: ignore[index]
            "width": hall["size_m"][0] + 2.0,  # type: ignore[index]
            "offset": [-1.0, -1.0],
            "step_time": step_s,
            "sample_time": step_s,
            "collision_mode": "unobstructed",
        },
        "robot": [
            {
                "number": len(starts),  # type: ignore[arg-type]
                "distribution": {"name": "manual"},
                "kinematics": {"name": "diff"},
                "shape": {"name": "circle", "radius": hall["radius_m"]},
                "state": [list(s) for s in starts],  # type: ignore[union-attr]
                "goal": [list(g) for g in goals],  # type: ignore[union-attr]
                "vel_max": [hall["speed_mps"], 1.0],
                "behavior": {"name": "dash"},
                "sensors": [
                    {
                        "name": "lidar2d",
                        "range_min": 0.1,
                        "range_max": hall["range_m"],
                        "angle_range": 2 * math.pi - 2 * math.pi / beams,
                        "number": beams,
                    }
                ],
            }
        ],
        "obstacle": [
            {
                "number": len(boxes),
                "distribution": {"name": "manual"},
                "shape": [b["shape"] for b in boxes],
                "state": [b["state"] for b in boxes],
            }
        ],
    }


def main() -> None:
    hall = json.loads(Path(sys.argv[1]).read_text())
    steps = int(sys.argv[2])
    step_s = float(sys.argv[3])
    import yaml

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "hall.yaml"
        path.write_text(yaml.safe_dump(world_yaml(hall, step_s)))
        env = irsim.make(str(path), display=False, disable_all_plot=True)
        start = time.perf_counter()
        for _ in range(steps):
            env.step()
        wall = time.perf_counter() - start
        scan = env.robot_list[0].get_lidar_scan()
        ranges = np.asarray(scan["ranges"])
        ends = np.array([robot.state[:2, 0] for robot in env.robot_list])
        moved = float(np.mean(np.hypot(*(ends - np.asarray(hall["starts"])[:, :2]).T)))
        env.end(0)
    print(
        json.dumps(
            {
                "robots": len(hall["starts"]),
                "obstacles": len(hall["boxes"]),
                "steps": steps,
                "step_s": step_s,
                "wall_s": wall,
                "real_time_factor": steps * step_s / wall,
                "beams_per_scan": int(ranges.size),
                "beams_hit_last_scan_robot0": int(np.sum(ranges < hall["range_m"] - 1e-6)),
                "mean_distance_moved_m": moved,
                "irsim_version": irsim.__version__,
            }
        )
    )


if __name__ == "__main__":
    main()
