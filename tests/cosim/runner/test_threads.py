"""A run's tables and bag are the same with one thread and with two, on the acceptance runs."""

from __future__ import annotations

import hashlib
import threading
from pathlib import Path

import pandas as pd
import pytest

import cosim
from adapters.navigation.astar import AStar
from cosim.testing.outcomes import VOLATILE

WALL_CLOCK_COLUMNS = {"plan_ms"}
"""Table columns that measure the machine (how long a plan took), not the simulation."""

WHOLE_STACK = {
    "navigation.traffic": "none",
    "robots.driver": "tasks",
    "tasks.initial": 50,
    "assignment.protocol": "distributed_simplex",
    "mapping.enabled": True,
    "odometry.drift": 0.02,
}

CASES = {
    "warehouse-random": ("warehouse-random", {}, 20.0),
    "warehouse-rows": ("warehouse-rows", {}, 20.0),
    "warehouse-mapping": ("warehouse-mapping", {}, 20.0),
    "lab-room": ("lab-room", {}, 20.0),
    "fleet50": ("fleet50", {}, 8.0),
    "fleet50-whole-stack": ("fleet50", WHOLE_STACK, 8.0),
}


def _tables(folder: Path) -> dict[str, str]:
    hashes = {}
    for path in sorted((folder / "tables").glob("*.parquet")):
        frame = pd.read_parquet(path)
        frame = frame.drop(columns=[c for c in frame.columns if c in WALL_CLOCK_COLUMNS])
        digest = pd.util.hash_pandas_object(frame, index=True).to_numpy().tobytes()
        hashes[path.name] = hashlib.sha256(digest + str(list(frame.columns)).encode()).hexdigest()
    return hashes


def _bag(folder: Path) -> dict[str, str]:
    return {
        path.name: hashlib.sha256(path.read_bytes()).hexdigest()
        for path in sorted((folder / "bag").iterdir())
    }


@pytest.mark.slow
@pytest.mark.parametrize("case", sorted(CASES))
def test_tables_and_bag_are_the_same_with_one_thread_and_with_two(tmp_path, case):
    preset, overrides, duration_s = CASES[case]
    scenario = cosim.load_scenario(preset, overrides)
    results = {}
    for threads in (1, 2):
        out = tmp_path / f"threads{threads}"
        results[threads] = cosim.run(
            scenario, seed=4, duration_s=duration_s, out=out, threads=threads
        )
    one, two = tmp_path / "threads1", tmp_path / "threads2"
    assert _tables(one) == _tables(two)
    assert _bag(one) == _bag(two)
    assert results[1].summary["threads"] == 1 and results[2].summary["threads"] == 2
    busy = results[2].summary["thread_busy"]
    assert len(busy["busy_s"]) == 2
    volatile = {*VOLATILE, "compile_time_s"}
    kept = {k: v for k, v in results[1].summary.items() if k not in volatile}
    assert kept == {k: v for k, v in results[2].summary.items() if k not in volatile}


@pytest.mark.slow
def test_a_planner_that_does_not_say_it_is_concurrent_plans_on_the_run_s_own_thread(
    monkeypatch,
):
    threads_seen: set[int] = set()
    plan = AStar.plan

    def watched(self, request):
        threads_seen.add(threading.get_ident())
        return plan(self, request)

    monkeypatch.setattr(AStar, "plan", watched)
    monkeypatch.setattr(AStar, "concurrent", False)
    scenario = cosim.load_scenario("fleet50", WHOLE_STACK)
    cosim.run(scenario, seed=4, duration_s=6.0, threads=2)
    assert threads_seen == {threading.get_ident()}
