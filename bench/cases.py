"""The fleet50 cases several benchmarks share, by their scenario overrides."""

from __future__ import annotations

from typing import Any

EVERY_ROBOT_PLANS: dict[str, Any] = {"navigation.traffic": "none"}
"""fleet50's robots each planning with A* and following with DWA (the paper's Nav2 role), not
moved by the preset's fleet manager: what the navigation figures and breakdowns measure."""

FULL_STACK: dict[str, Any] = {
    **EVERY_ROBOT_PLANS,
    "robots.driver": "tasks",
    "tasks.initial": 50,
    "assignment.protocol": "distributed_simplex",
    "mapping.enabled": True,
    "odometry.drift": 0.02,
}
"""fleet50 with the whole stack: 50 tasks assigned by distributed simplex (a new one for each
done), every robot mapping as it drives on drifting odometry, navigation on its own map
(every robot planning: the preset's fleet manager refuses robots localizing on their own
maps), and the robots layer that mapping turns on (``navigation.robots_layer = "auto"``:
each robot broadcasts its pose, each mapper leaves the others out of its map) and the
refine on walls (``mapping.refine = "walls"``). Since those defaults (after 384ef66) the
case maps better (fleet map IoU 0.964 against 0.615 at 30 s, seed 5) and runs about a third
slower (4.5-4.7x real time against 6.4-6.9x on 2 threads, measured 2026-11-28) than the
figures measured before them."""
