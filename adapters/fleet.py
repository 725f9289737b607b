"""The fleet adapter: ground-truth kinematics of every robot, odometry and cmd_vel.

Each robot is a host named after it. The adapter subscribes ``/<robot>/cmd_vel`` on the
robot's host and, at ``robots.control_hz`` in the PHYSICS stage, advances all robots in
one vectorized step and publishes ``/<robot>/odom``. The ``odom`` frame starts aligned
with ``map`` (each robot is told its start pose, as an initial pose is given to a
localizer), so without drift odometry equals ground truth.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

from adapters.naming import robot_name, topic
from cosim.adapter import RunContext
from cosim.bus import Envelope
from cosim.hosts import HostKind
from cosim.kernel import Stage
from cosim.messages import Message, Odometry, Twist
from cosim.timebase import NS_PER_S, period_ns
from models.kinematics import DriveLimits, FleetState
from models.world import Warehouse


def drive_limits(run: RunContext) -> DriveLimits:
    """The scenario's drive limits."""
    robots = run.scenario.robots
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

    def __init__(self, run: RunContext) -> None:
        world = run.service(Warehouse)
        robots = run.scenario.robots
        names = [robot_name(i) for i in range(robots.count)]
        self.state = FleetState(names, world.starts, robots.radius_m)
        self.limits = drive_limits(run)
        self.hosts = [run.add_host(name, HostKind.ROBOT) for name in names]
        self.period_ns = period_ns(robots.control_hz)
        run.provide(self.state)

    def start(self, run: RunContext) -> None:
        """Subscribe to every robot's cmd_vel and start the physics tick."""
        for index, (name, host) in enumerate(zip(self.state.names, self.hosts, strict=True)):
            run.bus.subscribe(topic(name, "cmd_vel"), host, self._on_cmd(index))
        self._odom_topics = [topic(name, "odom") for name in self.state.names]
        run.kernel.every(self.period_ns, lambda now: self._tick(run, now), stage=Stage.PHYSICS)

    def _on_cmd(self, index: int) -> Any:
        state = self.state

        def on_cmd(message: Message, _envelope: Envelope) -> None:
            assert isinstance(message, Twist)
            state.v_cmd[index] = message.linear_x_mps
            state.w_cmd[index] = message.angular_z_radps

        return on_cmd

    def _tick(self, run: RunContext, now_ns: int) -> None:
        if now_ns > 0:
            self.state.step(self.limits, self.period_ns / NS_PER_S)
        self._publish_odometry(run, now_ns)

    def _publish_odometry(self, run: RunContext, now_ns: int) -> None:
        state = self.state
        publish = run.bus.publish
        for i, host in enumerate(self.hosts):
            publish(
                self._odom_topics[i],
                Odometry(
                    now_ns,
                    "odom",
                    "base_link",
                    float(state.x[i]),
                    float(state.y[i]),
                    float(state.yaw[i]),
                    float(state.v[i]),
                    float(state.w[i]),
                ),
                host,
            )

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        """Robots and distance driven."""
        return {
            "robots": len(self.state),
            "distance_m": round(float(self.state.distance_m.sum()), 6),
        }
