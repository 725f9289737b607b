"""The navigation adapter: the Nav2 role on every robot.

Interface (per robot, on the robot's host): a :class:`~cosim.messages.NavGoal` on
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
import time
from collections.abc import Callable, Mapping
from typing import Any, ClassVar

import numpy as np

from adapters.fleet.motion import drive_limits
from adapters.mapping.geometry import map_geometry, unknown_grid
from adapters.mocap.tracking import tracked_robots
from adapters.naming import robot_name, topic
from adapters.navigation.fleet_traffic import FleetTraffic, check_localization
from adapters.navigation.layers import StaticLayer, StaticLayers, lanes_on
from adapters.navigation.localization import MeasuredPoses
from adapters.navigation.planning import GlobalPlanning
from adapters.navigation.records import NavRecords
from adapters.navigation.recovery import Recovery, StallWatch, stuck_kind
from adapters.navigation.robots_layer import RobotsLayer
from adapters.navigation.scan_memory import MovingMemory, ScanMemory
from cosim.adapter import RunContext
from cosim.bus import Envelope
from cosim.errors import ConfigError
from cosim.hosts import HostId
from cosim.kernel import Stage
from cosim.messages import (
    LaserScan,
    Message,
    NavGoal,
    NavStatus,
    Odometry,
    Path,
    TFMessage,
    Twist,
)
from cosim.messages import OccupancyGrid as GridMessage
from cosim.scenario.model import Scenario
from cosim.timebase import NS_PER_S, period_ns, s_to_ns
from models.kinematics import FleetState
from models.lidar import ScanGeometry
from models.mapping.se2 import compose
from models.navigation.costmap import CostmapParams, StaticCostmap
from models.navigation.dwa import DwaParams, dwa_batch
from models.navigation.follow import PathBook
from models.navigation.place_drive import free_ahead
from models.navigation.planner import (
    GoalStatus,
    goal_status,
)
from models.navigation.traffic import (
    MovingPoints,
    TrafficParams,
    keep_right,
    moving_points,
    speed_caps,
)
from models.occupancy import ground_truth_grid
from models.world import Warehouse

PROGRESS_M = 0.2
"""Remaining path length must shrink by this much to count as progress (m)."""
HALT_MPS = 0.02
"""Commanded speed below which a robot with a goal counts as halted (m/s)..."""
LANE_WIDTH_M = 2.5
"""``traffic = "lanes"`` and ``"pibt"``: aisles up to this wide are one-way (m); two robots
pass in wider."""
HALT_RADPS = 0.05
"""...when it does not turn faster than this either (rad/s)."""


class NavigationAdapter:
    """Global planning, local control, recovery and status reports for every robot."""

    name: ClassVar[str] = "navigation"
    requires: ClassVar[tuple[str, ...]] = ("world", "fleet", "lidar")

    @staticmethod
    def check_scenario(scenario: Scenario) -> None:
        """Refuse the fleet manager for robots that cannot localize well enough for it.

        See :func:`~adapters.navigation.fleet_traffic.check_localization`.
        """
        names = [robot_name(i) for i in range(scenario.robots.count)]
        tracked = np.isin(names, tracked_robots(scenario, names))
        check_localization(scenario, tracked)

    def __init__(self, run: RunContext) -> None:
        cfg = run.scenario.navigation
        if run.scenario.lidar.beams == 0:
            raise ConfigError(
                f"{run.scenario.source}: [robots] driver = 'navigation': expected lidar.beams "
                "> 0 (the local controller avoids what the lidar sees)"
            )
        self.cfg = cfg
        self.fleet = run.service(FleetState)
        self.names = list(self.fleet.names)
        self.hosts = [HostId(n) for n in self.names]
        n = len(self.names)
        radius = run.scenario.robots.radius_m
        if not run.has_service(StaticLayer):
            run.provide(StaticLayer(ground_truth_grid(run.service(Warehouse), cfg.resolution_m)))
        self.params = CostmapParams(radius, cfg.inflation_radius_m, cfg.cost_scaling)
        self.static = StaticCostmap.from_grid(run.service(StaticLayer).grid, self.params)
        self.mapping = run.scenario.mapping.enabled
        if self.mapping:
            area = map_geometry(run.service(Warehouse), run.scenario.mapping.resolution_m)
            self.layers = StaticLayers.unexplored(
                unknown_grid(area), len(self.names), self.params, cfg.resolution_m
            )
        else:
            self.layers = StaticLayers.shared(self.static, len(self.names))
        self.lanes: np.ndarray | None = None
        if cfg.traffic == "lanes":
            # drawn on the building's map by the fleet manager, as Open-RMF's lanes are
            self.lanes = lanes_on(
                self.layers[0],
                ground_truth_grid(run.service(Warehouse), cfg.resolution_m),
                LANE_WIDTH_M,
            )
        self.places: FleetTraffic | None = None
        if cfg.traffic == "pibt":  # the fleet manager moves every robot place by place
            truth = ground_truth_grid(run.service(Warehouse), cfg.resolution_m)
            self.places = FleetTraffic(
                self.static,
                lanes_on(self.static, truth, LANE_WIDTH_M),
                np.stack([self.fleet.x, self.fleet.y], axis=1),
                radius,
            )
        run.provide(self.static)
        self.measured = MeasuredPoses(run, self.names)
        """Robots localizing by motion capture (or their own reported pose)."""
        self.correction = [(0.0, 0.0, 0.0)] * len(self.names)
        """Per robot ``map -> odom`` from its mapping (identity without mapping)."""
        self.limits = drive_limits(run)
        self.dwa = DwaParams(control_period_s=1.0 / cfg.control_hz)
        self.period_ns = period_ns(cfg.control_hz)
        lidar = run.scenario.lidar
        angles = _beam_angles(lidar.beams, math.radians(lidar.fov_deg))
        self.memory = ScanMemory(n, angles, lidar.range_max_m)
        self.moving = MovingMemory(s_to_ns(cfg.obstacle_memory_s), self.layers.resolution_m)
        self.near_m = self.limits.max_speed_mps * self.dwa.sim_time_s + radius + 1.0
        self.paths = PathBook(n)
        self.pose = np.stack([self.fleet.x, self.fleet.y, self.fleet.yaw], axis=1)
        self.vel = np.zeros((n, 2))
        self.active = np.zeros(n, dtype=bool)
        self.goal = np.zeros((n, 2))
        self.goal_id = np.zeros(n, dtype=np.int64)
        self.best_remaining = np.full(n, np.inf)
        self.progress_ns = np.zeros(n, dtype=np.int64)
        self.progress_driven_m = np.zeros(n)  # distance driven at the last progress
        self.stuck = np.zeros(n, dtype=bool)
        self.remaining = np.zeros(n)  # way left to each goal at the last control tick (m)
        self.yardstick_from = np.zeros((n, 2))  # true position where each goal started
        self.robots_layer: RobotsLayer | None = None
        if cfg.robots_layer:
            self.robots_layer = RobotsLayer(
                self.names, self.hosts, radius, cfg.robots_layer_timeout_s
            )
        self.records = NavRecords(run.recorder, self.names)
        self.radius = radius
        self.rngs = [run.rng.stream(f"navigation/{name}") for name in self.names]
        self.traffic = TrafficParams()
        self.recovery = Recovery(n, self.memory, self.limits, radius, self.rngs)
        self.stalls = StallWatch(self.pose)
        self.status_topics = [topic(n, "nav/status") for n in self.names]
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
        self.planning = GlobalPlanning(
            static=self.static,
            layers=self.layers,
            lanes=self.lanes,
            memory=self.memory,
            moving=self.moving,
            robots_layer=self.robots_layer,
            paths=self.paths,
            pose=self.pose,
            goal=self.goal,
            radius_m=radius,
            inflation_m=cfg.inflation_radius_m,
            replan_hz=cfg.replan_hz,
            mapping=self.mapping,
            records=self.records,
            hosts=self.hosts,
            plan_topics=self.plan_topics,
        )

    # -- the bus ----------------------------------------------------------------------
    def start(self, run: RunContext) -> None:
        """Subscribe to goals, odometry and scans; start control, status and robots layer."""
        bus = run.bus
        for i, (name, host) in enumerate(zip(self.names, self.hosts, strict=True)):
            bus.subscribe(topic(name, "nav/goal"), host, self._on_goal(run, i))
            bus.subscribe(topic(name, "odom"), host, self._on_odom(i))
            bus.subscribe(topic(name, "scan"), host, self._on_scan(i))
            if self.mapping:
                bus.subscribe(topic(name, "tf"), host, self._on_correction(i))
                bus.subscribe(topic(name, "map"), host, self._on_map(i))
        self.measured.subscribe(run, self.hosts, self._on_measured_pose)
        kernel = run.kernel
        kernel.every(self.period_ns, lambda now: self._control(run, now), stage=Stage.CONTROL)
        kernel.every(
            period_ns(self.cfg.progress_hz),
            lambda now: self._progress(run, now),
            stage=Stage.CONTROL,
        )
        if self.robots_layer is not None:
            self.robots_layer.start(run, self.cfg.robots_layer_hz, self.pose, self.vel[:, 0])

    def _on_measured_pose(self, i: int, x_m: float, y_m: float, yaw_rad: float) -> None:
        self.pose[i] = (x_m, y_m, yaw_rad)

    def _on_odom(self, i: int) -> Callable[[Message, Envelope], None]:
        tracked = self.measured.tracked

        def on_odom(message: Message, _envelope: Envelope) -> None:
            assert isinstance(message, Odometry)
            self.vel[i] = (message.v_mps, message.w_radps)
            if tracked[i]:
                return  # localized by measured poses
            odom = (message.x_m, message.y_m, message.yaw_rad)
            # localized: the mapping's map -> odom correction applied to odometry
            self.pose[i] = compose(self.correction[i], odom) if self.mapping else odom

        return on_odom

    def _on_correction(self, i: int) -> Callable[[Message, Envelope], None]:
        def on_tf(message: Message, _envelope: Envelope) -> None:
            assert isinstance(message, TFMessage)
            for t in message.transforms:
                if t.parent == "map":
                    self.correction[i] = (t.x_m, t.y_m, t.yaw_rad)

        return on_tf

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

    def _status(self, run: RunContext, i: int, state: str, remaining: float) -> None:
        x, y, _ = self.pose[i]
        message = NavStatus(
            run.kernel.now_ns, int(self.goal_id[i]), state, float(x), float(y), float(remaining)
        )
        run.bus.publish(self.status_topics[i], message, self.hosts[i])

    # -- goals and plans ------------------------------------------------------------------
    def _on_goal(self, run: RunContext, i: int) -> Callable[[Message, Envelope], None]:
        def on_goal(message: Message, _envelope: Envelope) -> None:
            assert isinstance(message, NavGoal)
            self._accept(run, i, message)

        return on_goal

    def _accept(self, run: RunContext, i: int, goal: NavGoal) -> None:
        now = run.kernel.now_ns
        if not (math.isfinite(goal.x_m) and math.isfinite(goal.y_m)):
            # a goal without a position cancels the current one: the robot stops
            was_active = bool(self.active[i])
            self.goal_id[i] = goal.goal_id
            self.active[i] = False
            self.paths.clear(i)
            if was_active:
                self.records.row(now, i, "cancelled", self.goal[i, 0], self.goal[i, 1])
            if self.places is not None:
                self.places.end_goal(i)
            self._status(run, i, "cancelled", math.nan)
            return
        self.goal_id[i] = goal.goal_id
        self.goal[i] = (goal.x_m, goal.y_m)
        self.records.row(now, i, "goal", goal.x_m, goal.y_m)
        where = goal_status(self.static, (goal.x_m, goal.y_m))
        truth = np.array([self.fleet.x[i], self.fleet.y[i]])
        self.yardstick_from[i] = truth
        if where is not GoalStatus.OK:
            self._drop(run, i, "unreachable", where.value)
            return
        # path_length_ratio's yardstick (shortest way on the true map from the true position)
        # counts only on arrival. With the fleet's places, a goal reached from a place of
        # the robot's own component is reachable: its yardstick waits for the arrival
        # (1,000 robots: 1.4 s of searches at t = 0), and the way accepted is the way along
        # the places.
        places = self.places
        if places is not None:
            place = places.goal_place(i, self.goal[i])
            if place < 0:
                enclosed = not math.isfinite(self._yardstick(i))
                why = "enclosed" if enclosed else "off the fleet's places"
                self._drop(run, i, "unreachable", why)
                return
            places.set_goal(i, self.goal[i], place, now)
            self._begin(run, i, now, math.nan, places.way_left(i, self.pose[i, :2]))
            return
        # A robot planning on the static layer from exactly its true position finds a route
        # there (its first plan's "cleared" try) if and only if the yardstick exists, so it
        # measures it on arrival (1,000 robots: half the searches at t = 0 were yardsticks
        # of goals not reached in the run); others need it now.
        deferred = not self.mapping and np.array_equal(self.pose[i, :2], truth)
        shortest = math.nan if deferred else self._yardstick(i)
        if not deferred and not math.isfinite(shortest):
            self._drop(run, i, "unreachable", "enclosed")
            return
        started = time.perf_counter()
        found = self.planning.route(i, now, replan=False)
        route = found[0]
        if deferred and route is None:
            shortest = self._yardstick(i)
            if not math.isfinite(shortest):
                self._drop(run, i, "unreachable", "enclosed")
                return
        self._begin(run, i, now, shortest, shortest if route is None or not deferred else route[1])
        self.planning.finish(run, i, now, found, started, replan=False)

    def _begin(self, run: RunContext, i: int, now: int, shortest: float, way: float) -> None:
        """Robot ``i`` drives to its goal from now; ``way`` (m) goes out as accepted."""
        self.active[i] = True
        self.stuck[i] = False
        self.best_remaining[i] = math.inf
        self.progress_ns[i] = now
        self.progress_driven_m[i] = self.fleet.distance_m[i]
        self.recovery.reset(i)
        self.stalls.reset(i, self.pose[i], now)
        self.records.start_goal(i, now, float(self.fleet.distance_m[i]), shortest)
        self._status(run, i, "accepted", way)

    def _yardstick(self, i: int) -> float:
        """Robot ``i``'s shortest way (m) on the true map from where its goal started."""
        return self.planning.yardstick(self.yardstick_from[i], self.goal[i])

    def _drop(self, run: RunContext, i: int, state: str, detail: str = "") -> None:
        self.active[i] = False
        self.paths.clear(i)
        if self.places is not None:
            self.places.end_goal(i)
        self.records.row(
            run.kernel.now_ns, i, state, self.goal[i, 0], self.goal[i, 1], detail=detail
        )
        self._status(run, i, state, math.nan)

    # -- the control tick -------------------------------------------------------------------
    def _control(self, run: RunContext, now_ns: int) -> None:
        # arrivals first: an arrival may hand the robot its next goal at once (the goal
        # sender answers the status synchronously), which the rest of the tick then follows
        self._check_arrivals(run, now_ns)
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
        # a robot without a recent pose does not know where it is: it stops
        lost = self.measured.check(now_ns)
        if self.places is not None:
            self._control_places(run, now_ns, self.places, points, start, moving, lost)
            return
        self.planning.replan_due(run, now_ns, self.active, moving)
        carrots, remaining = self.paths.follow(
            self.pose[:, 0], self.pose[:, 1], self.cfg.lookahead_m
        )
        carrots = keep_right(carrots, moving, self.pose, self.active, self.traffic)
        v, w, blocked = self._local_control(carrots, self.goal, points, start, moving, now_ns)
        moving_ok = self.active & ~lost
        v = np.where(moving_ok, v, 0.0)
        w_cmd = np.where(moving_ok, w, 0.0)
        self._track_progress(run, now_ns, remaining)
        # halted: the controller found nothing admissible ahead, or chose to stand still
        # (a robot in the way) while its goal is elsewhere
        halted = blocked | ((np.abs(v) < HALT_MPS) & (np.abs(w) < HALT_RADPS))
        # ...or has hardly moved for a while whatever it commanded (dithering nose to nose)
        halted |= self.stalls.update(now_ns, self.pose, self.active)
        self.recovery.apply(
            now_ns,
            halted,
            moving_ok,
            v,
            w_cmd,
            lambda i: self.planning.plan(run, i, now_ns, replan=True),
            lambda i, kind: self.records.row(
                now_ns, i, "recovery", self.goal[i, 0], self.goal[i, 1], detail=kind
            ),
        )
        self._publish(run, v, w_cmd)

    def _control_places(
        self,
        run: RunContext,
        now_ns: int,
        places: FleetTraffic,
        points: np.ndarray,
        start: np.ndarray,
        moving: MovingPoints,
        lost: np.ndarray,
    ) -> None:
        """The control tick with the fleet's places: every robot drives.

        To its next place or to make way; no recovery moves (robots wait for their places).
        """
        aims, remaining = places.step(self.pose, self.active, self.progress_ns, now_ns)
        # the local controller only for robots settling onto a place from off it
        settle = None
        if places.settling.any():
            settle = self._local_control(aims, aims, points, start, moving, now_ns)
        free = free_ahead(points, start, self.pose, places.radius_m)
        v, w = places.commands(self.pose, aims, settle, free, self.limits)
        self._track_progress(run, now_ns, remaining)
        self.remaining = remaining
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
        """DWA commands for every robot: speeds (capped near moving things), yaw rates.

        Also which robots found nothing admissible ahead.
        """
        if self.robots_layer is None:
            discs, disc_start = np.zeros((0, 3)), np.zeros(len(self.names) + 1, dtype=np.int64)
        else:
            discs, disc_start = self.robots_layer.all_discs(now_ns)
        result = dwa_batch(
            self.pose,
            self.vel,
            self.limits,
            self.fleet.radius_m,
            carrots,
            goals,
            points,
            start,
            discs,
            disc_start,
            self.dwa,
        )
        caps = speed_caps(
            moving, len(self.names), self.radius, self.limits.max_speed_mps, self.traffic
        )
        return np.minimum(result.v, caps), result.w, result.blocked

    def _publish(self, run: RunContext, v: np.ndarray, w: np.ndarray) -> None:
        commands = [Twist(vi, wi) for vi, wi in zip(v.tolist(), w.tolist(), strict=True)]
        run.bus.publish_many(self.cmd_topics, commands, self.hosts)

    def _check_arrivals(self, run: RunContext, now_ns: int) -> None:
        gap = np.hypot(*(self.pose[:, :2] - self.goal).T)
        for i in np.flatnonzero(self.active & (gap <= self.cfg.goal_tolerance_m)).tolist():
            self.active[i] = False
            self.paths.clear(i)
            if math.isnan(self.records.shortest_m[i]):
                self.records.shortest_m[i] = self._yardstick(i)
            self.records.arrived(
                now_ns, i, self.goal[i, 0], self.goal[i, 1], float(self.fleet.distance_m[i])
            )
            if self.places is not None:
                self.places.end_goal(i)
            self._status(run, i, "arrived", 0.0)

    def _track_progress(self, run: RunContext, now_ns: int, remaining: np.ndarray) -> None:
        improved = self.active & (remaining < self.best_remaining - PROGRESS_M)
        self.best_remaining[improved] = remaining[improved]
        self.progress_ns[improved] = now_ns
        self.progress_driven_m[improved] = self.fleet.distance_m[improved]
        self.stuck[improved] = False
        timeout = s_to_ns(self.cfg.stuck_timeout_s)
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
                detail=f"no progress for {self.cfg.stuck_timeout_s:g} s: {kind} ({why})",
            )
            self.records.stuck(kind)
            self._status(run, i, "stuck", float(remaining[i]))

    def _progress(self, run: RunContext, now_ns: int) -> None:
        if self.places is None:
            _, remaining = self.paths.follow(self.pose[:, 0], self.pose[:, 1], self.cfg.lookahead_m)
        else:
            remaining = self.remaining
        for i in np.flatnonzero(self.active).tolist():
            self._status(run, i, "progress", float(remaining[i]))

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        """Arrivals, time to goal, path-length ratio, deadlocks, replans, recoveries."""
        summary = self.records.summary(run.kernel.now_ns / NS_PER_S)
        active = int(self.active.sum())
        summary["goals_active_at_end"] = active
        # accepted goals neither reached nor still being driven to: abandoned after `stuck`
        accepted = summary["goals"] - summary["goals_unreachable"]
        summary["goals_missed"] = accepted - summary["arrivals"] - active
        return summary


def _beam_angles(beams: int, fov_rad: float) -> np.ndarray:
    return ScanGeometry(beams, fov_rad, 0.0, 1.0).angles()
