"""The lidar adapter: one batched cast for every robot at each scan instant.

At ``lidar.rate_hz`` (SENSING stage) it casts all robots' beams against the static
world, the other robots and the dynamic obstacles in one call (a grid-indexed caster,
:mod:`models.sensing.raycast`), applies each robot's noise and dropout from the robot's own
random stream, and publishes ``/<robot>/scan`` on the robot's host.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, ClassVar

import numpy as np

from adapters.sensing.topics import scan_topic
from cosim.core.adapter import RunContext
from cosim.core.bus import TopicQos
from cosim.core.hosts import HostId
from cosim.core.kernel import Stage
from cosim.core.messages import LaserScan
from cosim.core.rng import BlockDraws
from cosim.core.summary import SummaryKey
from cosim.core.timebase import period_ns
from cosim.scenario.sections import LidarConfig
from models.fleet.kinematics import FleetState
from models.sensing.lidar import ScanGeometry, apply_sensor_model
from models.sensing.raycast import StaticScene, cast_batch, scene_cell_m
from models.world.obstacles import DynamicObstacles
from models.world.warehouse import Warehouse


class LidarAdapter:
    """Planar lidar on every robot."""

    name: ClassVar[str] = "lidar"
    requires: ClassVar[tuple[str, ...]] = ("world", "fleet")
    summary_keys: ClassVar[Mapping[str, SummaryKey]] = {
        "lidar_scans": SummaryKey("count", "scan instants (every robot scans at each)"),
        "lidar_rays": SummaryKey("count", "rays cast: scans x robots x beams"),
    }
    """The summary keys :meth:`finish` writes (documented in the summary reference)."""

    def __init__(self, run: RunContext) -> None:
        cfg = run.settings(LidarConfig)
        self.geometry = ScanGeometry(
            beams=cfg.beams,
            fov_rad=math.radians(cfg.fov_deg),
            range_min_m=cfg.range_min_m,
            range_max_m=cfg.range_max_m,
        )
        self.noise_std_m = cfg.noise_std_m
        self.dropout_prob = cfg.dropout_prob
        self.period_ns = period_ns(cfg.rate_hz)
        self.fleet = run.service(FleetState)
        segments = run.service(Warehouse).segments()
        self.scene = StaticScene(segments, cell_m=scene_cell_m(segments))
        self.dynamic = run.service(DynamicObstacles)
        self.beam_angles = self.geometry.angles()
        names = self.fleet.names
        beams = self.geometry.beams
        # float32 draws: the published ranges are float32 anyway
        # each robot's stream refilled on the run's threads (the same numbers)
        spread = run.workers.map
        self.noise = BlockDraws(
            [run.rng.stream(f"lidar/{n}/noise") for n in names],
            beams,
            dtype=np.float32,
            spread=spread,
        )
        self.dropout = BlockDraws(
            [run.rng.stream(f"lidar/{n}/dropout") for n in names],
            beams,
            kind="uniform",
            dtype=np.float32,
            spread=spread,
        )
        self._zeros = np.zeros((len(names), beams), dtype=np.float32)
        self._ones = np.ones((len(names), beams), dtype=np.float32)
        self.topics = [scan_topic(name) for name in self.fleet.names]
        self._own = np.arange(len(names), dtype=np.int64)  # each robot's own circle
        self._frames = [f"{name}/laser" for name in names]
        self._hosts = [HostId(name) for name in names]
        self.scans = 0
        if cfg.beams > 0:
            for name in self.topics:
                run.bus.advertise(name, LaserScan, TopicQos.SENSOR)

    def start(self, run: RunContext) -> None:
        """Start the scan tick (disabled when ``lidar.beams`` is 0)."""
        if self.geometry.beams > 0:
            run.kernel.every(self.period_ns, lambda now: self._scan(run, now), stage=Stage.SENSING)

    def _scan(self, run: RunContext, now_ns: int) -> None:
        fleet = self.fleet
        geometry = self.geometry
        bodies = np.stack([fleet.x, fleet.y, fleet.radius_m], axis=1)
        circles = np.vstack([bodies, self.dynamic.discs]) if len(self.dynamic) else bodies
        exact = cast_batch(
            self.scene,
            bodies[:, :2],
            fleet.yaw,
            self.beam_angles,
            circles,
            self._own,
            geometry.range_max_m,
            slices=run.workers.chunks,
        )
        scan_time_s = self.period_ns / 1e9
        # a disabled error source draws nothing (its stream is simply not used)
        normals = self.noise.draw() if self.noise_std_m > 0 else self._zeros
        uniforms = self.dropout.draw() if self.dropout_prob > 0 else self._ones
        scans = apply_sensor_model(
            exact, geometry, self.noise_std_m, self.dropout_prob, normals, uniforms
        )
        angle_min, increment = geometry.angle_min_rad, geometry.angle_increment_rad
        range_min, range_max = geometry.range_min_m, geometry.range_max_m
        messages = [
            LaserScan(
                now_ns, frame, angle_min, increment, range_min, range_max, scan_time_s, ranges
            )
            for frame, ranges in zip(self._frames, scans, strict=True)
        ]
        run.bus.publish_many(self.topics, messages, self._hosts)
        self.scans += 1

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        """Scan instants and rays cast."""
        rays = self.scans * len(self.fleet) * self.geometry.beams
        return {"lidar_scans": self.scans, "lidar_rays": rays}
