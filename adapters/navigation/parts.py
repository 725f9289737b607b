"""The parts of the navigation stack, and the one order they are built in.

:func:`build_parts` builds every part the navigation adapter's ticks use, from the run's
settings and services: the costmaps and the traffic policy, localization, the scans each
robot keeps, the robots layer, the local controller, recovery, the goals, the topics and
global planning. The order is the run's: what is provided to the run, advertised on the
bus and drawn from its random streams happens in it, so it stays as it is.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from adapters.fleet.motion import drive_limits
from adapters.fleet.robots_layer import RobotsLayer
from adapters.mapping.settings import MappingConfig
from adapters.navigation.contract import (
    ControllerContext,
    LocalController,
    PlannerContext,
    TrafficContext,
    controller_registry,
    planner_registry,
    traffic_registry,
)
from adapters.navigation.fleet_traffic import FleetTraffic
from adapters.navigation.goal_tracking import Drivers, GoalTracker
from adapters.navigation.layers import StaticLayers, padded, robot_layers, static_costmap
from adapters.navigation.localization import Localization
from adapters.navigation.off_map import OffMapWatch
from adapters.navigation.planning import GlobalPlanning
from adapters.navigation.recovery import Recovery, StallWatch
from adapters.navigation.scan_memory import MovingMemory, ScanMemory
from adapters.navigation.settings import NavigationConfig
from adapters.navigation.tables import NavRecords
from adapters.navigation.wiring import NavWiring
from cosim.core.adapter import RunContext
from cosim.core.errors import ConfigError
from cosim.core.hosts import HostId
from cosim.core.timebase import s_to_ns
from cosim.scenario.sections import LidarConfig, RobotsConfig
from models.arrays import FloatArray
from models.fleet.kinematics import DriveLimits, FleetState
from models.navigation.costmap import StaticCostmap
from models.navigation.dwa import DwaParams
from models.navigation.follow import PathBook
from models.navigation.traffic import TrafficParams
from models.sensing.lidar import ScanGeometry


@dataclass
class NavigationParts:
    """Every part of the navigation stack, shared as built (arrays are updated in place).

    Attributes:
        names: the robots, in fleet order.
        hosts: each robot's host.
        radius_m: the robots' footprint radius (m).
        mapping: robots build their own maps (and plan on them).
        static: the building's static costmap (offered to the run).
        layers: each robot's static layer (the shared one, or the map it builds).
        manager: the traffic policy's fleet manager, when it moves the robots, or None.
        localization: every robot's pose estimate (``map``) and measured velocity.
        limits: the robots' drive limits.
        memory: the lidar hits each robot keeps.
        moving: the moving things each robot remembers.
        near_m: lidar hits within this of a robot matter to its controller (m): what it can
            drive in a DWA horizon, plus its radius and a metre.
        paths: every robot's path being followed.
        robots_layer: the other robots' discs heard over the network, or None.
        records: the navigation table.
        control: the local controller (``navigation.controller``).
        recovery: the recovery moves of blocked robots.
        stalls: the watch for robots that hardly move.
        goals: every robot's goal and its status.
        interface: every robot's navigation topics.
        planning: global planning (``navigation.planner``).
        off_map: the robots whose pose is off the costmap.
        traffic: how robots keep clear of moving things (speed caps, keeping right).
    """

    names: list[str]
    hosts: list[HostId]
    radius_m: float
    mapping: bool
    static: StaticCostmap
    layers: StaticLayers
    manager: FleetTraffic | None
    localization: Localization
    limits: DriveLimits
    memory: ScanMemory
    moving: MovingMemory
    near_m: float
    paths: PathBook
    robots_layer: RobotsLayer | None
    records: NavRecords
    control: LocalController
    recovery: Recovery
    stalls: StallWatch
    goals: GoalTracker
    interface: NavWiring
    planning: GlobalPlanning
    off_map: OffMapWatch
    traffic: TrafficParams

    @property
    def pose(self) -> FloatArray:
        """(n, 3) every robot's pose estimate in ``map`` (m, rad), updated in place."""
        return self.localization.pose


