"""The benchmark suites, by name. Each takes a repetition count and returns a JSON dict."""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable
from typing import Any, ClassVar

import numpy as np
from assignment_bench import assignment_solve_stats
from breakdown_bench import whole_stack_breakdown
from cases import EVERY_ROBOT_PLANS, FULL_STACK
from controllers_bench import controllers_fleet50, planners_fleet50
from dwa_bench import dwa_us_per_robot
from envs_bench import envs_steps
from humans_bench import humans_coupling
from landmarks_bench import landmark_savings
from lidar_bench import lidar_rays_per_second
from mapping_bench import fleet50_mapping, per_scan_costs, recordings_mapping
from network_bench import network_deliveries_per_second
from ns3_bench import ns3_radio
from peers_bench import irsim_peer
from planner_bench import planner_ms
from recording_bench import bag_cost, bag_memory_1h, encoding
from scale_bench import fleet_scaling
from startup_bench import cli_startup
from study_bench import study_throughput_200
from threads_bench import threads_speedup

import cosim
from cosim.core.adapter import RunContext
from cosim.core.bus import Envelope
from cosim.core.hosts import BASE_HOST, HostId
from cosim.core.kernel import Kernel, Stage
from cosim.core.messages import Message, Twist
from cosim.core.registry import AdapterRegistry
from cosim.runner.execute import execute
from models.fleet.kinematics import FleetState

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


class SineDriver:
    """Bench-only robot software: sets every robot's command directly (no bus), weaving."""

    name: ClassVar[str] = "sine_driver"
    requires: ClassVar[tuple[str, ...]] = ("fleet",)

    def __init__(self, run: RunContext) -> None:
        self.fleet = run.service(FleetState)
        self.phase = np.linspace(0.0, 2 * np.pi, len(self.fleet), endpoint=False)

    def start(self, run: RunContext) -> None:
        def drive(now: int) -> None:
            t = now / 1e9
            self.fleet.v_cmd[:] = 0.8
            self.fleet.w_cmd[:] = 0.6 * np.sin(t / 2.0 + self.phase)

        run.kernel.every(50_000_000, drive, stage=Stage.CONTROL)

    def finish(self, run: RunContext) -> dict[str, Any]:
        return {}


def _rtf_runs(
    scenario: cosim.Scenario,
    repeat: int,
    names: list[str] | None = None,
    registry: AdapterRegistry | None = None,
    threads: int = 1,
) -> Result:
    walls, summaries = [], []
    warm = scenario.with_duration(1.0)
    execute(warm, names=names, registry=registry, threads=threads)  # JIT caches warm
    for seed in range(1, repeat + 1):
        result = execute(scenario.with_seed(seed), names=names, registry=registry, threads=threads)
        walls.append(result.summary["wall_time_s"])
        summaries.append(result.summary)
    wall = statistics.median(walls)
    sim = scenario.scenario.duration_s
    last = summaries[-1]
    return {
        "sim_time_s": sim,
        "robots": last["robots"],
        "wall_time_s_median": round(wall, 4),
        "real_time_factor_median": round(sim / wall, 2),
        "wall_time_s_all": walls,
        "collisions_last": last.get("collisions"),
        "distance_m_last": last.get("distance_m"),
        "repeat": repeat,
    }


def fleet50_physics(repeat: int) -> Result:
    """fleet50: kinematics + 10 Hz lidar + collision checks; robots weave (no bus driver)."""
    scenario = cosim.load_scenario("fleet50", {"scenario.duration_s": 60.0})
    registry = AdapterRegistry.from_entry_points().with_adapter(SineDriver)
    names = ["world", "fleet", "collisions", "lidar", "poses", "sine_driver"]
    return {"adapters": names, **_rtf_runs(scenario, repeat, names, registry)}


def fleet50_wander(repeat: int) -> Result:
    """fleet50 preset with the wander driver: physics plus robot software over the bus."""
    scenario = cosim.load_scenario(
        "fleet50", {"scenario.duration_s": 60.0, "robots.driver": "wander"}
    )
    return {"driver": "wander", **_rtf_runs(scenario, repeat)}


