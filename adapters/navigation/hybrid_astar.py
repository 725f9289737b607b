"""The ``hybrid_astar`` global planner: kinematically feasible paths of arcs and straights.

Hybrid-A* (Dolgov, Thrun, Montemerlo, Diebel, IJRR 2010; as in Nav2's Smac Hybrid-A*,
:func:`models.navigation.hybrid_astar.hybrid_astar`): a search over positions and headings
by straights, arcs of a minimum turning radius and, for a differential drive, turns on the
spot, each swept over the costmap (the robot's disc is clear where the cost under its
centre is below 253). Its paths bend no tighter than the turning radius except where they
turn on the spot, so a robot that cannot turn on the spot (or should not, carrying a load)
can follow them. The plan request carries no heading: the search leaves the start in any
direction (a differential-drive robot turns towards its path on the spot first).

A repair plans in full (``repair`` returns None): a windowed repair would have to join the
kept rest of the path at a heading the cut point does not know, and a full plan costs
only a few milliseconds on a 30 m x 30 m floor. One-way lanes are charged as ``astar``
charges them: a step against a lane costs 5 times more.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from adapters.navigation.astar import LANE_AGAINST
from adapters.navigation.contract import PlannerContext, PlanRequest, RepairRequest, Route
from cosim.scenario.fields import param
from models.navigation.hybrid_astar import HybridParams, hybrid_astar


@dataclass(frozen=True)
class HybridAStarSettings:
    """``[hybrid_astar]``: the lattice, the motions and the costs of the Hybrid-A* search."""

    ORDER: ClassVar[int] = 65
    """In a resolved scenario file, right after ``[navigation]``."""

    turning_radius_m: float = param(0.4, "radius of the arcs the paths turn by (m)", gt=0, le=10)
    cell_m: float = param(
        0.2,
        "edge of the position bins that close states; the straight motion is sqrt(2) "
        "times as long (m)",
        gt=0,
        le=2,
    )
    heading_bins: int = param(
        72, "heading bins that close states; arcs turn by whole bins", ge=4, le=720, unit="count"
    )
    turn_in_place: bool = param(True, "a differential drive may turn on the spot")
    rotate_cost_m: float = param(
        0.3, "cost of a turn on the spot by an arc's angle, as a distance driven (m)", ge=0
    )
    arc_penalty: float = param(
        1.2, "an arc costs this many times its length (Nav2's non-straight penalty)", ge=1,
        unit="ratio",
    )  # fmt: skip
    cost_weight: float = param(
        1.0,
        "weight of the costmap costs: a metre through a cell of cost c costs "
        "1 + cost_weight * c / 252",
        ge=0,
        le=100,
        unit="ratio",
    )
    max_expansions: int = param(
        100_000, "states expanded at most before a plan gives up", gt=0, unit="count"
    )
    analytic_expansion: bool = param(
        True, "try an arc then a straight (or a turn on the spot) to the goal as it searches"
    )

    def params(self) -> HybridParams:
        """The search's parameters."""
        return HybridParams(
            turning_radius_m=self.turning_radius_m,
            cell_m=self.cell_m,
            heading_bins=self.heading_bins,
            turn_in_place=self.turn_in_place,
            rotate_cost_m=self.rotate_cost_m,
            arc_penalty=self.arc_penalty,
            cost_weight=self.cost_weight,
            max_expansions=self.max_expansions,
            analytic_expansion=self.analytic_expansion,
        )


class HybridAStar:
    """Hybrid-A* over the whole map; repairs are full plans."""

    name: ClassVar[str] = "hybrid_astar"
    concurrent: ClassVar[bool] = True
    """Plans of different robots may run at once (each reads the shared maps and writes
    only arrays of its own; the primitives' cache is thread-safe)."""

    def __init__(self, context: PlannerContext) -> None:
        self.params = context.run.settings(HybridAStarSettings).params()

    def plan(self, request: PlanRequest) -> Route | None:
        """Hybrid-A* from the robot's position to its goal, both exactly."""
        layer = request.layer
        result = hybrid_astar(
            request.cost,
            request.start_m,
            request.goal_m,
            origin_xy_m=layer.origin_xy_m,
            resolution_m=layer.resolution_m,
            params=self.params,
            lanes=request.lanes,
            against=LANE_AGAINST,
        )
        if not result.found:
            return None
        return result.waypoints, result.length_m

    def repair(self, request: RepairRequest) -> Route | None:
        """None: the navigation then plans in full (see the module's docstring)."""
        return None
