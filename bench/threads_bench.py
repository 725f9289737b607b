"""Both cores inside a run: the whole stack, the preset and 1,000 robots at 1 and 2 threads.

Each measurement runs in a fresh process (so its peak resident memory is its own), warms
the numba caches with a 1 s run, then times the run loop (``summary["wall_time_s"]``). The
thread counts take turns within each repetition, and the speed-up is the median of the
per-repetition ratios, so that a machine's drift cancels. The tables of the two counts are
compared too: they must be identical (``tables_identical``).
"""

from __future__ import annotations

import json
import statistics
import subprocess
import sys
from typing import Any

from cases import FULL_STACK

Result = dict[str, Any]

CASES: dict[str, tuple[dict[str, Any], float]] = {
    "fleet50_whole_stack": (FULL_STACK, 30.0),
    "fleet50_preset": ({}, 30.0),
    "fleet1000_pibt": (
        {"robots.count": 1000, "world.size_m": [100.0, 100.0], "world.shelf_count": 600},
        10.0,
    ),
}

_ONE_RUN = """
import hashlib, json, sys
import pandas as pd
import cosim


def peak_mb():
    # VmHWM: this process's own peak (ru_maxrss would keep the forking parent's across exec)
    for line in open("/proc/self/status"):
        if line.startswith("VmHWM:"):
            return int(line.split()[1]) / 1024
    return float("nan")


overrides, duration, threads = json.loads(sys.argv[1]), float(sys.argv[2]), int(sys.argv[3])
scenario = cosim.load_scenario("fleet50", overrides)
cosim.run(scenario, duration_s=1.0, seed=5, threads=threads)
result = cosim.run(scenario, duration_s=duration, seed=5, threads=threads)
digest = hashlib.sha256()
for name, frame in sorted(result.tables.items()):
    frame = frame.drop(columns=[c for c in frame.columns if c == "plan_ms"])
    digest.update(pd.util.hash_pandas_object(frame, index=True).to_numpy().tobytes())
print(json.dumps({
    "wall_time_s": result.summary["wall_time_s"],
    "real_time_factor": result.summary["real_time_factor"],
    "thread_busy_share": result.summary["thread_busy"]["share_of_wall"],
    "peak_rss_mb": peak_mb(),
    "tables": digest.hexdigest()[:16],
}))
"""


def one_run(overrides: dict[str, Any], duration_s: float, threads: int) -> Result:
    """One measured run in a fresh process (see the module docstring)."""
    done = subprocess.run(
        [sys.executable, "-c", _ONE_RUN, json.dumps(overrides), str(duration_s), str(threads)],
        capture_output=True,
        text=True,
        check=True,
    )
    result: Result = json.loads(done.stdout.strip().splitlines()[-1])
    return result


def threads_speedup(repeat: int) -> Result:
    """Real-time factor, thread busy shares and peak memory at 1 and 2 threads, per case."""
    out: Result = {}
    for name, (overrides, duration_s) in CASES.items():
        runs: dict[int, list[Result]] = {1: [], 2: []}
        for _ in range(repeat):
            for threads in (1, 2):
                runs[threads].append(one_run(overrides, duration_s, threads))
        ratios = [
            two["real_time_factor"] / one["real_time_factor"]
            for one, two in zip(runs[1], runs[2], strict=True)
        ]
        out[name] = {
            "overrides": overrides,
            "sim_time_s": duration_s,
            **{
                f"threads_{t}": {
                    "real_time_factor_median": round(
                        statistics.median(r["real_time_factor"] for r in runs[t]), 2
                    ),
                    "real_time_factor_all": [r["real_time_factor"] for r in runs[t]],
                    "thread_busy_share_last": runs[t][-1]["thread_busy_share"],
                    "peak_rss_mb_max": round(max(r["peak_rss_mb"] for r in runs[t]), 1),
                }
                for t in (1, 2)
            },
            "speedup_2_threads_median": round(statistics.median(ratios), 3),
            "speedup_2_threads_all": [round(r, 3) for r in ratios],
            "tables_identical": len({r["tables"] for rs in runs.values() for r in rs}) == 1,
        }
    out["repeat"] = repeat
    out["note"] = "fresh process per run, numba caches warmed by a 1 s run, seed 5, no bag"
    return out
