"""The ``astar`` global planner: A* on the costmap, with local repair of the stretch ahead.

A full plan is A* (8-connected, octile heuristic, costs that respect Nav2's inflation
formula, :func:`models.navigation.planner.plan`), bounded by landmark distances (ALT) on the
shared building map of floors large enough for them to pay; the path is pruned to its
corners. A repair plans the 8 m ahead again in a window round that stretch
(:mod:`models.navigation.repair`) and keeps the rest.
"""

from __future__ import annotations

from typing import ClassVar

from adapters.navigation.contract import PlannerContext, PlanRequest, RepairRequest, Route
from models.navigation.landmarks import ALT_MIN_CELLS, LandmarkCache
from models.navigation.planner import path_to_world, plan, prune_path
from models.navigation.repair import RepairParams, repair_path

LANE_AGAINST = 5.0
"""With one-way lanes: a step against an aisle's direction costs this many times more."""


class AStar:
    """A* with landmark bounds on the building's map, and windowed repairs."""

    name: ClassVar[str] = "astar"
    concurrent: ClassVar[bool] = True
    """Plans of different robots may run at once (each reads the shared maps and writes
    only its own arrays; the landmark cache builds under a lock)."""

    def __init__(self, context: PlannerContext) -> None:
        self.static = context.static
        self.repair_params = RepairParams()
        # landmark bounds on the shared static layer, built on first use, on floors large
        # enough for the fleet's plans to pay for them (not on a map a robot builds: other
        # costs)
        cells = context.static.cost.size
        self.landmarks = LandmarkCache(context.static) if cells >= ALT_MIN_CELLS else None

    def plan(self, request: PlanRequest) -> Route | None:
        """A* over the whole map from the robot to its goal, pruned to its corners."""
        layer = request.layer
        marks = None
        if self.landmarks is not None and layer is self.static:
            marks = self.landmarks.get(1.0)
        result = plan(
            request.cost,
            layer.world_to_cell(request.start_m),
            layer.world_to_cell(request.goal_m),
            resolution_m=layer.resolution_m,
            lanes=request.lanes,
            against=LANE_AGAINST,
            landmarks=marks,
        )
        if not result.found:
            return None
        waypoints = path_to_world(layer, prune_path(request.cost, result.cells))
        waypoints[-1] = request.goal_m
        return waypoints, result.length_m

    def repair(self, request: RepairRequest) -> Route | None:
        """The stretch ahead planned again in a window round it, the rest kept."""
        repaired = repair_path(
            request.layer,
            request.points,
            request.discs,
            request.waypoints,
            request.segment,
            request.position_m,
            self.repair_params,
            lanes=request.lanes,
            against=LANE_AGAINST,
        )
        return None if repaired is None else (repaired.waypoints, repaired.length_m)
