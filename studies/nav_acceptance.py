"""Navigation acceptance: presets x seeds x 300 s on an ideal network.

Acceptance (issue "Collision-free navigation with local replanning"): 0 collisions, and
every reachable goal reached (no goal missed; random goals are reachable by construction,
goals still being driven to when the run ends are not counted as missed).

    .venv/bin/python studies/nav_acceptance.py --seeds 10 --duration-s 300 --workers 2

Writes studies/results/nav_acceptance.csv and .md and prints the table.
"""

from __future__ import annotations

import argparse
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

import pandas as pd

import cosim

PRESETS = ("warehouse-random", "warehouse-rows", "fleet50")
KEYS = (
    "robots",
    "collisions",
    "near_misses",
    "min_clearance_m",
    "goals",
    "arrivals",
    "goals_missed",
    "goals_unreachable",
    "deadlocks",
    "recoveries",
    "mean_time_to_goal_s",
    "path_length_ratio",
    "real_time_factor",
    "wall_time_s",
)


def one(job: tuple[str, int, float]) -> dict[str, Any]:
    preset, seed, duration = job
    scenario = cosim.load_scenario(
        preset,
        {"network.profile": "ideal", "robots.driver": "navigation", "record.messages": False},
    )
    summary = cosim.run(scenario, seed=seed, duration_s=duration).summary
    return {"preset": preset, "seed": seed, **{k: summary.get(k) for k in KEYS}}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=10)
    parser.add_argument("--duration-s", type=float, default=300.0)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--presets", nargs="*", default=list(PRESETS))
    parser.add_argument("--out", type=Path, default=Path(__file__).parent / "results")
    args = parser.parse_args(argv)
    jobs = [(p, s, args.duration_s) for p in args.presets for s in range(1, args.seeds + 1)]
    start = time.perf_counter()
    rows = []
    with ProcessPoolExecutor(args.workers) as pool:
        for k, row in enumerate(pool.map(one, jobs), 1):
            rows.append(row)
            print(
                f"[{k}/{len(jobs)}] {row['preset']} seed {row['seed']}: "
                f"collisions {row['collisions']}, missed {row['goals_missed']}, "
                f"arrivals {row['arrivals']}, rtf {row['real_time_factor']}",
                file=sys.stderr,
                flush=True,
            )
    frame = pd.DataFrame(rows)
    args.out.mkdir(parents=True, exist_ok=True)
    frame.to_csv(args.out / "nav_acceptance.csv", index=False)
    totals = frame.groupby("preset").agg(
        runs=("seed", "count"),
        collisions=("collisions", "sum"),
        goals_missed=("goals_missed", "sum"),
        arrivals=("arrivals", "sum"),
        deadlocks=("deadlocks", "sum"),
        near_misses=("near_misses", "sum"),
        min_clearance_m=("min_clearance_m", "min"),
        path_length_ratio=("path_length_ratio", "mean"),
        rtf_median=("real_time_factor", "median"),
    )
    text = (
        f"# Navigation acceptance\n\n{args.seeds} seeds x {args.duration_s:g} s, ideal "
        f"network, {time.perf_counter() - start:.0f} s wall on {args.workers} workers.\n\n"
        + totals.to_markdown()
        + "\n"
    )
    (args.out / "nav_acceptance.md").write_text(text)
    print(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
