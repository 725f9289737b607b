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

The adapter runs the ticks; its parts are built in :mod:`adapters.navigation.parts`, its
topics wired in :mod:`adapters.navigation.wiring`.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from typing import Any, ClassVar

import numpy as np

from adapters.navigation.commands import checked_commands
from adapters.navigation.contract import (
    ControlInputs,
    controller_registry,
    planner_registry,
    traffic_registry,
)
from adapters.navigation.fleet_traffic import FleetTraffic
from adapters.navigation.memory import check_navigation_memory
from adapters.navigation.motion_quality import MOTION_SUMMARY, MotionQuality
from adapters.navigation.parts import build_parts
from adapters.navigation.settings import NavigationConfig
from adapters.navigation.tables import NAV_SUMMARY, NAVIGATION
from cosim.core.adapter import RunContext
from cosim.core.kernel import Stage
from cosim.core.summary import SummaryKey
from cosim.core.table import TableSpec
from cosim.core.timebase import NS_PER_S, period_ns
from cosim.scenario.model import Scenario
from models.navigation.place_drive import free_ahead
from models.navigation.traffic import MovingPoints, keep_right, moving_points, speed_caps

HALT_MPS = 0.02
"""Commanded speed below which a robot with a goal counts as halted (m/s)..."""
HALT_RADPS = 0.05
"""...when it does not turn faster than this either (rad/s)."""