def build_parts(run: RunContext) -> NavigationParts:
    """Every part of the navigation stack for the run's robots.

    Raises:
        ConfigError: when the robots have no lidar (the local controller avoids what the
            lidar sees).
    """
    cfg = run.settings(NavigationConfig)
    _require_lidar(run)
    fleet = run.service(FleetState)
    names = list(fleet.names)
    hosts = [HostId(n) for n in names]
    n = len(names)
    radius = run.settings(RobotsConfig).radius_m
    static = static_costmap(run, radius)
    mapping = run.settings(MappingConfig).enabled
    layers = robot_layers(run, static, n)
    starts = np.stack([fleet.x, fleet.y], axis=1)
    traffic = traffic_registry().get(cfg.traffic)(
        TrafficContext(run, static, layers, starts, radius, cfg.resolution_m)
    )
    manager = traffic.manager  # a fleet manager moves the robots itself, or None
    run.provide(static)
    localization = Localization(run, fleet, mapping=mapping)
    pose = localization.pose
    limits = drive_limits(run)
    memory = _scan_memory(run, n)
    moving = MovingMemory(s_to_ns(cfg.obstacle_memory_s), layers.resolution_m)
    paths = PathBook(n)
    robots_layer = _robots_layer(run, cfg, names, hosts, radius, mapping=mapping)
    records = NavRecords(run.recorder, names, max_speed_mps=limits.max_speed_mps)
    rngs = [run.rng.stream(f"navigation/{name}") for name in names]
    control = controller_registry().get(cfg.controller)(
        ControllerContext(run, limits, fleet.radius_m, cfg.control_hz)
    )
    recovery = Recovery(n, memory, limits, radius, rngs)
    stalls = StallWatch(pose)
    interface = NavWiring.of(names, hosts)
    goals = GoalTracker(
        fleet,
        hosts,
        interface.status,
        pose,
        np.zeros((n, 2)),
        records,
        stuck_timeout_s=cfg.stuck_timeout_s,
        goal_tolerance_m=cfg.goal_tolerance_m,
    )
    interface.advertise(run.bus)
    if robots_layer is not None:
        robots_layer.advertise(run)
    # plans keep out of gaps the controller will not enter (robots building their own
    # maps plan on them as they come, unpadded)
    padding = float(getattr(control, "footprint_padding_m", 0.0))
    plan_static = padded(static, padding)
    plan_layers = layers if mapping else StaticLayers.shared(plan_static, n)
    planner = planner_registry().get(cfg.planner)(PlannerContext(run, static))
    planning = GlobalPlanning(
        planner=planner,
        static=static,
        layers=layers,
        plan_layers=plan_layers,
        padding_m=padding,
        lanes=traffic.lanes,
        memory=memory,
        moving=moving,
        robots_layer=robots_layer,
        paths=paths,
        pose=pose,
        goal=goals.goal,
        radius_m=radius,
        inflation_m=cfg.inflation_radius_m,
        replan_hz=cfg.replan_hz,
        mapping=mapping,
        records=records,
        hosts=hosts,
        plan_topics=interface.plan,
    )
    places = None if manager is None else manager.places
    goals.drivers = Drivers(static, planning, paths, places, recovery, stalls, mapping)
    return NavigationParts(
        names=names,
        hosts=hosts,
        radius_m=radius,
        mapping=mapping,
        static=static,
        layers=layers,
        manager=manager,
        localization=localization,
        limits=limits,
        memory=memory,
        moving=moving,
        # lidar hits within what a robot can drive in a DWA horizon (plus a margin) matter
        near_m=limits.max_speed_mps * DwaParams().sim_time_s + radius + 1.0,
        paths=paths,
        robots_layer=robots_layer,
        records=records,
        control=control,
        recovery=recovery,
        stalls=stalls,
        goals=goals,
        interface=interface,
        planning=planning,
        off_map=OffMapWatch(static, pose, goals, planning, records, replan=manager is None),
        traffic=TrafficParams(),
    )


def _require_lidar(run: RunContext) -> None:
    if run.settings(LidarConfig).beams == 0:
        raise ConfigError(
            f"{run.scenario.source}: [robots] driver = 'navigation': expected lidar.beams "
            "> 0 (the local controller avoids what the lidar sees)"
        )


def _scan_memory(run: RunContext, robots: int) -> ScanMemory:
    """Each robot's lidar hits, from the lidar's beams (angles in the sensor frame)."""
    lidar = run.settings(LidarConfig)
    angles = ScanGeometry(lidar.beams, math.radians(lidar.fov_deg), 0.0, 1.0).angles()
    return ScanMemory(robots, angles, lidar.range_max_m)


def _robots_layer(
    run: RunContext,
    cfg: NavigationConfig,
    names: list[str],
    hosts: list[HostId],
    radius: float,
    *,
    mapping: bool,
) -> RobotsLayer | None:
    """The robots layer, offered to the run, when ``navigation.robots_layer`` is on; else None."""
    if not cfg.robots_layer_on(mapping):
        return None
    robots_layer = RobotsLayer(names, hosts, radius, cfg.robots_layer_timeout_s)
    run.provide(robots_layer)
    return robots_layer
