"""Every registered local controller deciding for 50 robots, in real runs of the same hall.

fleet50 (30 m x 30 m, 72 shelves, 50 robots to random goals) with every robot planning for
itself (``navigation.traffic = "none"``, so the controller drives every robot at every tick)
and the robots layer on (the discs and neighbour velocities a reciprocal controller uses),
once per controller, in one process: the controller's wall time per robot and decision
(``controller_us_per_robot`` of the summary, the ``commands`` call alone), the run's real
time factor, goals reached and contacts. All controllers are measured in the same command,
so their ratios hold on a noisy machine; the target is each within ``dwa``'s budget.
"""

from __future__ import annotations

import statistics
from typing import Any

import cosim
from adapters.navigation.contract import controller_registry

Result = dict[str, Any]

DURATION_S = 20.0
OVERRIDES: dict[str, Any] = {
    "navigation.traffic": "none",
    "navigation.robots_layer": True,
    "record.messages": False,
    "record.bag": "none",
}


def controllers_fleet50(repeat: int) -> Result:
    """Per controller: median us per robot and decision, real time factor, arrivals."""
    out: Result = {"robots": 50, "duration_s": DURATION_S, "overrides": OVERRIDES}
    per: dict[str, Result] = {}
    for name in sorted(controller_registry().names()):
        us, rtf = [], []
        summary: dict[str, Any] = {}
        for _ in range(max(repeat, 1)):
            scenario = cosim.load_scenario(
                "fleet50",
                {"scenario.duration_s": DURATION_S, "navigation.controller": name, **OVERRIDES},
            )
            summary = dict(cosim.run(scenario).summary)
            us.append(float(summary["controller_us_per_robot"]))
            rtf.append(float(summary["real_time_factor"]))
        per[name] = {
            "us_per_robot_median": round(statistics.median(us), 2),
            "us_per_robot_all": [round(x, 2) for x in us],
            "real_time_factor_median": round(statistics.median(rtf), 2),
            "arrivals_last": summary["arrivals"],
            "collisions_last": summary["collisions"],
        }
    base = per.get("dwa", {}).get("us_per_robot_median")
    if base:
        for row in per.values():
            row["ratio_to_dwa"] = round(row["us_per_robot_median"] / base, 2)
    out["controllers"] = per
    out["target"] = "each controller's us_per_robot within dwa's (ratio_to_dwa <= 1)"
    return out


def planners_fleet50(repeat: int) -> Result:
    """Per global planner on fleet50 (every robot planning): plan times and path lengths."""
    from adapters.navigation.contract import planner_registry

    out: Result = {"robots": 50, "duration_s": DURATION_S, "overrides": OVERRIDES}
    per: dict[str, Result] = {}
    for name in sorted(planner_registry().names()):
        medians, p95s = [], []
        summary: dict[str, Any] = {}
        plans = 0
        for _ in range(max(repeat, 1)):
            scenario = cosim.load_scenario(
                "fleet50",
                {"scenario.duration_s": DURATION_S, "navigation.planner": name, **OVERRIDES},
            )
            result = cosim.run(scenario)
            summary = dict(result.summary)
            nav = result.tables["navigation"]
            timed = nav[nav.event.isin(["plan", "replan"])].plan_ms.dropna()
            plans = len(timed)
            medians.append(float(timed.median()))
            p95s.append(float(timed.quantile(0.95)))
        per[name] = {
            "plan_ms_median": round(statistics.median(medians), 3),
            "plan_ms_p95": round(statistics.median(p95s), 3),
            "plans_last": plans,
            "arrivals_last": summary["arrivals"],
            "path_length_ratio_last": summary["path_length_ratio"],
            "collisions_last": summary["collisions"],
        }
    out["planners"] = per
    return out
