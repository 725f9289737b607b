"""Fleets at scale (issue 16): wall time, real-time factor and peak memory from 50 to 1,000 robots.

The ``fleet50`` preset (navigation to random goals, 360-beam 10 Hz lidar) with the hall grown
with the fleet as in ``studies/scale.toml``: about 18 m^2 of floor per robot up to 200 robots,
then denser, up to 1,000 robots in 100 m x 100 m with 600 shelves. Each fleet size runs in a
fresh process, so its peak resident memory (``VmHWM``) is its own.

Targets: 1,000 navigating robots at least at real time (``rtf_1000`` >= 1) within 2 GB peak
resident memory.

The child process is this file run with ``--child``; it prints one JSON line.
"""

from __future__ import annotations

import argparse
import itertools
import json
import resource
import subprocess
import sys
import time
from pathlib import Path
from typing import Any, ClassVar, NamedTuple

import cosim
from cosim.core.adapter import RunContext
from cosim.core.kernel import Stage
from cosim.core.registry import AdapterRegistry
from cosim.runner.assembly import adapter_names
from cosim.runner.execute import execute

Result = dict[str, Any]
RTF_TARGET = 1.0
PEAK_RSS_TARGET_MB = 2048.0
SEED = 1
WARMUP_S = 1.0
"""Simulated seconds left out of the steady-state figures: every robot plans at t = 0."""


class Hall(NamedTuple):
    """One fleet size and the hall it runs in.

    Attributes:
        robots: fleet size.
        side_m: side of the square hall (m).
        shelves: shelf count (racks of 3).
        duration_s: simulated time of the run (s).
        placement: ``robots.placement``: ``dock`` (the preset's: every robot leaves a
            packed dock at t = 0) or ``random`` (robots spread over the floor, as in a
            hall at work).
        traffic: ``navigation.traffic``: ``none`` (the preset's: each robot plans alone)
            or a fleet traffic policy (``pibt``: robots move place by place).
    """

    robots: int
    side_m: float
    shelves: int
    duration_s: float
    placement: str = "dock"
    traffic: str = "none"

    @property
    def key(self) -> str:
        """Its key: ``robots_<N>``, with ``_<placement>`` unless the dock, ``_<traffic>``."""
        placement = "" if self.placement == "dock" else f"_{self.placement}"
        traffic = "" if self.traffic == "none" else f"_{self.traffic}"
        return f"robots_{self.robots}{placement}{traffic}"


HALLS = (
    Hall(50, 30.0, 72, 20.0),
    Hall(100, 42.0, 150, 20.0),
    Hall(200, 60.0, 300, 20.0),
    Hall(500, 75.0, 360, 10.0),
    Hall(1000, 100.0, 600, 10.0),
    Hall(1000, 100.0, 600, 10.0, "random"),
    Hall(1000, 100.0, 600, 10.0, "dock", "pibt"),
    Hall(1000, 100.0, 600, 10.0, "random", "pibt"),
)
"""18 m^2 of floor per robot up to 200 robots (the 30 m hall holds 50), 11.3 m^2 at 500 and
10 m^2 at 1,000; 0.08 shelves per m^2 up to 200 robots, 0.064 at 500, 0.06 at 1,000. The
1,000 robots run from the preset's dock (where they gridlock at the start) and spread over
the floor, each with ``navigation.traffic`` ``none`` (each robot plans alone) and ``pibt``
(the fleet manager moves robots place by place: no A*, no DWA once on the places)."""


class WallMarks:
    """Bench-only adapter: the wall clock when the run is built and at every simulated second.

    Constructed after every other adapter (it is named last and requires none), so its
    construction marks the end of the set-up; its marks fire in the RECORD stage, after the
    robots' work at the same instant. It changes no state and draws no random number.
    """

    name: ClassVar[str] = "wall_marks"
    requires: ClassVar[tuple[str, ...]] = ()
    built_s: ClassVar[float] = 0.0
    marks_s: ClassVar[list[float]] = []

    def __init__(self, run: RunContext) -> None:
        WallMarks.built_s = time.perf_counter()
        WallMarks.marks_s = []

    def start(self, run: RunContext) -> None:
        def mark(now: int) -> None:
            WallMarks.marks_s.append(time.perf_counter())

        run.kernel.every(1_000_000_000, mark, stage=Stage.RECORD)

    def finish(self, run: RunContext) -> dict[str, Any]:
        return {}


def _peak_rss_mb() -> float:
    """This process's peak resident memory (MiB).

    ``VmHWM`` where Linux has it: ``ru_maxrss`` of a child started by a large parent also
    counts the parent's resident memory at the fork (Linux keeps it across exec).
    """
    status = Path("/proc/self/status")
    if status.exists():
        for line in status.read_text().splitlines():
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1024  # kB
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024  # KiB on Linux


