"""The benchmark suites, by name. Each takes a repetition count and returns a JSON dict."""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable
from typing import Any

import cosim
from cosim.kernel import Kernel, Stage

Result = dict[str, Any]


def _median(values: list[float]) -> float:
    return round(statistics.median(values), 4)


def warehouse_random_60s(repeat: int) -> Result:
    """Wall time and real-time factor of the default scenario for 60 s of sim time."""
    scenario = cosim.load_scenario("warehouse-random", {"scenario.duration_s": 60.0})
    walls, events = [], []
    for seed in range(1, repeat + 1):
        result = cosim.run(scenario, seed=seed)
        walls.append(result.summary["wall_time_s"])
        events.append(result.summary["events"])
    wall = _median(walls)
    return {
        "scenario": "warehouse-random",
        "sim_time_s": 60.0,
        "wall_time_s_median": wall,
        "real_time_factor_median": round(60.0 / wall, 2),
        "wall_time_s_all": walls,
        "events_median": statistics.median(events),
        "repeat": repeat,
    }


def kernel_periodic_1000(repeat: int) -> Result:
    """Kernel events per second: 1,000 periodic callbacks at 100 Hz for 10 s of sim time."""
    rates = []
    for _ in range(repeat):
        kernel = Kernel()
        counter = [0]

        def tick(now: int, counter: list[int] = counter) -> None:
            counter[0] += 1

        for i in range(1000):
            kernel.every(10_000_000, tick, stage=Stage.CONTROL, start_ns=i * 10_000)
        start = time.perf_counter()
        processed = kernel.run(10_000_000_000)
        wall = time.perf_counter() - start
        assert counter[0] == processed
        rates.append(processed / wall)
    return {
        "processes": 1000,
        "rate_hz": 100,
        "sim_time_s": 10.0,
        "events": 1_000_000,
        "events_per_s_median": round(statistics.median(rates)),
        "repeat": repeat,
    }


SUITES: dict[str, Callable[[int], Result]] = {
    "warehouse_random_60s": warehouse_random_60s,
    "kernel_periodic_1000": kernel_periodic_1000,
}