def fleet1000_wander(repeat: int) -> Result:
    """1,000 robots in a 100 m x 100 m hall with racks, wander driver, same sensors."""
    scenario = cosim.load_scenario(
        "fleet50",
        {
            "scenario.duration_s": 10.0,
            "world.size_m": [100.0, 100.0],
            "world.shelf_count": 600,
            "robots.count": 1000,
            "robots.driver": "wander",
        },
    )
    return {"hall_m": [100.0, 100.0], "shelves": 600, **_rtf_runs(scenario, max(1, repeat - 2))}


def network_end_to_end(repeat: int) -> Result:
    """Messages through bus + network model + kernel delivery events, per second of wall time.

    10 robots each publish a Twist to the base every millisecond for 2 s of sim time under
    the wifi_nominal profile: every message is decided by the model, scheduled as a kernel
    event and handed to a subscriber.
    """
    scenario = cosim.load_scenario(
        "warehouse-random",
        {
            "robots.count": 10,
            "lidar.beams": 0,
            "network.profile": "wifi_nominal",
            "network.bandwidth_mbps": 0.0,
            "scenario.duration_s": 2.0,
            "record.messages": False,
        },
    )
    registry = AdapterRegistry.from_entry_points().with_adapter(Chatter)
    rates, delivered = [], 0
    for seed in range(1, repeat + 1):
        Chatter.received = 0
        start = time.perf_counter()
        execute(
            scenario.with_seed(seed),
            names=["world", "fleet", "network", "chatter"],
            registry=registry,
        )
        wall = time.perf_counter() - start
        delivered = Chatter.received
        rates.append(delivered / wall)
    return {
        "robots": 10,
        "messages_per_sim_s": 10_000,
        "profile": "wifi_nominal",
        "deliveries_last": delivered,
        "deliveries_per_s_median": round(statistics.median(rates)),
        "note": "includes run set-up (world, adapters) in the wall time",
        "repeat": repeat,
    }


class Chatter:
    """Bench-only traffic: every robot sends a Twist to the base every millisecond."""

    name: ClassVar[str] = "chatter"
    requires: ClassVar[tuple[str, ...]] = ("network",)
    received: ClassVar[int] = 0

    def __init__(self, run: RunContext) -> None:
        self.hosts = [HostId(n) for n in run.service(FleetState).names]

    def start(self, run: RunContext) -> None:
        def count(message: Message, envelope: Envelope) -> None:
            Chatter.received += 1

        run.bus.subscribe("/fleet/cmd", BASE_HOST, count)
        twist = Twist(0.5, 0.1)

        def send(now: int) -> None:
            for host in self.hosts:
                run.bus.publish("/fleet/cmd", twist, host)

        run.kernel.every(1_000_000, send, stage=Stage.CONTROL)

    def finish(self, run: RunContext) -> dict[str, Any]:
        return {}


BREAKDOWN = {
    "lidar (cast, noise, scan messages)": ("adapters/sensing/lidar.py", "_scan"),
    "navigation control tick (all below)": ("adapters/navigation/stack.py", "_control"),
    "  global planning (A*, costmap, memory)": ("adapters/navigation/planning.py", "route"),
    "  local control (DWA kernel)": ("models/navigation/dwa.py", "dwa_batch"),
    "physics tick (kinematics, collisions, odometry)": ("adapters/fleet/motion.py", "_tick"),
    "  collision checks": ("adapters/fleet/collisions.py", "guard"),
    "bus publish (one message)": ("cosim/core/bus.py", "publish"),
    "bus publish_many (a fleet's scans, odometry, commands)": ("cosim/core/bus.py", "publish_many"),
}


