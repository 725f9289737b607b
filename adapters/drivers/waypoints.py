"""Waypoint driving: every robot drives to random reachable points, one after another.

The robot's software (on its own host) keeps the latest odometry, and at the control
rate (CONTROL stage) a go-to-goal law computes every robot's command in one vectorized
call; each command is published on ``/<robot>/cmd_vel``. A new waypoint is drawn from
the robot's own random stream when the previous one is reached or after a timeout; it
is a free point in straight-line sight of the robot, so that a controller that avoids
nothing still does not drive into shelves.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

import numpy as np
import shapely
from shapely.geometry import LineString, box
from shapely.prepared import prep

from adapters.drivers.topics import waypoint_topic
from adapters.fleet.topics import cmd_vel_topic, odom_topic
from cosim.core.adapter import RunContext
from cosim.core.bus import Envelope
from cosim.core.hosts import HostId
from cosim.core.kernel import Stage
from cosim.core.messages import Goal, Message, Odometry, Twist
from cosim.core.summary import SummaryKey
from cosim.core.timebase import period_ns, s_to_ns
from cosim.scenario.sections import RobotsConfig
from models.drivers.goto import GoToGains, go_to_goal
from models.fleet.kinematics import FleetState
from models.world.warehouse import Warehouse

SIGHT_MARGIN_M = 0.15
"""Extra clearance around the straight path to a waypoint (m)."""
GOAL_TIMEOUT_S = 60.0
"""A waypoint not reached in this time is abandoned (s)."""
STALL_S = 3.0
"""A robot that has not moved ``STALL_M`` in this time (blocked) abandons its waypoint (s)."""
STALL_M = 0.1


class WaypointsAdapter:
    """Random line-of-sight waypoints and a go-to-goal controller for every robot."""

    name: ClassVar[str] = "waypoints"
    requires: ClassVar[tuple[str, ...]] = ("world", "fleet")
    summary_keys: ClassVar[Mapping[str, SummaryKey]] = {
        "waypoints_reached": SummaryKey("count", "random waypoints the robots reached"),
        "waypoints_abandoned": SummaryKey(
            "count", "waypoints given up (not reached in time, or the robot stalled)"
        ),
    }
    """The summary keys :meth:`finish` writes (documented in the summary reference)."""

    def __init__(self, run: RunContext) -> None:
        self.world = run.service(Warehouse)
        fleet = run.service(FleetState)
        self.names = list(fleet.names)
        count = len(self.names)
        self.radius_m = run.settings(RobotsConfig).radius_m
        self.max_speed_mps = run.settings(RobotsConfig).max_speed_mps
        self.gains = GoToGains()
        self.period_ns = period_ns(run.settings(RobotsConfig).control_hz)
        self.rngs = [run.rng.stream(f"waypoints/{name}") for name in self.names]
        self.hosts = [HostId(name) for name in self.names]
        self.pose = fleet.positions.copy()
        self.yaw = fleet.yaw.copy()
        self.goal = np.full((count, 2), np.nan)
        self.goal_deadline_ns = np.zeros(count, dtype=np.int64)
        self.progress_xy = self.pose.copy()
        self.progress_ns = np.zeros(count, dtype=np.int64)
        obstacles = (
            shapely.union_all([box(*b) for b in self.world.shelves])
            if len(self.world.shelves)
            else shapely.Point(-1e9, -1e9)
        )
        self._obstacles = prep(obstacles)
        self.reached = 0
        self.abandoned = 0
        for name in self.names:
            run.bus.advertise(cmd_vel_topic(name), Twist)
            run.bus.advertise(waypoint_topic(name), Goal)

    def start(self, run: RunContext) -> None:
        """Subscribe to odometry, issue first waypoints, start the control tick."""
        for index, (name, host) in enumerate(zip(self.names, self.hosts, strict=True)):
            run.bus.subscribe(odom_topic(name), host, self._on_odom(index))
        self._cmd_topics = [cmd_vel_topic(name) for name in self.names]
        self._goal_topics = [waypoint_topic(name) for name in self.names]
        for index in range(len(self.names)):
            self._new_goal(run, index)
        run.kernel.every(self.period_ns, lambda now: self._control(run, now), stage=Stage.CONTROL)

    def _on_odom(self, index: int) -> Any:
        def on_odom(message: Message, _envelope: Envelope) -> None:
            assert isinstance(message, Odometry)
            self.pose[index] = (message.x_m, message.y_m)
            self.yaw[index] = message.yaw_rad

        return on_odom

    def _in_sight(self, start: np.ndarray, end: np.ndarray) -> bool:
        path = LineString([tuple(start), tuple(end)]).buffer(self.radius_m + SIGHT_MARGIN_M)
        return not self._obstacles.intersects(path)

    def _new_goal(self, run: RunContext, index: int) -> None:
        rng = self.rngs[index]
        start = self.pose[index]
        clearance = self.radius_m + SIGHT_MARGIN_M
        for _ in range(200):
            candidate = rng.uniform((0.0, 0.0), self.world.size_m)
            if not self.world.is_free(candidate[None, :], clearance)[0]:
                continue
            if np.hypot(*(candidate - start)) < 1.0 or not self._in_sight(start, candidate):
                continue
            break
        else:  # boxed in: stay put until the next attempt
            candidate = start.copy()
        self.goal[index] = candidate
        now = run.kernel.now_ns
        self.goal_deadline_ns[index] = now + s_to_ns(GOAL_TIMEOUT_S)
        run.bus.publish(
            self._goal_topics[index],
            Goal(now, float(candidate[0]), float(candidate[1])),
            self.hosts[index],
        )
        run.recorder.event(
            now, self.names[index], "goal", f"x_m={candidate[0]:.3f} y_m={candidate[1]:.3f}"
        )

    def _control(self, run: RunContext, now_ns: int) -> None:
        v, w, arrived = go_to_goal(
            self.pose[:, 0],
            self.pose[:, 1],
            self.yaw,
            self.goal[:, 0],
            self.goal[:, 1],
            self.max_speed_mps,
            self.gains,
        )
        moved = np.hypot(*(self.pose - self.progress_xy).T) > STALL_M
        self.progress_xy[moved] = self.pose[moved]
        self.progress_ns[moved] = now_ns
        stalled = now_ns - self.progress_ns >= s_to_ns(STALL_S)
        expired = now_ns >= self.goal_deadline_ns
        for due in np.flatnonzero(arrived | expired | stalled):
            index = int(due)
            if arrived[index]:
                self.reached += 1
                run.recorder.event(now_ns, self.names[index], "arrived", "")
            else:
                self.abandoned += 1
                why = "blocked" if stalled[index] else "goal timeout"
                run.recorder.event(now_ns, self.names[index], "abandoned", why)
            self.progress_xy[index] = self.pose[index]
            self.progress_ns[index] = now_ns
            self._new_goal(run, index)
        publish = run.bus.publish
        for index, host in enumerate(self.hosts):
            publish(self._cmd_topics[index], Twist(float(v[index]), float(w[index])), host)

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        """Waypoints reached and abandoned."""
        return {"waypoints_reached": self.reached, "waypoints_abandoned": self.abandoned}
