"""What ``cosim run`` prints when a run is done: its speed, the highlights, where it is."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from cosim.runner.result import RunResult


def _count(value: Any) -> str:
    return f"{int(value):,}"


HIGHLIGHTS: tuple[tuple[str, str, Callable[[Any], str]], ...] = (
    ("arrivals", "goals reached", _count),
    ("deadlocks", "stuck reports", _count),
    ("collisions", "collisions", _count),
    ("min_clearance_m", "m smallest clearance", lambda v: f"{v:.2f}"),
    ("humans_near_misses", "near misses with people", _count),
    ("map_iou", "map IoU", lambda v: f"{v:.2f}"),
    ("messages_dropped", "messages dropped", _count),
    ("latency_ms_p50", "ms median latency", lambda v: f"{v:.3g}"),
)
"""Summary metrics shown after a run, when the run has them: key, label, format."""
TASK_DRIVER_SKIPS = ("arrivals",)
"""With tasks, goals reached are the tasks' legs: the tasks lead instead."""


SINGULAR = {
    "goals reached": "goal reached",
    "stuck reports": "stuck report",
    "collisions": "collision",
    "near misses with people": "near miss with people",
    "messages dropped": "message dropped",
}


def _singular(label: str) -> str:
    return SINGULAR.get(label, label)


def _tasks_phrase(s: dict[str, Any]) -> str | None:
    """``12 tasks completed (6.5 per min, 24.2 s mean latency)``, with the task driver."""
    done = s.get("tasks_completed")
    if done is None:
        return None
    details = []
    if s.get("tasks_per_min") is not None:
        details.append(f"{s['tasks_per_min']:.3g} per min")
    if s.get("mean_task_latency_s") is not None:
        details.append(f"{s['mean_task_latency_s']:.3g} s mean latency")
    noun = "task" if done == 1 else "tasks"
    return f"{done:,} {noun} completed" + (f" ({', '.join(details)})" if details else "")


def print_run(result: RunResult, out: Path, figures: list[Path]) -> None:
    """Print the run's lines: speed and size, highlights, results, bag and figures."""
    from cosim.runner.compiletime import speed_phrase

    s = result.summary
    speed = speed_phrase(s["sim_time_s"], s["wall_time_s"], result.compile_time_s)
    print(
        f"{s['scenario']} seed {s['seed']}: {speed}, "
        f"{s['robots']} robots, {s['events']:,} events, {s['messages_sent']:,} messages"
    )
    tasks = _tasks_phrase(s)
    skip = TASK_DRIVER_SKIPS if tasks is not None else ()
    highlights = [tasks] if tasks is not None else []
    highlights += [
        f"{show(s[key])} {_singular(label) if s[key] == 1 else label}"
        for key, label, show in HIGHLIGHTS
        if s.get(key) is not None and key not in skip
    ]
    if highlights:
        print("  " + ", ".join(highlights))
    tables = ", ".join(sorted(result.tables))
    print(f"results: {out}/  (summary.json, scenario.toml, tables/: {tables})")
    if result.bag is not None:
        recorded = sum(result.recorded.values())
        size_mb = sum(p.stat().st_size for p in result.bag.iterdir() if p.is_file()) / 1e6
        print(
            f"bag: {result.bag}/  ({recorded} messages on {len(result.recorded)} topics, "
            f"{size_mb:.1f} MB; `cosim bag info {result.bag}`, or open it in Foxglove)"
        )
    if figures:
        print(f"figures: {', '.join(str(f) for f in figures)}")
    elif (out / "figures").is_dir() and any((out / "figures").iterdir()):
        print(f"figures/: kept from before, not of this run (`cosim plot {out}` redraws them)")
