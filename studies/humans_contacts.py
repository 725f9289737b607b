"""Do people walk into robots? Contacts, near misses, stops, walking speed and trips.

Runs ``warehouse-humans`` over seeds for a few cases and prints one row per case (and,
with ``--json``, every run's figures). A contact is a row of ``tables/collisions`` whose
kind is ``person`` (``forklift`` counted apart); "at rest" means the robot stood still
(its commanded speed below ``HALT_MPS``): the person walked into it.

    .venv/bin/python studies/humans_contacts.py --cases w10 w20r6f2 --json out.json

Cases: ``w10`` 10 workers, 4 robots, 20 seeds x 300 s; ``w20r6`` 20 workers, 6 robots,
5 seeds x 300 s; ``w20r6f2`` the same with 2 forklifts; ``w10f2`` 10 workers and 2
forklifts, 5 seeds x 300 s; ``w100`` 100 workers, 2 seeds x 120 s.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from typing import Any

import cosim
from cosim.runner.execute import run

HALT_MPS = 0.02
CASES: dict[str, tuple[dict[str, Any], int, float]] = {
    "w10": ({"humans.workers": 10}, 20, 300.0),
    "w20r6": ({"humans.workers": 20, "robots.count": 6}, 5, 300.0),
    "w20r6f2": ({"humans.workers": 20, "robots.count": 6, "humans.forklifts": 2}, 5, 300.0),
    "w10f2": ({"humans.workers": 10, "humans.forklifts": 2}, 5, 300.0),
    "w100": ({"humans.workers": 100}, 2, 120.0),
}


def one_run(overrides: dict[str, Any], seed: int, duration_s: float) -> dict[str, Any]:
    """One run's figures."""
    scenario = cosim.load_scenario(
        "warehouse-humans",
        {**overrides, "record.bag": "none", "record.messages": False},
    )
    began = time.perf_counter()
    result = run(scenario, seed=seed, duration_s=duration_s)
    wall = time.perf_counter() - began
    s = result.summary
    hits = result.tables["collisions"]
    people = hits[hits["kind"] == "person"] if len(hits) else hits
    forks = hits[hits["kind"] == "forklift"] if len(hits) else hits
    table = result.tables["humans"]
    walkers = table[table["kind"] == "person"]
    moving = walkers[walkers["speed_mps"] > 0.05]
    return {
        "seed": seed,
        "person_contacts": len(people),
        "person_contacts_robot_at_rest": int((people["speed_mps"].abs() < HALT_MPS).sum())
        if len(people)
        else 0,
        "person_depth_max_m": round(float(people["depth_m"].max()), 3) if len(people) else 0.0,
        "forklift_contacts": len(forks),
        "min_distance_m": s.get("humans_min_distance_m"),
        "near_misses": s.get("humans_near_misses"),
        "robot_stops": s.get("humans_robot_stops"),
        "trips": s.get("humans_trips"),
        "waits": s.get("humans_yields"),
        "steps_cut": s.get("humans_steps_cut"),
        "walking_speed_mps": round(float(moving["speed_mps"].mean()), 4) if len(moving) else 0.0,
        "mean_speed_mps": round(float(walkers["speed_mps"].mean()), 4) if len(walkers) else 0.0,
        "tasks_per_min": s.get("tasks_per_min"),
        "coupling_ms_per_sim_s": round(1e3 * s["humans_coupling_wall_s"] / duration_s, 3),
        "wall_s": round(wall, 2),
        "rows_hash": int(
            __import__("pandas").util.hash_pandas_object(table, index=False).sum() % (1 << 61)
        ),
    }


def main() -> None:
    """Run the cases asked for and print a row per case."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", nargs="+", default=list(CASES), choices=list(CASES))
    parser.add_argument("--seeds", type=int, default=None, help="fewer seeds than the case's")
    parser.add_argument("--json", default=None, help="write every run's figures here")
    args = parser.parse_args()
    out: dict[str, list[dict[str, Any]]] = {}
    for case in args.cases:
        overrides, seeds, duration = CASES[case]
        rows = []
        for seed in range(1, (args.seeds or seeds) + 1):
            rows.append(one_run(overrides, seed, duration))
            print(case, rows[-1], flush=True)
        out[case] = rows

        def total(key: str, rows: list[dict[str, Any]] = rows) -> Any:
            return sum(r[key] for r in rows)

        def mean(key: str, rows: list[dict[str, Any]] = rows) -> float:
            return round(statistics.mean(r[key] for r in rows), 3)

        figures = [
            f"person contacts {total('person_contacts')}",
            f"robot at rest {total('person_contacts_robot_at_rest')}",
            f"deepest {max(r['person_depth_max_m'] for r in rows)} m",
            f"forklift contacts {total('forklift_contacts')}",
            f"min distance {min(r['min_distance_m'] for r in rows)} m",
            f"near misses {mean('near_misses')}",
            f"robot stops {mean('robot_stops')}",
            f"trips {mean('trips')}",
            f"waits {mean('waits')}",
            f"steps cut {total('steps_cut')}",
            f"walking {mean('walking_speed_mps')} m/s",
            f"mean {mean('mean_speed_mps')} m/s",
            f"tasks/min {mean('tasks_per_min')}",
            f"coupling {mean('coupling_ms_per_sim_s')} ms/sim s",
            f"wall {mean('wall_s')} s",
        ]
        print(f"== {case}: {len(rows)} runs x {duration:g} s | " + " | ".join(figures), flush=True)
    if args.json:
        with open(args.json, "w", encoding="utf-8") as handle:
            json.dump(out, handle, indent=1)


if __name__ == "__main__":
    main()
