"""Global planning for every robot: when to plan, on what, and what to do with a path.

Each robot plans on its costmap (:class:`~adapters.navigation.layers.StaticLayers`): the
static layer plus the moving things it remembers and, with ``navigation.robots_layer``, the
other robots' discs heard over the network; the global planner (``navigation.planner``, A*
by default) finds the path. A replan first asks the planner to repair the stretch ahead and
plans in full when that finds nothing or a much longer way; if nothing is found with what
the robot sees, it plans on the static layer alone, as Nav2's "clear costmap" recovery
does. Periodic replans (``replan_hz``) happen only when something moving is on the path
ahead or round the last plan.
"""

from __future__ import annotations

import math
import time

import numpy as np

from adapters.fleet.robots_layer import RobotsLayer
from adapters.navigation.contract import GlobalPlanner, PlanRequest, RepairRequest
from adapters.navigation.layers import StaticLayers, open_goal
from adapters.navigation.scan_memory import MovingMemory, ScanMemory
from adapters.navigation.tables import NavRecords
from cosim.core.adapter import RunContext
from cosim.core.hosts import HostId
from cosim.core.messages import Path
from cosim.core.timebase import period_ns
from models.arrays import FloatArray
from models.navigation.costmap import StaticCostmap, with_obstacles
from models.navigation.follow import PathBook, paths_blocked
from models.navigation.landmarks import ALT_MIN_CELLS, LandmarkCache
from models.navigation.lanes import in_lanes
from models.navigation.planner import shortest_path_length_m
from models.navigation.traffic import MovingPoints

PATH_CLEARANCE_M = 0.3
"""A moving thing closer than footprint plus this to the path ahead calls for a replan (m)."""
REPAIR_DETOUR_M = 2.0
"""A repair lengthening the way by more than this is checked against a full replan (m)."""
GOAL_OPENING_M = 0.15
"""Beyond the padding, how far round a goal in the padding its cells are opened (m): more
than a diagonal cell of the default 0.1 m costmap, so that the goal joins free space."""
OFF_MAP = "off the map"
"""Why a robot whose pose lies outside its costmap got no plan."""
Found = tuple[tuple[np.ndarray, float] | None, str, np.ndarray]
"""A plan's outcome: the route ``(waypoints, length_m)`` or None, how it was found, and the
moving things planned round."""


