"""Study throughput at scale (issue 16): 200 runs of ``warehouse-random`` x 300 s on 2 workers.

Target: the whole study within 5 minutes of wall time on the 2-core machine.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path
from typing import Any

from cosim.studies import load_study, run_study

Result = dict[str, Any]
RUNS = 200
DURATION_S = 300.0
WORKERS = 2
TARGET_WALL_S = 300.0

STUDY_TEXT = f"""
[study]
name = "bench_study_200"
scenario = "warehouse-random"
seeds = {RUNS}
duration_s = {DURATION_S}

[overrides]
"record.messages" = false
"record.bag" = "none"
"""


def study_throughput_200(repeat: int) -> Result:
    """Wall time and runs per minute of a 200-run study on 2 local workers, once.

    Args:
        repeat: ignored: the study runs once (it takes minutes).
    """
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "study.toml"
        path.write_text(STUDY_TEXT)
        start = time.perf_counter()
        spec = load_study(path)
        results = run_study(spec, Path(tmp) / "out", workers=WORKERS, report=False)
        wall = time.perf_counter() - start
    ok = results[results["status"] == "ok"]
    run_wall = float(ok["wall_time_s"].sum())
    return {
        "scenario": "warehouse-random",
        "runs": RUNS,
        "runs_failed": len(results) - len(ok),
        "sim_time_s_per_run": DURATION_S,
        "workers": WORKERS,
        "wall_s": round(wall, 2),
        "runs_per_min": round(RUNS / wall * 60, 2),
        "run_wall_time_s_sum": round(run_wall, 2),
        "run_wall_time_s_mean": round(run_wall / max(len(ok), 1), 3),
        "share_in_run_loops": round(run_wall / (WORKERS * wall), 3),
        "target_wall_s": TARGET_WALL_S,
        "met": wall <= TARGET_WALL_S,
        "note": (
            "wall_s: study validation, forkserver workers' start-up, every run's set-up and "
            "the writing of the run folders included; share_in_run_loops: the runs' own "
            "wall_time_s (kernel loop) over 2 x wall_s"
        ),
    }