def _shares(scenario: cosim.Scenario, breakdown: dict[str, tuple[str, str]]) -> Result:
    """cProfile shares of wall time of one run, by (file suffix, function) of the breakdown."""
    import cProfile
    import pstats

    profiler = cProfile.Profile()
    profiler.enable()
    result = cosim.run(scenario, threads=1)  # cProfile sees one thread: all the work on it
    profiler.disable()
    stats = pstats.Stats(profiler).stats  # type: ignore[attr-defined]
    total = sum(v[2] for v in stats.values())
    shares = {}
    for label, (path, func) in breakdown.items():
        cum = sum(
            v[3] for (file, _line, name), v in stats.items() if file.endswith(path) and name == func
        )
        shares[label] = round(cum / total, 3) if total else None
    return {"summary": result.summary, "shares": shares}


def fleet50_navigation(repeat: int) -> Result:
    """fleet50, every robot planning (A* + DWA) to random goals: real-time factor, where time
    goes; and the preset as it comes (its fleet manager, traffic 'pibt') in the same run."""
    scenario = cosim.load_scenario("fleet50", {"scenario.duration_s": 60.0, **EVERY_ROBOT_PLANS})
    runs = _rtf_runs(scenario, repeat)
    preset = _rtf_runs(cosim.load_scenario("fleet50", {"scenario.duration_s": 60.0}), repeat)
    profiled = _shares(scenario.with_duration(30.0), BREAKDOWN)
    return {
        **runs,
        "overrides": EVERY_ROBOT_PLANS,
        "preset_real_time_factor_median": preset["real_time_factor_median"],
        "preset_collisions_last": preset["collisions_last"],
        "arrivals_last": profiled["summary"]["arrivals"],
        "breakdown_share_of_wall_time": profiled["shares"],
        "breakdown_note": "cProfile shares of a 30 s run (profiling slows the run ~30 %)",
    }


FULL_STACK_BREAKDOWN = {
    "task assignment rounds (protocol, broadcasts)": ("adapters/assignment/dta.py", "_round_of"),
    "  distributed simplex merge and solve": ("models/assignment/dsimplex.py", "merge_and_solve"),
    "mapping: scan matching and map updates (every 0.5 m)": (
        "adapters/mapping/mapper.py",
        "_process",
    ),
    "mapping: maps out (every 5 s)": ("adapters/mapping/mapper.py", "_publish_maps"),
    "navigation: new maps' costmaps": ("adapters/navigation/layers.py", "build"),
    **BREAKDOWN,
}


LAYERS = {
    "sensors, physics and bus (wander driver)": {"robots.driver": "wander"},
    "+ navigation (random goals, every robot planning)": EVERY_ROBOT_PLANS,
    "+ task assignment (distributed simplex; robots drive to tasks), no mapping": {
        **FULL_STACK,
        "mapping.enabled": False,
        "odometry.drift": 0.0,
    },
    "+ mapping on drifting odometry (the full stack)": FULL_STACK,
}
"""The full stack built up layer by layer, each row adding to the one before: what each layer
costs per simulated second, so that the 20x target's budget (50 ms) can be read against it."""


def _layer_costs(repeat: int) -> dict[str, dict[str, float]]:
    """Wall time per simulated second (ms) of each of :data:`LAYERS` at 1 and 2 threads.

    Medians of ``repeat`` runs each; the two thread counts take turns layer by layer.
    """
    costs: dict[str, dict[str, float]] = {}
    for name, overrides in LAYERS.items():
        scenario = cosim.load_scenario("fleet50", {"scenario.duration_s": 30.0, **overrides})
        costs[name] = {}
        for threads in (1, 2):
            runs = _rtf_runs(scenario, repeat, threads=threads)
            costs[name][f"threads_{threads}"] = round(1000.0 / runs["real_time_factor_median"], 1)
    return costs


