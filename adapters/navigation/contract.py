"""What navigation's pluggable parts are: local controllers, global planners, traffic policies.

Each is a class registered by name in its entry-point group and chosen in ``[navigation]``:

- a **local controller** (``cosim.controllers``, ``navigation.controller``) turns every
  robot's carrot (the point of its path a lookahead ahead) into a speed and a yaw rate,
  keeping clear of what its lidar and the robots layer show; the navigation caps speeds
  near moving things afterwards, whatever the controller;
- a **global planner** (``cosim.planners``, ``navigation.planner``) finds a path on a
  robot's costmap, and may repair the stretch ahead of a path in a window;
- a **traffic policy** (``cosim.traffic``, ``navigation.traffic``) may draw one-way lanes
  the planner respects, and may take the robots over (a fleet manager moving them place by
  place instead of every robot planning for itself).

All batch over the fleet: arrays have one row per robot, in fleet order; positions are in
the ``map`` frame in metres, headings in radians (REP 103).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, ClassVar, Protocol

import numpy as np

from adapters.navigation.fleet_traffic import FleetTraffic
from adapters.navigation.layers import StaticLayers
from cosim.core.adapter import RunContext
from cosim.core.registry import Group, Registry
from models.arrays import BoolArray, FloatArray, IntArray, UInt8Array
from models.fleet.kinematics import DriveLimits
from models.geometry.occupancy import OccupancyGrid
from models.navigation.costmap import StaticCostmap
from models.navigation.traffic import MovingPoints
from models.slicing import Slices, whole
from models.world.warehouse import Warehouse, ground_truth_grid

Route = tuple[FloatArray, float]
"""A path: (k, 2) waypoints in ``map`` (m), the last one the goal, and its length (m)."""


# -- local controllers ------------------------------------------------------------------------
@dataclass(frozen=True)
class ControllerContext:
    """What a local controller knows of the run when it is built.

    Attributes:
        run: the run (settings: ``run.settings(MySettings)``; random streams).
        limits: the robots' drive limits (speeds, accelerations, yaw rates).
        radii_m: (n,) every robot's footprint radius (m).
        control_hz: the rate :meth:`LocalController.commands` is called at (Hz).
    """

    run: RunContext
    limits: DriveLimits
    radii_m: FloatArray
    control_hz: float


@dataclass(frozen=True)
class ControlInputs:
    """One control tick's view of the fleet.

    Attributes:
        pose: (n, 3) pose estimates ``x, y, yaw`` (m, rad) in ``map``.
        vel: (n, 2) measured speeds and yaw rates (m/s, rad/s).
        carrots: (n, 2) the points to head for (m).
        goals: (n, 2) the goals (m).
        points: lidar hits each robot remembers near it (m), robot ``i``'s at
            ``points[start[i]:start[i + 1]]``.
        start: (n + 1,) offsets into ``points``.
        moving: the hits that belong to moving things (their owner robot, position,
            distance ahead and to the side).
        discs: other robots heard over the network, ``x, y, radius`` (m), robot ``i``'s
            at ``discs[disc_start[i]:disc_start[i + 1]]`` (empty without the robots layer).
        disc_start: (n + 1,) offsets into ``discs``.
        now_ns: simulated time (ns).
        slices: cuts the robots over the run's threads (:mod:`models.slicing`); a batch
            controller whose robots are independent may hand it to its kernel, each
            robot's command the same whatever the cut.
        neighbours: (k, 5) what was heard of the robots in ``discs``, row for row (the
            same ``disc_start``): ``x, y, vx, vy, age_s``, position (m) and velocity (m/s,
            the heard speed along the heard heading) in ``map``, and the age of that news
            (s): now minus the time the state was sent, network latency included. Empty
            (0, 5) when the caller has none; then nothing is known of how the robots in
            ``discs`` move.
    """

    pose: FloatArray
    vel: FloatArray
    carrots: FloatArray
    goals: FloatArray
    points: FloatArray
    start: IntArray
    moving: MovingPoints
    discs: FloatArray
    disc_start: IntArray
    now_ns: int
    slices: Slices = whole
    neighbours: FloatArray = field(default_factory=lambda: np.zeros((0, 5)))


class LocalController(Protocol):
    """What a ``cosim.controllers`` entry point names: a class built once per run.

    Attributes:
        name: the registered name (``navigation.controller``).

    A controller may also set ``footprint_padding_m`` (m): the clearance beyond the
    footprint it never gives up; the global planner then blocks every cell nearer an
    obstacle than the footprint plus that (Nav2's ``footprint_padding``), so that it sends
    no robot into a gap the controller will not enter. Without it, 0.
    """

    name: ClassVar[str]

    def __init__(self, context: ControllerContext) -> None: ...

    def commands(self, inputs: ControlInputs) -> tuple[FloatArray, FloatArray, BoolArray]:
        """Every robot's speed (m/s) and yaw rate (rad/s), and which found no way ahead.

        A robot reported blocked counts as halted: it replans and starts recovering.

        What it returns is checked once per tick (:mod:`adapters.navigation.commands`):
        three numpy arrays of shape ``(n,)``, speeds and yaw rates of a real dtype and
        ``blocked`` of ``bool``, else the run ends with a
        :class:`~cosim.core.plugins.PluginError` naming the controller; so does a NaN or
        infinite speed or yaw rate. A speed beyond ``robots.max_speed_mps`` (forward) or
        ``robots.max_reverse_mps`` (backward), or a yaw rate beyond
        ``robots.max_yaw_rate_radps``, is clipped to the limit and counted
        (``controller_commands_clipped`` in the summary).
        """
        ...


def controller_contract(name: str, loaded: Any) -> str | None:
    """What a controller class lacks, or None."""
    if not isinstance(loaded, type):
        return "is not a class (expected a class built with a ControllerContext)"
    if not callable(getattr(loaded, "commands", None)):
        return "has no commands(inputs) method (see adapters.navigation.contract)"
    return None


CONTROLLERS = Group(
    "cosim.controllers",
    "local controller",
    "local controllers",
    "`adapters.navigation.contract` (`LocalController`)",
    "`navigation.controller`",
    check=controller_contract,
)
"""Local controllers (``navigation.controller``)."""


def controller_registry() -> Registry[type[LocalController]]:
    """The local controllers installed packages register (``cosim.controllers``)."""
    return CONTROLLERS.installed()


# -- global planners -------------------------------------------------------------------------
@dataclass(frozen=True)
class PlannerContext:
    """What a global planner knows of the run when it is built.

    Attributes:
        run: the run.
        static: the building's static costmap, shared by robots that do not map.
    """

    run: RunContext
    static: StaticCostmap


@dataclass(frozen=True)
class PlanRequest:
    """A path wanted from ``start`` to ``goal``.

    Attributes:
        layer: the robot's static costmap (geometry: origin, resolution, distance field).
        cost: (rows, cols) its Nav2 costs with the obstacles it plans round stamped in
            (0 free ... 252 near an obstacle, 253 inscribed, 254 lethal, 255 unknown).
        start_m: where the robot is (m).
        goal_m: its goal (m).
        lanes: one-way lanes on the layer's cells (a traffic policy's), or None.
    """

    layer: StaticCostmap
    cost: UInt8Array
    start_m: FloatArray
    goal_m: FloatArray
    lanes: UInt8Array | None


@dataclass(frozen=True)
class RepairRequest:
    """A path whose stretch ahead is to be planned again round what is in the way.

    Attributes:
        layer: the robot's static costmap.
        points: obstacle points it plans round (m).
        discs: other robots' discs ``x, y, radius`` (m), or None.
        waypoints: (k, 2) the path being followed (m).
        segment: the index of the path's segment the robot is on.
        position_m: where the robot is (m).
        lanes: one-way lanes on the layer's cells, or None.
    """

    layer: StaticCostmap
    points: FloatArray
    discs: FloatArray | None
    waypoints: FloatArray
    segment: int
    position_m: FloatArray
    lanes: UInt8Array | None


class GlobalPlanner(Protocol):
    """What a ``cosim.planners`` entry point names: a class built once per run.

    A planner may also say ``concurrent: ClassVar[bool] = True``: the plans of different
    robots due at one instant may then run at once on the run's threads (``--threads``),
    so :meth:`plan` and :meth:`repair` must not write state another call reads. Without
    it, plans run one after another. Either way they are followed in robot order, so the
    tables are the same.

    Attributes:
        name: the registered name (``navigation.planner``).
    """

    name: ClassVar[str]

    def __init__(self, context: PlannerContext) -> None: ...

    def plan(self, request: PlanRequest) -> Route | None:
        """A path over the whole map, or None if there is none."""
        ...

    def repair(self, request: RepairRequest) -> Route | None:
        """The path with its stretch ahead planned again, or None (then :meth:`plan`)."""
        ...


def planner_contract(name: str, loaded: Any) -> str | None:
    """What a planner class lacks, or None."""
    if not isinstance(loaded, type):
        return "is not a class (expected a class built with a PlannerContext)"
    for method in ("plan", "repair"):
        if not callable(getattr(loaded, method, None)):
            return f"has no {method}(request) method (see adapters.navigation.contract)"
    return None


PLANNERS = Group(
    "cosim.planners",
    "global planner",
    "global planners",
    "`adapters.navigation.contract` (`GlobalPlanner`)",
    "`navigation.planner`",
    check=planner_contract,
)
"""Global planners (``navigation.planner``)."""


def planner_registry() -> Registry[type[GlobalPlanner]]:
    """The global planners installed packages register (``cosim.planners``)."""
    return PLANNERS.installed()


# -- traffic policies ------------------------------------------------------------------------
@dataclass(frozen=True)
class TrafficContext:
    """What a traffic policy knows of the run when it is built.

    Attributes:
        run: the run.
        static: the building's static costmap.
        layers: each robot's static layer (the shared one, or the map it builds).
        starts_m: (n, 2) the robots' start positions (m).
        radius_m: the robots' footprint radius (m).
        resolution_m: the costmaps' cell size (m).
    """

    run: RunContext
    static: StaticCostmap
    layers: StaticLayers
    starts_m: FloatArray
    radius_m: float
    resolution_m: float

    def truth(self) -> OccupancyGrid:
        """The building's true occupancy grid at the costmaps' cell size (built on call)."""
        return ground_truth_grid(self.run.service(Warehouse), self.resolution_m)


class TrafficPolicy(Protocol):
    """What a ``cosim.traffic`` entry point names: a class built once per run.

    It may also declare a static ``check_scenario(scenario)`` that refuses scenarios it
    cannot run (raising :class:`~cosim.core.errors.ConfigError`) before anything is built.

    Attributes:
        name: the registered name (``navigation.traffic``).
        lanes: one-way lanes on the robots' layers' cells that planners respect, or None.
        manager: a fleet manager that moves the robots itself, or None (every robot plans).
    """

    name: ClassVar[str]
    lanes: UInt8Array | None
    manager: FleetTraffic | None

    def __init__(self, context: TrafficContext) -> None: ...


def traffic_contract(name: str, loaded: Any) -> str | None:
    """What a traffic policy class lacks, or None."""
    if not isinstance(loaded, type):
        return "is not a class (expected a class built with a TrafficContext)"
    return None


TRAFFIC_POLICIES = Group(
    "cosim.traffic",
    "traffic policy",
    "traffic policies",
    "`adapters.navigation.contract` (`TrafficPolicy`)",
    "`navigation.traffic`",
    check=traffic_contract,
)
"""Traffic policies (``navigation.traffic``)."""


def traffic_registry() -> Registry[type[TrafficPolicy]]:
    """The traffic policies installed packages register (``cosim.traffic``)."""
    return TRAFFIC_POLICIES.installed()
