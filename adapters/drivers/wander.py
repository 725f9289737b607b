"""The wander driver: every robot roams, steering away from what its lidar sees.

The robot software (on each robot's host) keeps its latest ``/<robot>/scan``; at the
control rate (CONTROL stage) one vectorized call computes every robot's command, which
goes out on ``/<robot>/cmd_vel``. Robots without a scan yet stand still.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any, ClassVar

import numpy as np

from adapters.fleet.topics import cmd_vel_topic
from adapters.sensing.topics import scan_topic
from cosim.core.adapter import RunContext
from cosim.core.bus import Envelope
from cosim.core.hosts import HostId
from cosim.core.kernel import Stage
from cosim.core.messages import LaserScan, Message, Twist
from cosim.core.timebase import period_ns
from cosim.scenario.sections import LidarConfig, RobotsConfig
from models.drivers.wander import WanderParams, wander
from models.fleet.kinematics import FleetState


class WanderAdapter:
    """Reactive roaming from lidar scans for every robot."""

    name: ClassVar[str] = "wander"
    requires: ClassVar[tuple[str, ...]] = ("fleet", "lidar")

    def __init__(self, run: RunContext) -> None:
        self.names = list(run.service(FleetState).names)
        self.hosts = [HostId(name) for name in self.names]
        robots = run.settings(RobotsConfig)
        lidar = run.settings(LidarConfig)
        self.max_speed_mps = robots.max_speed_mps
        self.max_yaw_rate_radps = robots.max_yaw_rate_radps
        self.range_max_m = lidar.range_max_m
        self.params = WanderParams()
        self.period_ns = period_ns(robots.control_hz)
        self.ranges = np.full((len(self.names), max(lidar.beams, 1)), np.nan)
        self.angles: np.ndarray | None = None
        self.seen = np.zeros(len(self.names), dtype=bool)
        for name in self.names:
            run.bus.advertise(cmd_vel_topic(name), Twist)

    def start(self, run: RunContext) -> None:
        """Subscribe to every robot's scan and start the control tick."""
        for index, (name, host) in enumerate(zip(self.names, self.hosts, strict=True)):
            run.bus.subscribe(scan_topic(name), host, self._on_scan(index))
        self._cmd_topics = [cmd_vel_topic(name) for name in self.names]
        run.kernel.every(self.period_ns, lambda now: self._control(run), stage=Stage.CONTROL)

    def _on_scan(self, index: int) -> Callable[[Message, Envelope], None]:
        def on_scan(message: Message, _envelope: Envelope) -> None:
            assert isinstance(message, LaserScan)
            if self.angles is None:
                count = len(message.ranges_m)
                self.angles = message.angle_min_rad + message.angle_increment_rad * np.arange(count)
            self.ranges[index] = message.ranges_m
            self.seen[index] = True

        return on_scan

    def _control(self, run: RunContext) -> None:
        if self.angles is None:
            return
        v, w = wander(
            self.ranges,
            self.angles,
            self.range_max_m,
            self.max_speed_mps,
            self.max_yaw_rate_radps,
            self.params,
        )
        v = np.where(self.seen, v, 0.0).tolist()
        w = np.where(self.seen, w, 0.0).tolist()
        publish = run.bus.publish
        for index, host in enumerate(self.hosts):
            publish(self._cmd_topics[index], Twist(v[index], w[index]), host)

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        """Nothing to add."""
        return {}