def fleet50_full_stack(repeat: int) -> Result:
    """fleet50 with navigation, task assignment and mapping: real-time factor, where time goes."""
    scenario = cosim.load_scenario("fleet50", {"scenario.duration_s": 30.0, **FULL_STACK})
    runs = _rtf_runs(scenario, repeat)
    profiled = _shares(scenario.with_duration(15.0), FULL_STACK_BREAKDOWN)
    summary = profiled["summary"]
    return {
        **runs,
        "overrides": FULL_STACK,
        "target": "on 2 threads, at least IR-SIM-X's physics measured in the same run "
        "(`make bench-peers`: peers.ratio_to_irsim_x_median.whole_stack >= 1.0)",
        "layers_wall_ms_per_sim_s": _layer_costs(max(1, repeat - 1)),
        "layers_note": "each layer adds to the one above it; 30 s runs, same session, "
        "at 1 and 2 threads (the whole stack's real-time factor above: 1 thread)",
        "arrivals_last": summary.get("arrivals"),
        "path_length_ratio_last": summary.get("path_length_ratio"),
        "breakdown_share_of_wall_time": profiled["shares"],
        "breakdown_note": "cProfile shares of a 15 s run (profiling slows the run ~30 %)",
    }


STUDY_TEXT = """
[study]
name = "bench_study"
scenario = "warehouse-random"
seeds = 4
duration_s = 180

[grid]
"network.latency_ms" = [0, 50]
"assignment.protocol" = ["distributed_simplex", "cbba"]

[overrides]
"record.messages" = false
"""


def study_throughput(repeat: int) -> Result:
    """Runs per minute of a 16-run study (180 s each) on 1 and 2 local workers, and the speed-up."""
    import shutil
    import tempfile
    from pathlib import Path

    from cosim.studies import load_study, run_study

    rates: dict[int, list[float]] = {1: [], 2: []}
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "study.toml"
        path.write_text(STUDY_TEXT)
        spec = load_study(path)
        for _ in range(max(1, repeat - 1)):
            for workers in (1, 2):
                out = Path(tmp) / f"out{workers}"
                shutil.rmtree(out, ignore_errors=True)
                start = time.perf_counter()
                run_study(spec, out, workers=workers, report=False)
                rates[workers].append(len(spec.runs()) / (time.perf_counter() - start) * 60)
    one, two = statistics.median(rates[1]), statistics.median(rates[2])
    return {
        "runs": 16,
        "sim_time_s_per_run": 180,
        "runs_per_min_1_worker": round(one, 2),
        "runs_per_min_2_workers": round(two, 2),
        "speedup_2_workers": round(two / one, 3),
        "target_speedup": 1.8,
        "note": "2 workers are forkserver processes (start-up included); 1 worker runs in-process",
    }


def lidar(repeat: int) -> Result:
    """Grid ray caster throughput, one core (see bench/lidar_bench.py)."""
    return lidar_rays_per_second(max(repeat, 20))


SUITES: dict[str, Callable[[int], Result]] = {
    "warehouse_random_60s": warehouse_random_60s,
    "kernel_periodic_1000": kernel_periodic_1000,
    "lidar": lidar,
    "network": network_deliveries_per_second,
    "network_end_to_end": network_end_to_end,
    "ns3_radio": ns3_radio,
    "envs": envs_steps,
    "planner": planner_ms,
    "fleet50_navigation": fleet50_navigation,
    "fleet50_full_stack": fleet50_full_stack,
    "dwa": dwa_us_per_robot,
    "controllers": controllers_fleet50,
    "planners": planners_fleet50,
    "assignment": assignment_solve_stats,
    "study": study_throughput,
    "study_throughput_200": study_throughput_200,
    "fleet50_physics": fleet50_physics,
    "fleet50_wander": fleet50_wander,
    "fleet1000_wander": fleet1000_wander,
    "fleet_scaling": fleet_scaling,
    "landmarks": landmark_savings,
    "bag_cost": bag_cost,
    "bag_memory_1h": bag_memory_1h,
    "cdr_encoding": encoding,
    "mapping_per_scan": per_scan_costs,
    "fleet50_mapping": fleet50_mapping,
    "recordings_mapping": recordings_mapping,
    "humans_coupling": humans_coupling,
    "cli_startup": cli_startup,
    "peers": irsim_peer,
    "threads": threads_speedup,
    "whole_stack_breakdown": whole_stack_breakdown,
}

ON_REQUEST = {"peers"}
"""Suites ``make bench`` leaves out: ``peers`` needs the peer's own environment, which
``make bench-peers`` installs before running it."""
