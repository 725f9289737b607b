"""The teleop driver: every robot follows the velocity commands an operator sends.

An operator's command for a robot arrives on ``/<robot>/teleop/cmd_vel`` (a
:class:`~cosim.core.messages.Twist` in ``base_link``; a Unity scene's
``geometry_msgs/Twist`` on ``/<robot>/cmd_vel`` is published there by ``cosim run
--unity``). The robot's software (on its own host) keeps the latest one and, at the
control rate (CONTROL stage), publishes it on ``/<robot>/cmd_vel`` clipped to the
``[robots]`` limits (forward speed, reverse speed, yaw rate). A robot that has had no
command for :data:`DEADMAN_S` (simulated time, the wall clock in a real-time run) gets
zero velocity, as a teleop node's dead-man does when its operator lets go. The robot's
kinematics and the collision checks apply as for any driver.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any, ClassVar

from adapters.drivers.topics import teleop_topic
from adapters.fleet.topics import cmd_vel_topic
from cosim.core.adapter import RunContext
from cosim.core.bus import Envelope
from cosim.core.hosts import HostId
from cosim.core.kernel import Stage
from cosim.core.messages import Message, Twist
from cosim.core.summary import SummaryKey
from cosim.core.timebase import period_ns, s_to_ns
from cosim.scenario.sections import RobotsConfig
from models.fleet.kinematics import FleetState

DEADMAN_S = 0.5
"""A robot with no command this long stops (s)."""


class TeleopAdapter:
    """Follows each robot's latest operator command; stops it when commands stop."""

    name: ClassVar[str] = "teleop"
    requires: ClassVar[tuple[str, ...]] = ("fleet",)
    summary_keys: ClassVar[Mapping[str, SummaryKey]] = {
        "teleop_commands": SummaryKey("count", "operator velocity commands taken"),
        "teleop_deadman_stops": SummaryKey(
            "count", f"robots stopped after {DEADMAN_S:g} s without a command"
        ),
    }
    """The summary keys :meth:`finish` writes (documented in the summary reference)."""

    def __init__(self, run: RunContext) -> None:
        robots = run.settings(RobotsConfig)
        self.names = list(run.service(FleetState).names)
        self.hosts = [HostId(name) for name in self.names]
        self.max_speed_mps = robots.max_speed_mps
        self.max_reverse_mps = robots.max_reverse_mps
        self.max_yaw_rate_radps = robots.max_yaw_rate_radps
        self.period_ns = period_ns(robots.control_hz)
        self.deadman_ns = s_to_ns(DEADMAN_S)
        count = len(self.names)
        self.v_mps = [0.0] * count
        self.w_radps = [0.0] * count
        self.heard_ns = [-self.deadman_ns - 1] * count
        """Kernel time each robot's latest command arrived (ns)."""
        self.commands = 0
        self.stops = 0
        self._following = [False] * count
        for name in self.names:
            run.bus.advertise(cmd_vel_topic(name), Twist)
            run.bus.advertise(teleop_topic(name), Twist)

    def start(self, run: RunContext) -> None:
        """Subscribe to every robot's operator commands and start the control tick."""
        for index, (name, host) in enumerate(zip(self.names, self.hosts, strict=True)):
            run.bus.subscribe(teleop_topic(name), host, self._on_command(run, index))
        self._cmd_topics = [cmd_vel_topic(name) for name in self.names]
        run.kernel.every(self.period_ns, lambda now: self._control(run, now), stage=Stage.CONTROL)

    def _on_command(self, run: RunContext, index: int) -> Callable[[Message, Envelope], None]:
        def on_command(message: Message, _envelope: Envelope) -> None:
            assert isinstance(message, Twist)
            v, w = message.linear_x_mps, message.angular_z_radps
            if not (math.isfinite(v) and math.isfinite(w)):
                return  # senders check; a non-finite command never reaches the wheels
            self.v_mps[index] = min(max(v, -self.max_reverse_mps), self.max_speed_mps)
            self.w_radps[index] = min(max(w, -self.max_yaw_rate_radps), self.max_yaw_rate_radps)
            self.heard_ns[index] = run.kernel.now_ns
            self.commands += 1

        return on_command

    def _control(self, run: RunContext, now_ns: int) -> None:
        topics, messages = self._cmd_topics, []
        for index in range(len(self.names)):
            live = now_ns - self.heard_ns[index] <= self.deadman_ns
            if self._following[index] and not live:
                self.stops += 1
                run.recorder.event(now_ns, self.names[index], "teleop_stop", "no command")
            self._following[index] = live
            if live:
                messages.append(Twist(self.v_mps[index], self.w_radps[index]))
            else:
                messages.append(Twist(0.0, 0.0))
        run.bus.publish_many(topics, messages, self.hosts)

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        """Commands taken and dead-man stops."""
        return {"teleop_commands": self.commands, "teleop_deadman_stops": self.stops}
