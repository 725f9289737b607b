"""Where the whole stack's wall time goes, at 1 and 2 threads, timed rather than sampled.

Each component's entry point (the lidar's scan, the physics tick, the navigation tick, a
distributed-simplex round, the batches of scans and of new maps, map quality and maps out)
is wrapped in a wall-clock timer for the measured runs only; what no timer covers (message
deliveries, the task source, the kernel itself) is the rest. A sampling profiler splits
two threads' time unreliably (it charged the scan messages with the other thread's lock
hand-overs), so this bench times.
"""

from __future__ import annotations

import collections
import functools
import statistics
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

from cases import FULL_STACK

import cosim
from adapters.assignment.dta import DtaAdapter
from adapters.fleet.motion import FleetAdapter
from adapters.mapping.mapper import MappingAdapter
from adapters.navigation.stack import NavigationAdapter
from adapters.sensing.lidar import LidarAdapter
from cosim.core.batches import InstantBatch

Result = dict[str, Any]

TIMED: list[tuple[type, str, str]] = [
    (LidarAdapter, "_scan", "lidar: cast, noise draws, scan messages"),
    (FleetAdapter, "_tick", "physics tick: kinematics, collisions, odometry messages"),
    (NavigationAdapter, "_control", "navigation tick (its replans and DWA on the threads)"),
    (DtaAdapter, "_round_of", "distributed simplex rounds: solves, claims, broadcasts"),
    (MappingAdapter, "_sample", "map quality samples"),
    (MappingAdapter, "_publish_maps", "maps out"),
]
REST = "the rest: deliveries, the task source, the kernel"


@contextmanager
def _timers(spent: collections.Counter[str]) -> Iterator[None]:
    saved: list[tuple[type, str, Callable[..., Any]]] = []

    def wrap(owner: type, name: str, label: str) -> None:
        original = getattr(owner, name)
        saved.append((owner, name, original))

        @functools.wraps(original)
        def timed(*args: Any, **kwargs: Any) -> Any:
            start = time.perf_counter()
            try:
                return original(*args, **kwargs)
            finally:
                spent[label] += time.perf_counter() - start

        setattr(owner, name, timed)

    for owner, name, label in TIMED:
        wrap(owner, name, label)
    close = InstantBatch._close

    def timed_close(batch: InstantBatch[Any, Any]) -> None:
        start = time.perf_counter()
        try:
            close(batch)
        finally:
            scans = "_process" in getattr(batch.compute, "__qualname__", "")
            label = "scan matching and map updates" if scans else "new maps' costmaps"
            spent[label] += time.perf_counter() - start

    InstantBatch._close = timed_close  # type: ignore[method-assign]
    try:
        yield
    finally:
        InstantBatch._close = close  # type: ignore[method-assign]
        for owner, name, original in saved:
            setattr(owner, name, original)


def whole_stack_breakdown(repeat: int) -> Result:
    """Seconds and shares of the run's wall time per component, whole stack, 1 and 2 threads."""
    scenario = cosim.load_scenario("fleet50", FULL_STACK)
    for threads in (1, 2):
        cosim.run(scenario, duration_s=1.0, threads=threads)  # caches warm
    shares: dict[int, dict[str, list[float]]] = {1: {}, 2: {}}
    walls: dict[int, list[float]] = {1: [], 2: []}
    for _ in range(repeat):
        for threads in (1, 2):
            spent: collections.Counter[str] = collections.Counter()
            with _timers(spent):
                result = cosim.run(scenario, seed=5, duration_s=30.0, threads=threads)
            wall = float(result.summary["wall_time_s"])
            walls[threads].append(wall)
            spent[REST] = wall - sum(spent.values())
            for label, seconds in spent.items():
                shares[threads].setdefault(label, []).append(seconds / wall)
    return {
        f"threads_{threads}": {
            "wall_time_s_all": walls[threads],
            "share_of_wall_median": {
                label: round(statistics.median(values), 3)
                for label, values in sorted(shares[threads].items(), key=lambda kv: -kv[1][0])
            },
        }
        for threads in (1, 2)
    } | {"sim_time_s": 30.0, "seed": 5, "repeat": repeat}
