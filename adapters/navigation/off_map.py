"""Robots whose pose lies off the costmap: they stop, and leaving and coming back is recorded.

A measured pose (motion capture, a physical robot's report) can be anything, and a plan
from outside the costmap finds nothing: a robot whose pose is off the costmap is stopped
by the control tick until its pose is back. Each change is a row of the navigation table
(``off_map``, ``on_map``); a robot back on the costmap with a goal plans again at once,
unless a fleet manager moves the robots.
"""

from __future__ import annotations

import numpy as np

from adapters.navigation.goal_tracking import GoalTracker
from adapters.navigation.planning import GlobalPlanning
from adapters.navigation.tables import NavRecords
from cosim.core.adapter import RunContext
from models.arrays import BoolArray, FloatArray
from models.navigation.costmap import StaticCostmap


class OffMapWatch:
    """Which robots are off the costmap, with the changes recorded.

    Args:
        static: the static costmap (its extent is the costmap's).
        pose: (n, 3) every robot's pose estimate in ``map`` (m, rad), read at each check.
        goals: every robot's goal (a robot back on the costmap with one plans again).
        planning: the global planning (the plan made again).
        records: the navigation table.
        replan: plan again for a robot back on the costmap (False when a fleet manager
            moves the robots).
    """

    def __init__(
        self,
        static: StaticCostmap,
        pose: FloatArray,
        goals: GoalTracker,
        planning: GlobalPlanning,
        records: NavRecords,
        *,
        replan: bool,
    ) -> None:
        self.static = static
        self.pose = pose
        self.goals = goals
        self.planning = planning
        self.records = records
        self.replan = replan
        self.off: BoolArray = np.zeros(len(pose), dtype=bool)
        """Robots whose pose is off the costmap (stopped until it is back)."""

    def check(self, run: RunContext, now_ns: int) -> BoolArray:
        """The robots whose pose lies off the costmap; leaving and coming back recorded.

        A robot back on the costmap with a goal plans again at once (a plan asked for
        while it was off found nothing).
        """
        static = self.static
        x, y = self.pose[:, 0], self.pose[:, 1]
        with np.errstate(invalid="ignore"):
            ix = np.floor((x - static.origin_xy_m[0]) / static.resolution_m)
            iy = np.floor((y - static.origin_xy_m[1]) / static.resolution_m)
            on = (ix >= 0) & (ix < static.width) & (iy >= 0) & (iy < static.height)
        off = ~on
        for i in np.flatnonzero(off != self.off).tolist():
            goal = self.goals.goal[i]
            where = f"pose ({x[i]:.2f}, {y[i]:.2f}) m"
            if off[i]:
                grid = f"{static.width}x{static.height}"
                detail = f"{where} outside the {grid} costmap: stopped"
            else:
                detail = f"{where}: back on the costmap"
            event = "off_map" if off[i] else "on_map"
            self.records.row(now_ns, i, event, goal[0], goal[1], detail=detail)
            if not off[i] and self.goals.active[i] and self.replan:
                self.planning.plan(run, i, now_ns, replan=True)
        self.off = off
        return off
