"""Every robot's current navigation goal: taken, driven to, reached or given up, and said.

A goal (:class:`~cosim.core.messages.NavGoal` on ``/<robot>/nav/goal``) is checked on the
robot's static map, planned (or handed to the fleet manager's places), and answered on
``/<robot>/nav/status`` (:class:`~cosim.core.messages.NavStatus`): ``accepted`` when a
goal is taken, ``progress`` (the way left) at ``navigation.progress_hz``, ``arrived``
within ``navigation.goal_tolerance_m``, ``stuck`` when the way left has not shrunk by
:data:`PROGRESS_M` for ``navigation.stuck_timeout_s`` (Nav2's progress checker; the robot
keeps trying), and ``unreachable`` or ``cancelled`` when a goal is dropped.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from adapters.navigation.places import FleetPlaces
from adapters.navigation.planning import GlobalPlanning
from adapters.navigation.recovery import Recovery, StallWatch, stuck_kind
from adapters.navigation.tables import NavRecords
from cosim.core.adapter import RunContext
from cosim.core.hosts import HostId
from cosim.core.messages import NavGoal, NavStatus
from cosim.core.timebase import s_to_ns
from models.arrays import BoolArray, FloatArray
from models.fleet.kinematics import FleetState
from models.navigation.costmap import StaticCostmap
from models.navigation.follow import PathBook
from models.navigation.planner import GoalStatus, goal_status

PROGRESS_M = 0.2
"""Remaining path length must shrink by this much to count as progress (m)."""


@dataclass
class Drivers:
    """What drives a robot to its goal, and what must hear of a new or ended goal.

    Attributes:
        static: the building's static costmap (goals inside obstacles are refused).
        planning: the global planner (the first plan, and the yardstick of optimal ways).
        paths: every robot's path being followed.
        places: the fleet manager's places, when it moves the robots.
        recovery: the recovery state (reset for a new goal).
        stalls: the stall watch (reset for a new goal).
        mapping: robots plan on their own maps (their pose is an estimate).
    """

    static: StaticCostmap
    planning: GlobalPlanning
    paths: PathBook
    places: FleetPlaces | None
    recovery: Recovery
    stalls: StallWatch
    mapping: bool


class GoalTracker:
    """The goals of every robot: taken, driven to, reached or given up, and said.

    The arrays are shared with the planner and the fleet manager (mutated in place).

    Args:
        fleet: the fleet's true state (distance driven: the yardstick of progress).
        hosts: every robot's host (statuses are published there).
        status_topics: every robot's ``/<robot>/nav/status``.
        pose: (n, 3) every robot's pose estimate in ``map`` (m, rad), shared.
        goal: (n, 2) every robot's goal in ``map`` (m), shared with the planner.
        records: the navigation table.
        stuck_timeout_s: no progress for this long is ``stuck`` (s).
        goal_tolerance_m: a robot this close to its goal has arrived (m).
    """

    def __init__(
        self,
        fleet: FleetState,
        hosts: list[HostId],
        status_topics: list[str],
        pose: FloatArray,
        goal: FloatArray,
        records: NavRecords,
        *,
        stuck_timeout_s: float,
        goal_tolerance_m: float,
    ) -> None:
        n = len(hosts)
        self.fleet = fleet
        self.hosts = hosts
        self.status_topics = status_topics
        self.pose = pose
        self.records = records
        self.stuck_timeout_s = stuck_timeout_s
        self.goal_tolerance_m = goal_tolerance_m
        self.drivers: Drivers | None = None
        self.active: BoolArray = np.zeros(n, dtype=bool)
        self.goal: FloatArray = goal
        self.goal_id = np.zeros(n, dtype=np.int64)
        self.best_remaining: FloatArray = np.full(n, np.inf)
        self.progress_ns = np.zeros(n, dtype=np.int64)
        self.progress_driven_m: FloatArray = np.zeros(n)  # distance driven at the last progress
        self.stuck: BoolArray = np.zeros(n, dtype=bool)
        self.remaining: FloatArray = np.zeros(n)  # way left at the last control tick (m)
        self.yardstick_from: FloatArray = np.zeros((n, 2))  # true position where goals started

    def status(self, run: RunContext, i: int, state: str, remaining: float) -> None:
        """Publish robot ``i``'s status ``state`` with the way left (m) on its host."""
        x, y, _ = self.pose[i]
        message = NavStatus(
            run.kernel.now_ns, int(self.goal_id[i]), state, float(x), float(y), float(remaining)
        )
        run.bus.publish(self.status_topics[i], message, self.hosts[i])

    def accept(self, run: RunContext, i: int, goal: NavGoal) -> None:
        """Robot ``i`` is given ``goal``: take it (and plan), or drop it as unreachable.

        A goal without a position cancels the current one: the robot stops.
        """
        d = self.drivers
        assert d is not None, "GoalTracker.drivers are set when the navigation is assembled"
        now = run.kernel.now_ns
        self.goal_id[i] = goal.goal_id
        if not (math.isfinite(goal.x_m) and math.isfinite(goal.y_m)):
            self.drop(run, i, "cancelled")
            return
        self.goal[i] = (goal.x_m, goal.y_m)
        self.records.row(now, i, "goal", goal.x_m, goal.y_m)
        where = goal_status(d.static, (goal.x_m, goal.y_m))
        truth = np.array([self.fleet.x[i], self.fleet.y[i]])
        self.yardstick_from[i] = truth
        if where is not GoalStatus.OK:
            self.drop(run, i, "unreachable", where.value)
            return
        # path_length_ratio's yardstick (shortest way on the true map from the true position)
        # counts only on arrival. With the fleet's places, a goal reached from a place of
        # the robot's own component is reachable: its yardstick waits for the arrival, and
        # the way accepted is the way along the places.
        places = d.places
        if places is not None:
            place = places.goal_place(i, self.goal[i])
            if place < 0:
                enclosed = not math.isfinite(self.yardstick(i))
                why = "enclosed" if enclosed else "off the fleet's places"
                self.drop(run, i, "unreachable", why)
                return
            places.set_goal(i, self.goal[i], place, now)
            self._begin(run, i, now, math.nan, places.way_left(i, self.pose[i, :2]))
            return
        # A robot planning on the static layer from exactly its true position finds a route
        # there (its first plan's "cleared" try) if and only if the yardstick exists, so it
        # measures it on arrival; others need it now.
        deferred = not d.mapping and np.array_equal(self.pose[i, :2], truth)
        shortest = math.nan if deferred else self.yardstick(i)
        if not deferred and not math.isfinite(shortest):
            self.drop(run, i, "unreachable", "enclosed")
            return
        started = time.perf_counter()
        found = d.planning.route(i, now, replan=False)
        route = found[0]
        if deferred and route is None:
            shortest = self.yardstick(i)
            if not math.isfinite(shortest):
                self.drop(run, i, "unreachable", "enclosed")
                return
        self._begin(run, i, now, shortest, shortest if route is None or not deferred else route[1])
        d.planning.finish(run, i, now, found, started, replan=False)

    def _begin(self, run: RunContext, i: int, now_ns: int, shortest_m: float, way_m: float) -> None:
        """Robot ``i`` drives to its goal from now; ``way_m`` (m) goes out as accepted."""
        assert self.drivers is not None
        self.drivers.recovery.reset(i)
        self.drivers.stalls.reset(i, self.pose[i], now_ns)
        self.end_stall(i, now_ns)
        self.active[i] = True
        self.best_remaining[i] = math.inf
        self.progress_ns[i] = now_ns
        self.progress_driven_m[i] = self.fleet.distance_m[i]
        self.records.start_goal(i, now_ns, float(self.fleet.distance_m[i]), shortest_m)
        self.status(run, i, "accepted", way_m)

    def yardstick(self, i: int) -> float:
        """Robot ``i``'s shortest way (m) on the true map from where its goal started."""
        assert self.drivers is not None
        return self.drivers.planning.yardstick(self.yardstick_from[i], self.goal[i])

    def drop(self, run: RunContext, i: int, state: str, detail: str = "") -> None:
        """Robot ``i`` stops driving to its goal: ``unreachable`` or ``cancelled``."""
        assert self.drivers is not None
        was_active = bool(self.active[i])
        self.end_stall(i, run.kernel.now_ns)
        self.active[i] = False
        self.drivers.paths.clear(i)
        if self.drivers.places is not None:
            self.drivers.places.end_goal(i)
        if state != "cancelled" or was_active:
            self.records.row(
                run.kernel.now_ns, i, state, self.goal[i, 0], self.goal[i, 1], detail=detail
            )
        self.status(run, i, state, math.nan)

    def arrivals(self, run: RunContext, now_ns: int) -> None:
        """Robots within the goal tolerance have arrived (said one by one).

        One by one: an arrival may hand the robot its next goal at once (the goal sender
        answers the status synchronously).
        """
        assert self.drivers is not None
        gap = np.hypot(*(self.pose[:, :2] - self.goal).T)
        for i in np.flatnonzero(self.active & (gap <= self.goal_tolerance_m)).tolist():
            self.end_stall(i, now_ns)
            self.active[i] = False
            self.drivers.paths.clear(i)
            if math.isnan(self.records.shortest_m[i]):
                self.records.shortest_m[i] = self.yardstick(i)
            self.records.arrived(
                now_ns, i, self.goal[i, 0], self.goal[i, 1], float(self.fleet.distance_m[i])
            )
            if self.drivers.places is not None:
                self.drivers.places.end_goal(i)
            self.status(run, i, "arrived", 0.0)

    def track(self, run: RunContext, now_ns: int, remaining: FloatArray) -> None:
        """Note progress on the way left (m) of every robot; say ``stuck`` once per stall."""
        improved = self.active & (remaining < self.best_remaining - PROGRESS_M)
        for i in np.flatnonzero(improved & self.stuck).tolist():
            self.end_stall(i, now_ns)
        self.best_remaining[improved] = remaining[improved]
        self.progress_ns[improved] = now_ns
        self.progress_driven_m[improved] = self.fleet.distance_m[improved]
        timeout = s_to_ns(self.stuck_timeout_s)
        late = self.active & ~self.stuck & (now_ns - self.progress_ns >= timeout)
        for i in np.flatnonzero(late).tolist():
            self.stuck[i] = True
            kind, why = stuck_kind(
                float(self.fleet.distance_m[i] - self.progress_driven_m[i]),
                float(remaining[i]),
                float(self.best_remaining[i]),
            )
            self.records.row(
                now_ns,
                i,
                "stuck",
                self.goal[i, 0],
                self.goal[i, 1],
                detail=f"no progress for {self.stuck_timeout_s:g} s: {kind} ({why})",
            )
            self.records.stuck(kind)
            self.status(run, i, "stuck", float(remaining[i]))

    def end_stall(self, i: int, now_ns: int) -> None:
        """Robot ``i``'s stall, if it was reported stuck, ends now: count its time stuck.

        A stall counts from the robot's last progress (the whole stall, not only the part
        after the report) to its next progress, arrival, drop, new goal or the run's end.
        """
        if self.stuck[i]:
            self.stuck[i] = False
            self.records.stalled((now_ns - int(self.progress_ns[i])) / 1e9)

    def close(self, now_ns: int) -> None:
        """The run ends: stalls still going count up to now."""
        for i in np.flatnonzero(self.stuck).tolist():
            self.end_stall(i, now_ns)

    def report(self, run: RunContext, remaining: FloatArray) -> None:
        """Publish ``progress`` with the way left (m) for every robot with a goal."""
        for i in np.flatnonzero(self.active).tolist():
            self.status(run, i, "progress", float(remaining[i]))