class GlobalPlanning:
    """Plans, repairs and replans of every robot's global path.

    Args:
        planner: the global planner.
        static: the static layer every robot shares (the building's map).
        layers: each robot's static layer (the shared one, or the map it builds).
        plan_layers: the layers plans are made on: ``layers`` with the controller's
            footprint padding (:func:`adapters.navigation.layers.padded`), or ``layers``.
        padding_m: that padding (m).
        lanes: one-way lanes on the layers' cells (``traffic = "lanes"``), or None.
        memory: the scans each robot keeps.
        moving: the moving things each robot remembers.
        robots_layer: the other robots' discs heard over the network, or None.
        paths: every robot's path (followed by the local controller).
        pose: (n, 3) every robot's pose, updated in place by the adapter.
        goal: (n, 2) every robot's goal, updated in place by the adapter.
        radius_m: footprint radius (m).
        inflation_m: inflation radius (m).
        replan_hz: periodic replanning rate (Hz).
        mapping: robots plan on maps they build (repairs are off: the rest of an old
            path was planned on an older map).
        records: the navigation table.
        hosts: every robot's host (its ``plan`` topic is published from there).
        plan_topics: every robot's ``plan`` topic.
    """

    def __init__(
        self,
        *,
        planner: GlobalPlanner,
        static: StaticCostmap,
        layers: StaticLayers,
        plan_layers: StaticLayers,
        padding_m: float,
        lanes: np.ndarray | None,
        memory: ScanMemory,
        moving: MovingMemory,
        robots_layer: RobotsLayer | None,
        paths: PathBook,
        pose: FloatArray,
        goal: FloatArray,
        radius_m: float,
        inflation_m: float,
        replan_hz: float,
        mapping: bool,
        records: NavRecords,
        hosts: list[HostId],
        plan_topics: list[str],
    ) -> None:
        self.planner = planner
        self.static = static
        self.layers = layers
        self.plan_layers = plan_layers
        self.padding_m = padding_m
        self.lanes = lanes
        self.memory = memory
        self.moving = moving
        self.robots_layer = robots_layer
        self.paths = paths
        self.pose = pose
        self.goal = goal
        self.radius = radius_m
        self.inflation_m = inflation_m
        self.replan_ns = period_ns(replan_hz)
        self.mapping = mapping
        self.records = records
        self.hosts = hosts
        self.plan_topics = plan_topics
        n = len(pose)
        self.planned_around = np.zeros(n, dtype=bool)
        self.next_plan_ns = np.zeros(n, dtype=np.int64)
        # landmark bounds for the yardstick's searches on the building's map, built on first
        # use, on floors large enough for them to pay
        self.landmarks = LandmarkCache(static) if static.cost.size >= ALT_MIN_CELLS else None

    def yardstick(self, start: FloatArray, goal: FloatArray) -> float:
        """The shortest way (m) on the true map from ``start`` to ``goal``."""
        marks = None if self.landmarks is None else self.landmarks.get(0.0)
        return shortest_path_length_m(self.static, start, goal, landmarks=marks)

    def replan_due(
        self, run: RunContext, now_ns: int, active: np.ndarray, moving: MovingPoints
    ) -> None:
        """Periodic replans of the robots due, where the costmap changed where it matters.

        Something moving on the path ahead now, or round the last plan (Nav2 replans at
        1 Hz whatever happens; without a change the result is the same path).
        """
        due = active & (now_ns >= self.next_plan_ns)
        if not due.any():
            return
        on_path = paths_blocked(
            self.paths, moving.owner, moving.points, self.radius + PATH_CLEARANCE_M
        )
        replan = []
        for i in np.flatnonzero(due).tolist():
            if self.planned_around[i] or on_path[i]:
                replan.append(i)
            else:
                self.next_plan_ns[i] = now_ns + self.replan_ns
        if len(replan) > 1 and getattr(self.planner, "concurrent", False):
            # routes of different robots at once on the run's threads; followed in order,
            # each plan_ms its own route's time (not the batch's)
            def timed(i: int) -> tuple[Found, float]:
                start = time.perf_counter()
                return self.route(i, now_ns, replan=True), time.perf_counter() - start

            routes = run.workers.map(timed, replan)
            for i, (found, took_s) in zip(replan, routes, strict=True):
                self.finish(run, i, now_ns, found, time.perf_counter() - took_s, replan=True)
            return
        for i in replan:
            self.plan(run, i, now_ns, replan=True)

    def _obstacles(self, i: int, now_ns: int) -> tuple[np.ndarray, np.ndarray]:
        """What robot ``i`` plans round: moving things it remembers, robots it hears."""
        res = self.layers.resolution_m
        points = self.moving.recall(i, res)
        points = points[~self.memory.seen_through(i, points, 2 * res)]
        if self.lanes is not None and len(points):
            # in a one-way aisle whatever moves goes the robot's way: it is traffic to
            # follow (the local controller keeps the distance), not a wall to plan round
            points = points[~in_lanes(self.lanes, points, self.layers.origin_xy_m, res)]
        no_discs = np.zeros((0, 3))
        discs = no_discs if self.robots_layer is None else self.robots_layer.discs(i, now_ns)
        return points, discs

    def plan(self, run: RunContext, i: int, now_ns: int, *, replan: bool) -> bool:
        """Plan robot ``i``'s way and follow it; False when none was found."""
        started = time.perf_counter()
        found = self.route(i, now_ns, replan=replan)
        self.finish(run, i, now_ns, found, started, replan=replan)
        return found[0] is not None

    def off_map(self, i: int) -> bool:
        """Whether robot ``i``'s pose lies outside its costmap (no plan can start there)."""
        layer = self.layers[i]
        return not layer.in_bounds(layer.world_to_cell(self.pose[i, :2]))

    def route(self, i: int, now_ns: int, *, replan: bool) -> Found:
        """A new route for robot ``i`` (:data:`Found`), not followed yet.

        None for a robot whose pose is off its costmap (``detail`` says so): it is told
        to stop (:meth:`off_map`), never planned from outside the grid.
        """
        if self.off_map(i):
            return None, OFF_MAP, np.zeros((0, 2))
        points, discs = self._obstacles(i, now_ns)
        layer = self.layers[i]
        # a robot mapping as it goes plans in full: the rest of its old path was planned on
        # an older map, through space that may since have turned out to be wall
        repair = replan and not self.mapping and self.paths.lengths[i] >= 2
        nothing = np.zeros((0, 2))
        # with what it sees, then as Nav2's "clear costmap" recovery does on the static
        # layer alone (leaving the robots and people in the way to the local controller);
        # each first as a repair of the stretch ahead, then in full; a repair that makes
        # the way much longer than it was is checked against a full replan (another aisle
        # may be shorter than the detour round a jam)
        route = None
        detail = ""
        was = float(self.paths.follow_one(i, self.pose[i, 0], self.pose[i, 1])) if repair else 0.0
        for seen, near, detail in ((points, discs, ""), (nothing, np.zeros((0, 3)), "cleared")):
            route = self._repair(i, layer, seen, near) if repair else None
            if route is not None and route[1] <= was + REPAIR_DETOUR_M:
                detail = f"{detail} repaired".strip()
                break
            repaired, route = route, self._full(i, layer, seen, near)
            if route is None and repaired is not None:
                route, detail = repaired, f"{detail} repaired".strip()
            if route is not None:
                break
        return route, detail, points

    def finish(
        self, run: RunContext, i: int, now_ns: int, found: Found, started: float, *, replan: bool
    ) -> None:
        """Follow a found route (or retry at the next replan) and record the plan."""
        route, detail, points = found
        if route is not None:
            self._set_path(run, i, now_ns, route[0], points)
        else:
            self.next_plan_ns[i] = now_ns + self.replan_ns
            if detail == OFF_MAP:
                # a path to follow from where the robot is not, perhaps to an old goal:
                # none; it plans afresh once back on the map
                self.paths.clear(i)
        self.records.row(
            now_ns,
            i,
            "replan" if replan else "plan",
            self.goal[i, 0],
            self.goal[i, 1],
            path_length_m=route[1] if route is not None else math.nan,
            plan_ms=(time.perf_counter() - started) * 1e3,
            detail=detail if route is not None or detail == OFF_MAP else "no path",
        )

    def _repair(
        self, i: int, layer: StaticCostmap, points: np.ndarray, discs: np.ndarray
    ) -> tuple[np.ndarray, float] | None:
        """The path with its stretch ahead replanned, or None."""
        request = RepairRequest(
            self.plan_layers[i],
            points,
            discs if len(discs) else None,
            self.paths.waypoints(i),
            int(self.paths.segment[i]),
            self.pose[i, :2],
            self.lanes,
        )
        return self.planner.repair(request)

    def _full(
        self, i: int, layer: StaticCostmap, points: np.ndarray, discs: np.ndarray
    ) -> tuple[np.ndarray, float] | None:
        """A path from the robot to its goal over the whole map, or None.

        Searched on the padded costs (:func:`adapters.navigation.layers.padded`) with a
        way into a goal that lies in the padding; ``layer`` (the unpadded one) gives the
        grid's geometry and, on the building's map, the planner's landmark bounds (the
        padded costs are never below it).
        """
        plan_layer = self.plan_layers[i]
        cost = with_obstacles(plan_layer, points, discs=discs if len(discs) else None)
        if plan_layer is not layer:
            open_goal(cost, layer, plan_layer, self.goal[i], GOAL_OPENING_M + self.padding_m)
        request = PlanRequest(layer, cost, self.pose[i, :2], self.goal[i], self.lanes)
        return self.planner.plan(request)

    def _set_path(
        self,
        run: RunContext,
        i: int,
        now_ns: int,
        waypoints: np.ndarray,
        points: np.ndarray,
    ) -> None:
        """Robot ``i`` follows ``waypoints``, published on its ``plan`` topic."""
        self.paths.set(i, waypoints)
        # Nav2's planner publishes every plan it makes on `plan` (for tools; nothing here
        # subscribes)
        run.bus.publish(self.plan_topics[i], Path(now_ns, "map", waypoints.copy()), self.hosts[i])
        # moving things the new path bends around: replan while they may leave
        shaped = paths_blocked(
            self.paths,
            np.full(len(points), i),
            points,
            self.radius + self.inflation_m,
            len(waypoints),
        )
        self.planned_around[i] = bool(shaped[i])
        self.next_plan_ns[i] = now_ns + self.replan_ns
