"""Navigation records: ``tables/navigation`` rows and the navigation summary (its keys).

``plan_ms`` is the wall-clock time of a plan, a column that is not a function of the
scenario and seed; it is registered as volatile, and runs are compared without it
(:meth:`cosim.runner.result.RunResult.deterministic_tables`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from adapters.navigation.recovery import STUCK_KINDS
from cosim.core.recorder import Recorder
from cosim.core.summary import SummaryKey
from cosim.core.table import TableSpec
from cosim.core.timebase import NS_PER_S

NAVIGATION = TableSpec(
    "navigation",
    "One row per goal, plan, replan, recovery, stuck report, arrival and drop of every robot.",
    {
        "t_s": "when (s)",
        "robot": "the robot",
        "event": "goal, plan, replan, recovery, stuck, arrived, unreachable, cancelled, off_map "
        "(the pose left the costmap: the robot stops) or on_map (it came back)",
        "goal_x_m": "the goal's x in map (m)",
        "goal_y_m": "the goal's y in map (m)",
        "path_length_m": "plans: the length of the path found (m); arrivals: the distance "
        "driven to the goal (m); empty otherwise",
        "shortest_m": "arrivals: the shortest way on the true map from where the robot took "
        "the goal (m); empty otherwise",
        "lost_s": "arrivals: the time taken beyond driving that shortest way at "
        "robots.max_speed_mps (s); empty otherwise",
        "plan_ms": "plans: wall-clock time the planner took (ms; volatile)",
        "detail": "how a plan was found (repaired, cleared), the recovery step, why stuck",
    },
    categorical=("robot", "event", "detail"),
    volatile=("plan_ms",),
)
NAV_COLUMNS = tuple(NAVIGATION.columns)

_STUCK_WHY = {
    "halted": "it had barely moved since its last progress",
    "detoured": "it drove, but its way left grew longer than its best",
    "slowed": "it drove on its way, slowed by traffic",
}
NAV_SUMMARY: Mapping[str, SummaryKey] = {
    "goals": SummaryKey("count", "goals the robots took on (goal rows of tables/navigation)"),
    "arrivals": SummaryKey("count", "goals reached"),
    "mean_time_to_goal_s": SummaryKey(
        "s", "time from taking a goal to reaching it, mean over arrivals (null: none)"
    ),
    "path_length_ratio": SummaryKey(
        "ratio",
        "distance driven to a goal over its shortest path, mean over arrivals more than "
        "0.5 m away (null: none)",
    ),
    "deadlocks": SummaryKey("count", "stuck reports: no progress for navigation.stuck_timeout_s"),
    "stuck_s": SummaryKey(
        "s",
        "time robots spent in stalls that were reported stuck, each from its last progress "
        "to its next progress, arrival, drop or the end of the run, summed over robots",
    ),
    "time_lost_s": SummaryKey(
        "s",
        "over arrivals: time taken beyond driving the shortest way on the true map at "
        "robots.max_speed_mps, summed (lost_s of tables/navigation)",
    ),
    "time_lost_max_s": SummaryKey("s", "the largest lost_s of one arrival (null: none)"),
    "arrivals_over_twice": SummaryKey(
        "count",
        "arrivals more than 0.5 m away that took more than twice the time of their shortest "
        "way at robots.max_speed_mps",
    ),
    **{
        f"stuck_{kind}": SummaryKey("count", f"stuck reports where {_STUCK_WHY[kind]}")
        for kind in STUCK_KINDS
    },
    "goals_unreachable": SummaryKey("count", "goals dropped as unreachable"),
    "replans": SummaryKey("count", "global plans made again for a goal"),
    "recoveries": SummaryKey("count", "recovery steps of robots that could not go on"),
}
"""The summary keys :meth:`NavRecords.summary` writes."""


class NavRecords:
    """Rows of ``tables/navigation`` and the statistics behind the summary.

    Args:
        recorder: the run's recorder.
        names: robot names, by index.
        max_speed_mps: the robots' top speed (m/s): the yardstick of time lost.
    """

    def __init__(self, recorder: Recorder, names: list[str], *, max_speed_mps: float) -> None:
        self.table = recorder.table(NAVIGATION)
        self.recorder = recorder
        self.names = names
        n = len(names)
        self.goal_t0_ns = np.zeros(n, dtype=np.int64)
        self.goal_d0_m = np.zeros(n)
        self.shortest_m = np.full(n, math.nan)
        self.times_s: list[float] = []
        self.ratios: list[float] = []
        self.counts: dict[str, int] = {}
        self.stuck_kinds: dict[str, int] = {}
        self.max_speed_mps = max_speed_mps
        self.lost_s: list[float] = []
        self.over_twice = 0
        self.stuck_s = 0.0

    def row(
        self,
        t_ns: int,
        i: int,
        event: str,
        goal_x_m: float,
        goal_y_m: float,
        *,
        path_length_m: float = math.nan,
        plan_ms: float = math.nan,
        shortest_m: float = math.nan,
        lost_s: float = math.nan,
        detail: str = "",
    ) -> None:
        """Record one navigation event of robot ``i``."""
        self.table.append(
            t_s=t_ns / NS_PER_S,
            robot=self.names[i],
            event=event,
            goal_x_m=float(goal_x_m),
            goal_y_m=float(goal_y_m),
            path_length_m=float(path_length_m),
            plan_ms=float(plan_ms),
            shortest_m=float(shortest_m),
            lost_s=float(lost_s),
            detail=detail,
        )
        self.counts[event] = self.counts.get(event, 0) + 1
        if event in ("stuck", "unreachable", "arrived", "off_map", "on_map"):
            text = f"goal ({goal_x_m:.2f}, {goal_y_m:.2f})" + (f": {detail}" if detail else "")
            self.recorder.event(t_ns, self.names[i], event, text)

    def stuck(self, kind: str) -> None:
        """Count a ``stuck`` report by its kind, one of :data:`STUCK_KINDS`."""
        self.stuck_kinds[kind] = self.stuck_kinds.get(kind, 0) + 1

    def start_goal(self, i: int, t_ns: int, driven_m: float, shortest_m: float) -> None:
        """Remember when and where a goal started (for time to goal and path ratio)."""
        self.goal_t0_ns[i] = t_ns
        self.goal_d0_m[i] = driven_m
        self.shortest_m[i] = shortest_m

    def stalled(self, seconds: float) -> None:
        """Add one stall reported stuck, ``seconds`` long, to the time stuck."""
        self.stuck_s += seconds

    def arrived(self, t_ns: int, i: int, goal_x_m: float, goal_y_m: float, driven_m: float) -> None:
        """Record an arrival, its time, the time it lost and its path-length ratio."""
        taken_s = (t_ns - int(self.goal_t0_ns[i])) / NS_PER_S
        shortest = float(self.shortest_m[i])
        needed_s = shortest / self.max_speed_mps
        lost = max(0.0, taken_s - needed_s) if math.isfinite(shortest) else math.nan
        self.row(
            t_ns,
            i,
            "arrived",
            goal_x_m,
            goal_y_m,
            path_length_m=driven_m - self.goal_d0_m[i],
            shortest_m=shortest,
            lost_s=lost,
        )
        self.times_s.append(taken_s)
        if math.isfinite(lost):
            self.lost_s.append(lost)
        if shortest > 0.5:  # goals next to the robot say nothing about path quality
            self.ratios.append((driven_m - self.goal_d0_m[i]) / shortest)
            self.over_twice += int(taken_s > 2 * needed_s)

    def summary(self, sim_time_s: float) -> dict[str, Any]:
        """Navigation metrics for ``summary.json``."""
        counts = self.counts
        return {
            "goals": counts.get("goal", 0),
            "arrivals": counts.get("arrived", 0),
            "mean_time_to_goal_s": round(float(np.mean(self.times_s)), 6) if self.times_s else None,
            "path_length_ratio": round(float(np.mean(self.ratios)), 6) if self.ratios else None,
            "deadlocks": counts.get("stuck", 0),
            "stuck_s": round(self.stuck_s, 6),
            "time_lost_s": round(float(np.sum(self.lost_s)), 6),
            "time_lost_max_s": round(float(np.max(self.lost_s)), 6) if self.lost_s else None,
            "arrivals_over_twice": self.over_twice,
            **{f"stuck_{kind}": self.stuck_kinds.get(kind, 0) for kind in STUCK_KINDS},
            "goals_unreachable": counts.get("unreachable", 0),
            "replans": counts.get("replan", 0),
            "recoveries": counts.get("recovery", 0),
        }