class NavigationAdapter:
    """Global planning, local control, recovery and status reports for every robot.

    Its parts (:class:`~adapters.navigation.parts.NavigationParts`) are built once, in the
    run's order, by :func:`~adapters.navigation.parts.build_parts`.
    """

    name: ClassVar[str] = "navigation"
    requires: ClassVar[tuple[str, ...]] = ("world", "fleet", "lidar")
    tables: ClassVar[tuple[TableSpec, ...]] = (NAVIGATION,)
    """The tables it writes (documented in the table reference)."""
    summary_keys: ClassVar[Mapping[str, SummaryKey]] = {
        **NAV_SUMMARY,
        **MOTION_SUMMARY,
        "goals_active_at_end": SummaryKey("count", "goals still being driven to at the end"),
        "controller_commands_clipped": SummaryKey(
            "count", "local controller commands clipped to the robots' drive limits"
        ),
        "goals_missed": SummaryKey(
            "count",
            "goals taken on that were neither reached, nor unreachable, nor still being "
            "driven to at the end (abandoned after a stuck report)",
        ),
    }
    """The summary keys :meth:`finish` writes (documented in the summary reference)."""

    @staticmethod
    def check_scenario(scenario: Scenario) -> None:
        """Names known, what the chosen traffic policy refuses, and costmaps that fit in memory.

        A policy may declare ``check_scenario(scenario)``: the fleet manager refuses robots
        that cannot localize well enough for its places. A ``resolution_m`` whose costmaps
        would not fit in memory is refused (:mod:`adapters.navigation.memory`).
        """
        cfg = scenario.section(NavigationConfig)
        controller_registry().get(cfg.controller)
        planner_registry().get(cfg.planner)
        check = getattr(traffic_registry().get(cfg.traffic), "check_scenario", None)
        if check is not None:
            check(scenario)
        check_navigation_memory(scenario)

    def __init__(self, run: RunContext) -> None:
        self.cfg = run.settings(NavigationConfig)
        self.parts = build_parts(run)
        self.pose = self.parts.pose
        self.clipped = 0
        """Robot commands of the local controller clipped to the drive limits, so far."""
        self.quality = MotionQuality(len(self.parts.names), self.cfg.control_hz)
        self.workers = run.workers

    # -- the bus ----------------------------------------------------------------------
    def start(self, run: RunContext) -> None:
        """Subscribe to goals, odometry and scans; start control, status and robots layer."""
        parts = self.parts
        parts.interface.subscribe(
            run, parts.goals, parts.memory, self.pose, parts.layers, mapping=parts.mapping
        )
        parts.localization.subscribe(run, parts.hosts)
        kernel = run.kernel
        kernel.every(
            period_ns(self.cfg.control_hz),
            lambda now: self._control(run, now),
            stage=Stage.CONTROL,
        )
        kernel.every(
            period_ns(self.cfg.progress_hz),
            lambda now: self._progress(run, now),
            stage=Stage.CONTROL,
        )
        if parts.robots_layer is not None:
            vel = parts.localization.vel
            parts.robots_layer.start(run, self.cfg.robots_layer_hz, self.pose, vel[:, 0])

    # -- the control tick -------------------------------------------------------------------
    def _control(self, run: RunContext, now_ns: int) -> None:
        parts = self.parts
        # arrivals first: an arrival may hand the robot its next goal at once (the goal
        # sender answers the status synchronously), which the rest of the tick then follows
        parts.goals.arrivals(run, now_ns)
        points, start = parts.memory.near(parts.near_m)
        layers = parts.layers
        moving = moving_points(
            points,
            start,
            self.pose,
            layers.distance,
            layers.origin_xy_m,
            layers.resolution_m,
            parts.traffic,
        )
        parts.moving.remember(now_ns, moving.owner, moving.points)
        # a robot without a recent pose does not know where it is, nor one whose pose is off
        # the map (a measured pose can be anything): it stops
        lost = parts.localization.measured.check(now_ns) | parts.off_map.check(run, now_ns)
        if parts.manager is not None:
            self._control_places(run, now_ns, parts.manager, points, start, moving, lost)
            return
        active, goal = parts.goals.active, parts.goals.goal
        parts.planning.replan_due(run, now_ns, active, moving)
        carrots, remaining = parts.paths.follow(
            self.pose[:, 0], self.pose[:, 1], self.cfg.lookahead_m
        )
        carrots = keep_right(carrots, moving, self.pose, active, parts.traffic)
        v, w, blocked = self._local_control(carrots, goal, points, start, moving, now_ns)
        moving_ok = active & ~lost
        fleet = parts.goals.fleet
        self.quality.sample(fleet.v, fleet.w, moving_ok)
        v = np.where(moving_ok, v, 0.0)
        w_cmd = np.where(moving_ok, w, 0.0)
        parts.goals.track(run, now_ns, remaining)
        # halted: the controller found nothing admissible ahead, or chose to stand still
        # (a robot in the way) while its goal is elsewhere
        halted = blocked | ((np.abs(v) < HALT_MPS) & (np.abs(w) < HALT_RADPS))
        # ...or has hardly moved for a while whatever it commanded (dithering nose to nose)
        halted |= parts.stalls.update(now_ns, self.pose, active)
        parts.recovery.apply(
            now_ns,
            halted,
            moving_ok,
            v,
            w_cmd,
            lambda i: parts.planning.plan(run, i, now_ns, replan=True),
            lambda i, kind: parts.records.row(
                now_ns, i, "recovery", goal[i, 0], goal[i, 1], detail=kind
            ),
        )
        parts.interface.publish_commands(run, v, w_cmd)

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
        goals = self.parts.goals
        aims, remaining = manager.step(self.pose, goals.active, goals.progress_ns, now_ns)
        places = manager.places
        # the local controller only for robots settling onto a place from off it
        settle = None
        if places.settling.any():
            settle = self._local_control(aims, aims, points, start, moving, now_ns)
        free = free_ahead(points, start, self.pose, places.radius_m)
        v, w = places.commands(self.pose, aims, settle, free, self.parts.limits)
        goals.track(run, now_ns, remaining)
        goals.remaining = remaining
        self.parts.interface.publish_commands(run, np.where(lost, 0.0, v), np.where(lost, 0.0, w))

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
        parts = self.parts
        n = len(parts.names)
        if parts.robots_layer is None:
            discs, neighbours = np.zeros((0, 3)), np.zeros((0, 5))
            disc_start = np.zeros(n + 1, dtype=np.int64)
        else:
            discs, neighbours, disc_start = parts.robots_layer.all_neighbours(now_ns)
        vel = parts.localization.vel
        inputs = ControlInputs(
            self.pose,
            vel,
            carrots,
            goals,
            points,
            start,
            moving,
            discs,
            disc_start,
            now_ns,
            self.workers.chunks,
            neighbours,
        )
        started = time.perf_counter()
        returned = parts.control.commands(inputs)
        self.quality.decided(time.perf_counter() - started)
        v, w, blocked, clipped = checked_commands(
            parts.control, returned, parts.names, parts.limits
        )
        self.clipped += clipped
        caps = speed_caps(moving, n, parts.radius_m, parts.limits.max_speed_mps, parts.traffic)
        return np.minimum(v, caps), w, blocked

    def _progress(self, run: RunContext, now_ns: int) -> None:
        parts = self.parts
        if parts.manager is None:
            _, remaining = parts.paths.follow(
                self.pose[:, 0], self.pose[:, 1], self.cfg.lookahead_m
            )
        else:
            remaining = parts.goals.remaining
        parts.goals.report(run, remaining)

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        """Arrivals, time to goal, path-length ratio, deadlocks, replans, recoveries, clips."""
        self.parts.goals.close(run.kernel.now_ns)
        summary = self.parts.records.summary(run.kernel.now_ns / NS_PER_S)
        active = int(self.parts.goals.active.sum())
        summary["goals_active_at_end"] = active
        summary["controller_commands_clipped"] = self.clipped
        summary.update(self.quality.summary())
        # accepted goals neither reached nor still being driven to: abandoned after `stuck`
        accepted = summary["goals"] - summary["goals_unreachable"]
        summary["goals_missed"] = accepted - summary["arrivals"] - active
        return summary
