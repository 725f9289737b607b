"""The navigation adapter: the Nav2 role on every robot.

Interface (per robot, on the robot's host): a :class:`~cosim.core.messages.NavGoal` on
``/<robot>/nav/goal`` means "go to (x, y)" (a goal with NaN coordinates cancels the current
one: the robot stops, status ``cancelled``); the adapter answers on ``/<robot>/nav/status``
with ``accepted``, periodic ``progress``, ``arrived``, ``stuck`` (no progress for
``navigation.stuck_timeout_s``; it keeps trying) and ``unreachable`` (outside the map,
inside an obstacle, or enclosed on the static map; the goal is dropped).

Each robot plans on its own costmap: the static layer (pluggable through the
:class:`StaticLayer` service; the ground-truth map by default) inflated once, plus the
lidar hits it remembers and, with ``navigation.robots_layer``, the other robots' discs
heard over the network. A* gives the global path (replanned at ``replan_hz``, when the
controller is blocked, and after recoveries); a batched Dynamic Window Approach follows
it at ``control_hz``, keeping clear of the latest scan's hits. Blocked robots recover:
wait, rotate, back up, replan.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any, ClassVar

import numpy as np

from adapters.fleet.motion import drive_limits
from adapters.fleet.robots_layer import RobotsLayer
from adapters.mapping.settings import MappingConfig
from adapters.naming import topic
from adapters.navigation.contract import (
    ControlInputs,
    ControllerContext,
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
from adapters.navigation.planning import GlobalPlanning
from adapters.navigation.recovery import Recovery, StallWatch
from adapters.navigation.scan_memory import MovingMemory, ScanMemory
from adapters.navigation.settings import NavigationConfig
from adapters.navigation.tables import NAVIGATION, NavRecords
from cosim.core.adapter import RunContext
from cosim.core.bus import Envelope
from cosim.core.errors import ConfigError
from cosim.core.hosts import HostId
from cosim.core.kernel import Stage
from cosim.core.messages import (
    LaserScan,
    Message,
    NavGoal,
    NavStatus,
    Path,
    Twist,
)
from cosim.core.messages import OccupancyGrid as GridMessage
from cosim.core.table import TableSpec
from cosim.core.timebase import NS_PER_S, period_ns, s_to_ns
from cosim.scenario.model import Scenario
from cosim.scenario.sections import LidarConfig, RobotsConfig
from models.arrays import BoolArray
from models.fleet.kinematics import FleetState
from models.navigation.dwa import DwaParams
from models.navigation.follow import PathBook
from models.navigation.place_drive import free_ahead
from models.navigation.traffic import (
    MovingPoints,
    TrafficParams,
    keep_right,
    moving_points,
    speed_caps,
)
from models.sensing.lidar import ScanGeometry

HALT_MPS = 0.02
"""Commanded speed below which a robot with a goal counts as halted (m/s)..."""
HALT_RADPS = 0.05
"""...when it does not turn faster than this either (rad/s)."""


class NavigationAdapter:
    """Global planning, local control, recovery and status reports for every robot."""

    name: ClassVar[str] = "navigation"
    requires: ClassVar[tuple[str, ...]] = ("world", "fleet", "lidar")
    tables: ClassVar[tuple[TableSpec, ...]] = (NAVIGATION,)
    """The tables it writes (documented in the table reference)."""

    @staticmethod
    def check_scenario(scenario: Scenario) -> None:
        """Names known, and what the chosen traffic policy refuses (before anything is built).

        A policy may declare ``check_scenario(scenario)``: the fleet manager refuses robots
        that cannot localize well enough for its places.
        """
        cfg = scenario.section(NavigationConfig)
        controller_registry().get(cfg.controller)
        planner_registry().get(cfg.planner)
        check = getattr(traffic_registry().get(cfg.traffic), "check_scenario", None)
        if check is not None:
            check(scenario)

    def __init__(self, run: RunContext) -> None:
        cfg = run.settings(NavigationConfig)
        if run.settings(LidarConfig).beams == 0:
            raise ConfigError(
                f"{run.scenario.source}: [robots] driver = 'navigation': expected lidar.beams "
                "> 0 (the local controller avoids what the lidar sees)"
            )
        self.cfg = cfg
        self.fleet = run.service(FleetState)
        self.names = list(self.fleet.names)
        self.hosts = [HostId(n) for n in self.names]
        n = len(self.names)
        radius = run.settings(RobotsConfig).radius_m
        self.static = static_costmap(run, radius)
        self.mapping = run.settings(MappingConfig).enabled
        self.layers = robot_layers(run, self.static, n)
        starts = np.stack([self.fleet.x, self.fleet.y], axis=1)
        traffic = traffic_registry().get(cfg.traffic)(
            TrafficContext(run, self.static, self.layers, starts, radius, cfg.resolution_m)
        )
        self.lanes = traffic.lanes
        self.manager = traffic.manager  # a fleet manager moves the robots itself, or None
        run.provide(self.static)
        self.localization = Localization(run, self.fleet, mapping=self.mapping)
        self.measured = self.localization.measured
        self.limits = drive_limits(run)
        self.period_ns = period_ns(cfg.control_hz)
        lidar = run.settings(LidarConfig)
        angles = _beam_angles(lidar.beams, math.radians(lidar.fov_deg))
        self.memory = ScanMemory(n, angles, lidar.range_max_m)
        self.moving = MovingMemory(s_to_ns(cfg.obstacle_memory_s), self.layers.resolution_m)
        # lidar hits within what a robot can drive in a DWA horizon (plus a margin) matter
        self.near_m = self.limits.max_speed_mps * DwaParams().sim_time_s + radius + 1.0
        self.paths = PathBook(n)
        self.pose = self.localization.pose
        self.vel = self.localization.vel
        self.robots_layer: RobotsLayer | None = None
        if cfg.robots_layer:
            self.robots_layer = RobotsLayer(
                self.names, self.hosts, radius, cfg.robots_layer_timeout_s
            )
            run.provide(self.robots_layer)
        self.records = NavRecords(run.recorder, self.names)
        self.rngs = [run.rng.stream(f"navigation/{name}") for name in self.names]
        self.traffic = TrafficParams()
        self.radius = radius
        self.control = controller_registry().get(cfg.controller)(
            ControllerContext(run, self.limits, self.fleet.radius_m, cfg.control_hz)
        )
        self.recovery = Recovery(n, self.memory, self.limits, radius, self.rngs)
        self.stalls = StallWatch(self.pose)
        self.off: BoolArray = np.zeros(n, dtype=bool)
        """Robots whose pose is off the costmap (stopped until it is back)."""
        self.status_topics = [topic(n, "nav/status") for n in self.names]
        self.goals = GoalTracker(
            self.fleet,
            self.hosts,
            self.status_topics,
            self.pose,
            np.zeros((n, 2)),
            self.records,
            stuck_timeout_s=cfg.stuck_timeout_s,
            goal_tolerance_m=cfg.goal_tolerance_m,
        )
        self.cmd_topics = [topic(n, "cmd_vel") for n in self.names]
        self.plan_topics = [topic(n, "plan") for n in self.names]
        bus = run.bus
        for status, cmd, path in zip(
            self.status_topics, self.cmd_topics, self.plan_topics, strict=True
        ):
            bus.advertise(status, NavStatus)
            bus.advertise(cmd, Twist)
            bus.advertise(path, Path)
        if self.robots_layer is not None:
            self.robots_layer.advertise(run)
        # plans keep out of gaps the controller will not enter (robots building their own
        # maps plan on them as they come, unpadded)
        padding = float(getattr(self.control, "footprint_padding_m", 0.0))
        plan_static = padded(self.static, padding)
        plan_layers = self.layers if self.mapping else StaticLayers.shared(plan_static, n)
        planner = planner_registry().get(cfg.planner)(PlannerContext(run, self.static))
        self.planning = GlobalPlanning(
            planner=planner,
            static=self.static,
            layers=self.layers,
            plan_layers=plan_layers,
            padding_m=padding,
            lanes=self.lanes,
            memory=self.memory,
            moving=self.moving,
            robots_layer=self.robots_layer,
            paths=self.paths,
            pose=self.pose,
            goal=self.goals.goal,
            radius_m=radius,
            inflation_m=cfg.inflation_radius_m,
            replan_hz=cfg.replan_hz,
            mapping=self.mapping,
            records=self.records,
            hosts=self.hosts,
            plan_topics=self.plan_topics,
        )
        self.goals.drivers = Drivers(
            self.static,
            self.planning,
            self.paths,
            None if self.manager is None else self.manager.places,
            self.recovery,
            self.stalls,
            self.mapping,
        )

    # -- the bus ----------------------------------------------------------------------
    def start(self, run: RunContext) -> None:
        """Subscribe to goals, odometry and scans; start control, status and robots layer."""
        bus = run.bus
        for i, (name, host) in enumerate(zip(self.names, self.hosts, strict=True)):
            bus.subscribe(topic(name, "nav/goal"), host, self._on_goal(run, i))
            bus.subscribe(topic(name, "scan"), host, self._on_scan(i))
            if self.mapping:
                bus.subscribe(topic(name, "map"), host, self._on_map(i))
        self.localization.subscribe(run, self.hosts)
        kernel = run.kernel
        kernel.every(self.period_ns, lambda now: self._control(run, now), stage=Stage.CONTROL)
        kernel.every(
            period_ns(self.cfg.progress_hz),
            lambda now: self._progress(run, now),
            stage=Stage.CONTROL,
        )
        if self.robots_layer is not None:
            self.robots_layer.start(run, self.cfg.robots_layer_hz, self.pose, self.vel[:, 0])

    def _on_map(self, i: int) -> Callable[[Message, Envelope], None]:
        def on_map(message: Message, _envelope: Envelope) -> None:
            assert isinstance(message, GridMessage)
            self.layers.update(i, message)

        return on_map

    def _on_scan(self, i: int) -> Callable[[Message, Envelope], None]:
        def on_scan(message: Message, _envelope: Envelope) -> None:
            assert isinstance(message, LaserScan)
            self.memory.add(i, self.pose[i].copy(), message.ranges_m)

        return on_scan

    # -- goals and plans ------------------------------------------------------------------
    def _on_goal(self, run: RunContext, i: int) -> Callable[[Message, Envelope], None]:
        def on_goal(message: Message, _envelope: Envelope) -> None:
            assert isinstance(message, NavGoal)
            self.goals.accept(run, i, message)

        return on_goal

    # -- the control tick -------------------------------------------------------------------
    def _control(self, run: RunContext, now_ns: int) -> None:
        # arrivals first: an arrival may hand the robot its next goal at once (the goal
        # sender answers the status synchronously), which the rest of the tick then follows
        self.goals.arrivals(run, now_ns)
        points, start = self.memory.near(self.near_m)
        layers = self.layers
        moving = moving_points(
            points,
            start,
            self.pose,
            layers.distance,
            layers.origin_xy_m,
            layers.resolution_m,
            self.traffic,
        )
        self.moving.remember(now_ns, moving.owner, moving.points)
        # a robot without a recent pose does not know where it is, nor one whose pose is off
        # the map (a measured pose can be anything): it stops
        lost = self.measured.check(now_ns) | self._off_map(run, now_ns)
        if self.manager is not None:
            self._control_places(run, now_ns, self.manager, points, start, moving, lost)
            return
        active, goal = self.goals.active, self.goals.goal
        self.planning.replan_due(run, now_ns, active, moving)
        carrots, remaining = self.paths.follow(
            self.pose[:, 0], self.pose[:, 1], self.cfg.lookahead_m
        )
        carrots = keep_right(carrots, moving, self.pose, active, self.traffic)
        v, w, blocked = self._local_control(carrots, goal, points, start, moving, now_ns)
        moving_ok = active & ~lost
        v = np.where(moving_ok, v, 0.0)
        w_cmd = np.where(moving_ok, w, 0.0)
        self.goals.track(run, now_ns, remaining)
        # halted: the controller found nothing admissible ahead, or chose to stand still
        # (a robot in the way) while its goal is elsewhere
        halted = blocked | ((np.abs(v) < HALT_MPS) & (np.abs(w) < HALT_RADPS))
        # ...or has hardly moved for a while whatever it commanded (dithering nose to nose)
        halted |= self.stalls.update(now_ns, self.pose, active)
        self.recovery.apply(
            now_ns,
            halted,
            moving_ok,
            v,
            w_cmd,
            lambda i: self.planning.plan(run, i, now_ns, replan=True),
            lambda i, kind: self.records.row(
                now_ns, i, "recovery", goal[i, 0], goal[i, 1], detail=kind
            ),
        )
        self._publish(run, v, w_cmd)

    def _off_map(self, run: RunContext, now_ns: int) -> BoolArray:
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
            if not off[i] and self.goals.active[i] and self.manager is None:
                self.planning.plan(run, i, now_ns, replan=True)
        self.off = off
        return off

    def _control_places(
        self,
        run: RunContext,
        now_ns: int,
        manager: FleetTraffic,
        points: np.ndarray,
        start: np.ndarray,
        moving: MovingPoints,
        lost: np.ndarray,
    ) -> None:
        """The control tick with the fleet's places: every robot drives.

        To its next place or to make way; no recovery moves (robots wait for their places).
        """
        goals = self.goals
        aims, remaining = manager.step(self.pose, goals.active, goals.progress_ns, now_ns)
        places = manager.places
        # the local controller only for robots settling onto a place from off it
        settle = None
        if places.settling.any():
            settle = self._local_control(aims, aims, points, start, moving, now_ns)
        free = free_ahead(points, start, self.pose, places.radius_m)
        v, w = places.commands(self.pose, aims, settle, free, self.limits)
        goals.track(run, now_ns, remaining)
        goals.remaining = remaining
        self._publish(run, np.where(lost, 0.0, v), np.where(lost, 0.0, w))

    def _local_control(
        self,
        carrots: np.ndarray,
        goals: np.ndarray,
        points: np.ndarray,
        start: np.ndarray,
        moving: MovingPoints,
        now_ns: int,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The local controller's commands, speeds capped near moving things."""
        if self.robots_layer is None:
            discs, disc_start = np.zeros((0, 3)), np.zeros(len(self.names) + 1, dtype=np.int64)
        else:
            discs, disc_start = self.robots_layer.all_discs(now_ns)
        inputs = ControlInputs(
            self.pose, self.vel, carrots, goals, points, start, moving, discs, disc_start, now_ns
        )
        v, w, blocked = self.control.commands(inputs)
        caps = speed_caps(
            moving, len(self.names), self.radius, self.limits.max_speed_mps, self.traffic
        )
        return np.minimum(v, caps), w, blocked

    def _publish(self, run: RunContext, v: np.ndarray, w: np.ndarray) -> None:
        commands = [Twist(vi, wi) for vi, wi in zip(v.tolist(), w.tolist(), strict=True)]
        run.bus.publish_many(self.cmd_topics, commands, self.hosts)

    def _progress(self, run: RunContext, now_ns: int) -> None:
        if self.manager is None:
            _, remaining = self.paths.follow(self.pose[:, 0], self.pose[:, 1], self.cfg.lookahead_m)
        else:
            remaining = self.goals.remaining
        self.goals.report(run, remaining)

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        """Arrivals, time to goal, path-length ratio, deadlocks, replans, recoveries."""
        summary = self.records.summary(run.kernel.now_ns / NS_PER_S)
        active = int(self.goals.active.sum())
        summary["goals_active_at_end"] = active
        # accepted goals neither reached nor still being driven to: abandoned after `stuck`
        accepted = summary["goals"] - summary["goals_unreachable"]
        summary["goals_missed"] = accepted - summary["arrivals"] - active
        return summary


def _beam_angles(beams: int, fov_rad: float) -> np.ndarray:
    return ScanGeometry(beams, fov_rad, 0.0, 1.0).angles()
