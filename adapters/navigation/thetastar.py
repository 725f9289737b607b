"""The ``thetastar`` global planner: any-angle Theta* on the costmap, with windowed repairs.

A full plan is Theta* (Nash, Daniel, Koenig, Felner, AAAI 2007; in its lazy form, Nash,
Koenig, Tovey, AAAI 2010; :func:`models.navigation.thetastar.theta_star`): A* on the
8-connected grid whose cells may take their parent's parent when it sees them, with a
cost-aware line of sight as Nav2's Theta* planner has (cells at or above 253 refused, the
cells crossed charged by the ``astar`` planner's cost formula, integrated along the
segment). Its paths bend only round obstacles, so they need no pruning.

A repair plans the stretch ahead again by Theta* in a window round it, as ``astar``'s
repair does with A*, and keeps the rest of the path. The navigation asks for a repair at
every replan and plans in full only when the repair finds nothing or a much longer way:
a repair keeps replans local (a window of a few thousand cells instead of the floor) and
the path beyond the window unchanged, where returning None would make every replan a
full plan. One-way lanes are charged as ``astar`` charges them: a cell passed against
its lane costs 5 times more.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from adapters.navigation.astar import LANE_AGAINST
from adapters.navigation.contract import PlannerContext, PlanRequest, RepairRequest, Route
from cosim.scenario.fields import param
from models.navigation.planner import path_to_world
from models.navigation.repair import RepairParams
from models.navigation.thetastar import repair_theta, theta_star


@dataclass(frozen=True)
class ThetaStarSettings:
    """``[thetastar]``: the cost weight of Theta*'s paths and the reach of its repairs."""

    ORDER: ClassVar[int] = 64
    """In a resolved scenario file, right after ``[navigation]``."""

    cost_weight: float = param(
        1.0,
        "weight of the costmap costs: a metre through cells of cost c costs "
        "1 + cost_weight * c / 252; 0: the shortest any-angle path",
        ge=0,
        le=100,
        unit="ratio",
    )
    repair_ahead_m: float = param(
        8.0, "a repair plans the path again up to this far ahead of the robot (m)", gt=0
    )
    repair_margin_m: float = param(
        3.0, "a repair searches this far round the stretch it plans again (m)", gt=0
    )


class ThetaStar:
    """Theta* over the whole map, and Theta* repairs of the stretch ahead in a window."""

    name: ClassVar[str] = "thetastar"
    concurrent: ClassVar[bool] = True
    """Plans of different robots may run at once (each reads the shared maps and writes
    only arrays of its own)."""

    def __init__(self, context: PlannerContext) -> None:
        self.settings = context.run.settings(ThetaStarSettings)
        self.repair_params = RepairParams(
            self.settings.repair_ahead_m, self.settings.repair_margin_m
        )

    def plan(self, request: PlanRequest) -> Route | None:
        """Theta* from the robot's cell to its goal's; the last waypoint is the goal itself."""
        layer = request.layer
        result = theta_star(
            request.cost,
            layer.world_to_cell(request.start_m),
            layer.world_to_cell(request.goal_m),
            cost_weight=self.settings.cost_weight,
            resolution_m=layer.resolution_m,
            lanes=request.lanes,
            against=LANE_AGAINST,
        )
        if not result.found:
            return None
        waypoints = path_to_world(layer, result.cells)
        waypoints[-1] = request.goal_m
        return waypoints, float(np.hypot(*np.diff(waypoints, axis=0).T).sum())

    def repair(self, request: RepairRequest) -> Route | None:
        """The stretch ahead planned again by Theta* in a window round it, the rest kept."""
        repaired = repair_theta(
            request.layer,
            request.points,
            request.discs,
            request.waypoints,
            request.segment,
            request.position_m,
            self.repair_params,
            cost_weight=self.settings.cost_weight,
            lanes=request.lanes,
            against=LANE_AGAINST,
        )
        return None if repaired is None else (repaired.waypoints, repaired.length_m)
