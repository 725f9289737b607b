"""Cost of the SUMO coupling: warehouse-humans with 10 and 100 workers, and without people."""

from __future__ import annotations

import statistics
import tempfile
import time
from pathlib import Path
from typing import Any

import cosim
from adapters.humans.session import SumoSession
from cosim.runner.execute import run

Result = dict[str, Any]
DURATION_S = 60.0


def _scenario(workers: int) -> cosim.Scenario:
    return cosim.load_scenario(
        "warehouse-humans",
        {
            "humans.workers": workers,
            "scenario.duration_s": DURATION_S,
            "record.bag": "none",
            "record.messages": False,
        },
    )


def _sumo_alone(folder: Path) -> float:
    """Wall seconds SUMO alone needs for the run's people (its files, no robots, no reads)."""
    session = SumoSession(folder / "humans.sumocfg", seed=1)
    try:
        start = time.perf_counter()
        for k in range(1, int(DURATION_S * 10)):
            session.step(k / 10)
        return time.perf_counter() - start
    finally:
        session.close()


def humans_coupling(repeat: int) -> Result:
    """Per simulated second: the coupling (mirror robots, step SUMO, read people, keep them
    clear of robots and pace them, metrics),
    SUMO's own stepping, and the whole run with 0, 10 and 100 workers (interleaved).

    The whole run's extra wall time over 0 workers is split into the coupling and the rest
    (``beyond_coupling``): SUMO start-up and files, encounter metrics and the people table,
    lidar and collision checks against people, and the robots replanning around them.
    """
    counts = (0, 10, 100)
    walls: dict[int, list[float]] = {n: [] for n in counts}
    coupling: dict[int, list[float]] = {n: [] for n in counts[1:]}
    alone: dict[int, list[float]] = {n: [] for n in counts[1:]}
    last: dict[int, dict[str, Any]] = {}
    with tempfile.TemporaryDirectory() as tmp:  # caches and libsumo warm before timing
        run(_scenario(10).with_duration(5.0), out=Path(tmp) / "run")
    for _ in range(repeat):
        for n in counts:
            with tempfile.TemporaryDirectory() as tmp:
                result = run(_scenario(n), out=Path(tmp) / "run")
                walls[n].append(result.summary["wall_time_s"])
                last[n] = result.summary
                if n:
                    coupling[n].append(result.summary["humans_coupling_wall_s"])
                    alone[n].append(_sumo_alone(Path(tmp) / "run" / "sumo"))
    per_s = {n: round(1e3 * statistics.median(v) / DURATION_S, 2) for n, v in coupling.items()}
    result: Result = {
        "scenario": "warehouse-humans (4 robots, tasks), 60 s, no bag",
        "coupling_ms_per_sim_s": {str(n): v for n, v in per_s.items()},
        "sumo_alone_ms_per_sim_s": {
            str(n): round(1e3 * statistics.median(v) / DURATION_S, 2) for n, v in alone.items()
        },
        "run_wall_s_median": {str(n): round(statistics.median(v), 3) for n, v in walls.items()},
        "real_time_factor": {
            str(n): round(DURATION_S / statistics.median(v), 1) for n, v in walls.items()
        },
        "near_misses": {str(n): last[n].get("humans_near_misses", 0) for n in counts},
        "replans": {str(n): last[n].get("replans") for n in counts},
        "person_contacts": {str(n): last[n].get("humans_collisions") for n in counts[1:]},
        "trips": {str(n): last[n].get("humans_trips") for n in counts[1:]},
        "repeat": repeat,
    }
    base = statistics.median(walls[0])
    extra = {n: 1e3 * (statistics.median(walls[n]) - base) / DURATION_S for n in counts[1:]}
    result["run_extra_ms_per_sim_s"] = {str(n): round(v, 2) for n, v in extra.items()}
    result["beyond_coupling_ms_per_sim_s"] = {
        str(n): round(extra[n] - per_s[n], 2) for n in counts[1:]
    }
    return result