def _child(hall: Hall, seed: int) -> Result:
    """One run in this process: the figures of :func:`fleet_scaling` for one fleet size."""
    rss_imports = _peak_rss_mb()
    start = time.perf_counter()
    scenario = cosim.load_scenario(
        "fleet50",
        {
            "scenario.duration_s": hall.duration_s,
            "scenario.seed": seed,
            "robots.count": hall.robots,
            "robots.placement": hall.placement,
            "navigation.traffic": hall.traffic,
            "world.size_m": [hall.side_m, hall.side_m],
            "world.shelf_count": hall.shelves,
            "record.bag": "none",
            "record.messages": False,
        },
    )
    registry = AdapterRegistry.from_entry_points().with_adapter(WallMarks)
    names = [*adapter_names(scenario), WallMarks.name]
    summary = execute(scenario, names=names, registry=registry).summary
    marks = WallMarks.marks_s
    robot_s = hall.robots * hall.duration_s
    out: Result = {
        "robots": hall.robots,
        "placement": hall.placement,
        "traffic": hall.traffic,
        "hall_m": [hall.side_m, hall.side_m],
        "shelves": summary["shelves"],
        "sim_time_s": hall.duration_s,
        "wall_time_s": summary["wall_time_s"],
        "real_time_factor": summary["real_time_factor"],
        "wall_us_per_robot_s": round(summary["wall_time_s"] / robot_s * 1e6, 1),
        "peak_rss_mb": round(_peak_rss_mb(), 1),
        "rss_after_imports_mb": round(rss_imports, 1),
        "setup_s": round(WallMarks.built_s - start, 3),
        "first_instant_s": round(marks[0] - WallMarks.built_s, 3),
        "wall_s_per_sim_s": [round(b - a, 3) for a, b in itertools.pairwise(marks)],
    }
    warm = int(WARMUP_S)
    if len(marks) > warm + 1:
        steady_sim_s = len(marks) - 1 - warm
        steady_wall_s = marks[-1] - marks[warm]
        out["real_time_factor_after_warmup"] = round(steady_sim_s / steady_wall_s, 3)
        out["wall_us_per_robot_s_after_warmup"] = round(
            steady_wall_s / (hall.robots * steady_sim_s) * 1e6, 1
        )
    for key in ("arrivals", "collisions", "goals_missed", "replans", "events"):
        out[key] = summary.get(key)
    return out


def _code_version() -> str:
    done = subprocess.run(
        ["git", "describe", "--always", "--dirty"],
        capture_output=True,
        text=True,
        cwd=Path(__file__).resolve().parent,
        check=False,
    )
    return done.stdout.strip() or "unknown"


def fleet_scaling(
    repeat: int, *, halls: tuple[Hall, ...] = HALLS, seed: int = SEED, timeout_s: float = 1800.0
) -> Result:
    """Navigating fleets of 50 to 1,000 robots, each fleet size in a fresh process.

    Args:
        repeat: ignored: one run per fleet size (the 1,000-robot run alone takes minutes);
            the per-second wall times show the spread within a run.
        halls: the fleet sizes, halls and durations to run, smallest first.
        seed: the scenario seed of every run.
        timeout_s: wall-clock limit of one fleet size's process; on expiry the larger
            fleets are not run.

    Returns:
        Per fleet size (``robots_<N>``) the run's figures, and the headline ``rtf_1000`` and
        ``peak_rss_mb_1000`` with their targets and ``met`` flags (None when not run).
    """
    out: Result = {
        "preset": "fleet50",
        "driver": "navigation",
        "seed": seed,
        "code": _code_version(),
        "note": (
            "one fresh process per fleet size. wall_time_s / real_time_factor are cosim's: "
            "adapter start and the kernel loop, so the first instant (every robot plans at "
            "t = 0, first_instant_s) is included; world generation, maps and adapter "
            "construction (setup_s) are not. *_after_warmup leave out the first simulated "
            "second. peak_rss_mb is the process's own peak (VmHWM), set-up and imports included "
            "(rss_after_imports_mb). wall_us_per_robot_s = wall_time_s / (robots x sim_time_s)."
        ),
    }
    for hall in halls:
        key = hall.key
        child = json.dumps(hall._asdict())
        start = time.perf_counter()
        try:
            done = subprocess.run(
                [sys.executable, __file__, "--child", child, "--seed", str(seed)],
                capture_output=True,
                text=True,
                timeout=timeout_s,
                check=False,
            )
        except subprocess.TimeoutExpired:
            out[key] = {"timed_out_after_s": timeout_s, "sim_time_s": hall.duration_s}
            print(f"  {key}: no result within {timeout_s:.0f} s; larger fleets skipped", flush=True)
            break
        if done.returncode != 0:
            raise RuntimeError(f"{key}: the child process failed:\n{done.stderr[-2000:]}")
        out[key] = json.loads(done.stdout.strip().splitlines()[-1])
        out[key]["process_wall_s"] = round(time.perf_counter() - start, 2)
        print(
            f"  {key}: {out[key]['real_time_factor']}x real time, "
            f"{out[key]['peak_rss_mb']} MB peak, {out[key]['process_wall_s']} s",
            flush=True,
        )
    biggest = out.get("robots_1000", {})
    rtf, rss = biggest.get("real_time_factor"), biggest.get("peak_rss_mb")
    out.update(
        rtf_1000=rtf,
        rtf_1000_target=RTF_TARGET,
        rtf_1000_met=None if rtf is None else rtf >= RTF_TARGET,
        rtf_1000_after_warmup=biggest.get("real_time_factor_after_warmup"),
        rtf_1000_random=out.get("robots_1000_random", {}).get("real_time_factor"),
        rtf_1000_random_after_warmup=out.get("robots_1000_random", {}).get(
            "real_time_factor_after_warmup"
        ),
        rtf_1000_pibt=out.get("robots_1000_pibt", {}).get("real_time_factor"),
        rtf_1000_random_pibt=out.get("robots_1000_random_pibt", {}).get("real_time_factor"),
        peak_rss_mb_1000=rss,
        peak_rss_mb_1000_target=PEAK_RSS_TARGET_MB,
        peak_rss_mb_1000_met=None if rss is None else rss <= PEAK_RSS_TARGET_MB,
    )
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--child", required=True, help="a Hall as JSON (internal)")
    parser.add_argument("--seed", type=int, default=SEED)
    args = parser.parse_args(argv)
    print(json.dumps(_child(Hall(**json.loads(args.child)), args.seed)), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
