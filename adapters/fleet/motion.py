"""The fleet adapter: ground-truth kinematics of every robot, odometry and cmd_vel.

Each robot is a host named after it. The adapter subscribes ``/<robot>/cmd_vel`` on the
robot's host and, at ``robots.control_hz`` in the PHYSICS stage, advances all robots in
one vectorized step and publishes ``/<robot>/odom``. Before a step is committed, motion
guards (the collision adapter) may hold robots back. The ``odom`` frame starts aligned
with ``map`` (each robot is told its start pose, as an initial pose is given to a
localizer); with ``odometry.drift`` > 0 it drifts away from ground truth. Odometry is
``robot_i/odom`` -> ``robot_i/base_link`` (REP 105 frames with the robot's prefix).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any, ClassVar

import numpy as np

from adapters.fleet.mirror import Mirrors
from adapters.fleet.topics import cmd_vel_topic, odom_topic
from adapters.naming import robot_name
from cosim.core.adapter import RunContext
from cosim.core.bus import Envelope
from cosim.core.hosts import HostKind
from cosim.core.kernel import Stage
from cosim.core.messages import Message, Odometry, Twist
from cosim.core.rng import BlockDraws
from cosim.core.summary import SummaryKey
from cosim.core.timebase import NS_PER_S, period_ns
from cosim.scenario.sections import OdometryConfig, RobotsConfig
from models.fleet.kinematics import DriveLimits, FleetState, Motion
from models.fleet.odometry import advance, drift_increments
from models.world.warehouse import Warehouse

MotionGuard = Callable[[int, Motion], None]
"""Called with (now in ns, proposed motion) before a step is committed; may hold robots."""


def drive_limits(run: RunContext) -> DriveLimits:
    """The scenario's drive limits."""
    robots = run.settings(RobotsConfig)
    return DriveLimits(
        max_speed_mps=robots.max_speed_mps,
        max_reverse_mps=robots.max_reverse_mps,
        max_yaw_rate_radps=robots.max_yaw_rate_radps,
        max_accel_mps2=robots.max_accel_mps2,
        max_yaw_accel_radps2=robots.max_yaw_accel_radps2,
    )


class FleetAdapter:
    """Integrates every robot's motion and publishes odometry."""

    name: ClassVar[str] = "fleet"
    requires: ClassVar[tuple[str, ...]] = ("world",)
    summary_keys: ClassVar[Mapping[str, SummaryKey]] = {
        "robots": SummaryKey("count", "robots in the fleet"),
        "distance_m": SummaryKey("m", "distance driven by all robots together"),
        "odometry_error_m_mean": SummaryKey(
            "m", "distance between a robot's odometry position and its true one at the end, mean"
        ),
    }
    """The summary keys :meth:`finish` writes (documented in the summary reference)."""

    def __init__(self, run: RunContext) -> None:
        world = run.service(Warehouse)
        robots = run.settings(RobotsConfig)
        names = [robot_name(i) for i in range(robots.count)]
        self.state = FleetState(names, world.starts, robots.radius_m)
        self.limits = drive_limits(run)
        self.hosts = [run.add_host(name, HostKind.ROBOT) for name in names]
        self.period_ns = period_ns(robots.control_hz)
        self.dt_s = self.period_ns / NS_PER_S
        self.guards: list[MotionGuard] = []
        self.drift = run.settings(OdometryConfig).drift
        self.odom = world.starts.astype(float).copy()
        self._noise = BlockDraws([run.rng.stream(f"odometry/{n}") for n in names], width=2)
        self._frames = [(f"{n}/odom", f"{n}/base_link") for n in names]
        self.mirrors = Mirrors(self.state)
        # the step and the odometry arc are compiled: load them now rather than in the first
        # tick, where a real-time run would fall behind the wall clock (proposals change
        # nothing, and neither does an arc whose result is dropped)
        self.state.propose(self.limits, self.dt_s)
        zeros = np.zeros(len(names))
        advance(self.odom[:, 0], self.odom[:, 1], self.odom[:, 2], zeros, zeros)
        run.provide(self.state)
        run.provide(self.mirrors)
        run.provide(self)
        for name in names:
            run.bus.advertise(odom_topic(name), Odometry)

    def add_guard(self, guard: MotionGuard) -> None:
        """Let ``guard`` inspect (and hold back) every proposed step before it is committed."""
        self.guards.append(guard)

    def start(self, run: RunContext) -> None:
        """Subscribe to every robot's cmd_vel and start the physics tick."""
        for index, (name, host) in enumerate(zip(self.state.names, self.hosts, strict=True)):
            run.bus.subscribe(cmd_vel_topic(name), host, self._on_cmd(index))
        self._odom_topics = [odom_topic(name) for name in self.state.names]
        run.kernel.every(self.period_ns, lambda now: self._tick(run, now), stage=Stage.PHYSICS)

    def _on_cmd(self, index: int) -> Callable[[Message, Envelope], None]:
        state = self.state

        def on_cmd(message: Message, _envelope: Envelope) -> None:
            assert isinstance(message, Twist)
            state.v_cmd[index] = message.linear_x_mps
            state.w_cmd[index] = message.angular_z_radps

        return on_cmd

    def _tick(self, run: RunContext, now_ns: int) -> None:
        if now_ns > 0:
            state = self.state
            motion = state.propose(self.limits, self.dt_s)
            for guard in self.guards:
                guard(now_ns, motion)
            if self.mirrors.any:
                self.mirrors.apply(motion, self.dt_s)
            state.commit(motion)
            # the arc each robot drove: guards zero the velocity of robots they hold
            self._integrate_odometry(motion.v * self.dt_s, motion.w * self.dt_s)
        self._publish_odometry(run, now_ns)

    def _integrate_odometry(self, ds: np.ndarray, dtheta: np.ndarray) -> None:
        if self.drift > 0:
            ds, dtheta = drift_increments(ds, dtheta, self.drift, self._noise.draw())
        x, y, yaw = advance(self.odom[:, 0], self.odom[:, 1], self.odom[:, 2], ds, dtheta)
        self.odom = np.stack([x, y, yaw], axis=1)

    def _publish_odometry(self, run: RunContext, now_ns: int) -> None:
        state = self.state
        odom = self.odom.tolist()
        v = state.v.tolist()
        w = state.w.tolist()
        messages = [
            Odometry(now_ns, frame, child, x, y, yaw, vi, wi)
            for (frame, child), (x, y, yaw), vi, wi in zip(self._frames, odom, v, w, strict=True)
        ]
        run.bus.publish_many(self._odom_topics, messages, self.hosts)

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        """Robots, distance driven and the final odometry error."""
        state = self.state
        error = np.hypot(self.odom[:, 0] - state.x, self.odom[:, 1] - state.y)
        return {
            "robots": len(state),
            "distance_m": round(float(state.distance_m.sum()), 6),
            "odometry_error_m_mean": round(float(error.mean()), 6),
        }
