"""The ``[navigation]`` section: the Nav2 role on every robot."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Literal

from cosim.scenario.fields import param


@dataclass(frozen=True)
class NavigationConfig:
    """``[navigation]``: the Nav2 role, global planning and local control on every robot.

    Defaults follow Nav2's where it has one: a 1 Hz replanning cadence as in its
    ``navigate_to_pose`` behaviour tree (``RateController hz=1.0``), a 10 Hz local
    controller, a 0.25 m goal tolerance (``xy_goal_tolerance``). Inflation uses a 1 m radius
    with scaling 3 (Nav2's code defaults are 0.55 m and 10; the gentler slope keeps robots
    in the middle of 1.6 m aisles). ``stuck`` comes after 30 s without progress: with 50
    robots in one hall, 10 s (Nav2's progress checker) mostly flags robots that are merely
    slowed by traffic and would arrive.
    """

    ORDER: ClassVar[int] = 60
    """Where the section comes in a resolved scenario and in the adapters' order."""

    planner: str = param(
        "astar", "global planner on the costmap, a registered planner", registry="cosim.planners"
    )
    controller: str = param(
        "dwa", "local controller, a registered controller", registry="cosim.controllers"
    )
    replan_hz: float = param(1.0, "periodic global replanning rate (Hz)", gt=0, le=50)
    control_hz: float = param(10.0, "local controller rate (Hz)", gt=0, le=100)
    robots_layer: bool | Literal["auto"] = param(
        "auto",
        "robots broadcast pose and footprint over the network; others avoid them and their "
        "mappers leave them out of the map; auto: on whenever mapping.enabled",
    )
    robots_layer_hz: float = param(5.0, "robots layer broadcast rate (Hz)", gt=0, le=1000)
    robots_layer_timeout_s: float = param(1.0, "forget a robot not heard from for (s)", gt=0)
    resolution_m: float = param(0.1, "costmap cell size (m)", gt=0, le=1)
    inflation_radius_m: float = param(1.0, "inflation radius (m)", gt=0, le=10.0)
    cost_scaling: float = param(3.0, "inflation cost scaling factor (1/m)", gt=0, unit="1/m")
    lookahead_m: float = param(1.0, "carrot distance ahead on the path (m)", gt=0)
    goal_tolerance_m: float = param(0.25, "distance at which a goal is reached (m)", gt=0)
    obstacle_memory_s: float = param(3.0, "how long lidar obstacles stay in the costmap (s)", ge=0)
    stuck_timeout_s: float = param(
        30.0,
        "no progress for this long reports `stuck` (s); the paper's robots stall 20-30 s "
        "before the fleet layer re-targets them",
        gt=0,
    )
    progress_hz: float = param(1.0, "rate of `progress` status reports (Hz)", gt=0, le=1000)
    traffic: str = param(
        "none",
        "fleet traffic policy, a registered one: 'none': every robot plans for itself; 'lanes': "
        "the same with aisles up to 2.5 m wide one-way, neighbours in opposite directions "
        "(the planner charges 5x for a step against one); 'pibt': the fleet manager moves "
        "every robot over a 2r + 0.14 m grid of places with those one-way aisles, one PIBT "
        "step at a time (Okumura et al. 2022), robots stalled 10 s first, then the oldest goal",
        registry="cosim.traffic",
    )
    goals: tuple[tuple[float, float], ...] = param(
        (),
        "driver 'navigation': a series of goals [[x_m, y_m], ...] in map, visited in order "
        "and round again (robot i starts at goal i); empty: random reachable goals",
        unit="m",
    )

    def robots_layer_on(self, mapping: bool) -> bool:
        """Whether the robots layer runs, in a run where ``mapping.enabled`` is ``mapping``.

        ``auto`` turns it on with mapping: robots are not the building, and a mapper that
        does not know where the others are draws them into its map as walls (in
        ``warehouse-random``, 10 seeds x 120 s at drift 0.02, fleet map IoU 0.94-1.00 with it,
        0.86-1.00 without: ``make study-mapping-defaults``).
        """
        return mapping if self.robots_layer == "auto" else bool(self.robots_layer)
