"""A forward range finder on every robot: ``sensor_msgs/Range`` and a ``ranges`` table.

A narrow ultrasonic cone (``rangefinder.fov_deg`` wide, a few rays across it) looks ahead
of each robot at ``rangefinder.rate_hz``; its reading is the nearest surface any ray hits
(walls, shelves, other robots, people), or ``+inf`` with nothing within range (REP 117).
Every robot's reading is published on ``/<robot>/range`` from the robot's own host, and
recorded in ``tables/ranges`` (t_s, robot, range_m). All robots are cast in one call.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from cosim.core.adapter import RunContext
from cosim.core.bus import TopicQos
from cosim.core.hosts import HostId
from cosim.core.kernel import Stage
from cosim.core.messages import Const, Message, ros_message, std
from cosim.core.summary import SummaryKey
from cosim.core.table import TableSpec
from cosim.core.timebase import NS_PER_S, period_ns
from cosim.scenario.fields import param
from models.fleet.kinematics import FleetState
from models.sensing.raycast import StaticScene, cast_batch, scene_cell_m
from models.world.obstacles import DynamicObstacles
from models.world.warehouse import Warehouse

ULTRASOUND = 0
"""``sensor_msgs/Range.radiation_type`` of an ultrasonic sensor."""

RANGES = TableSpec(
    "ranges",
    "Every robot's range finder reading.",
    {
        "t_s": "reading time (s)",
        "robot": "the robot",
        "range_m": "distance to the nearest surface ahead (m); inf with nothing in range",
    },
    categorical=("robot",),
)


@dataclass(frozen=True)
class RangeFinderSettings:
    """``[rangefinder]``: the forward range finder on every robot."""

    rate_hz: float = param(10.0, "readings per second (Hz)", gt=0, le=1000)
    fov_deg: float = param(15.0, "width of the sensing cone (deg)", gt=0, le=90)
    rays: int = param(5, "rays cast across the cone", ge=1, le=100, unit="count")
    range_min_m: float = param(0.02, "nearest reading (m)", ge=0)
    range_max_m: float = param(4.0, "farthest reading (m)", gt=0, le=100)


@ros_message(
    std.RANGE,
    wire={
        "header.stamp": "stamp_ns",
        "header.frame_id": "frame_id",
        "radiation_type": Const(ULTRASOUND),
        "field_of_view": "field_of_view_rad",
        "min_range": "range_min_m",
        "max_range": "range_max_m",
        "range": "range_m",
    },
)
class Range(Message):
    """``sensor_msgs/msg/Range``: one ultrasonic reading in the sensor's frame (m, rad)."""

    stamp_ns: int
    frame_id: str
    field_of_view_rad: float
    range_min_m: float
    range_max_m: float
    range_m: float


class RangeFinderAdapter:
    """A forward ultrasonic range finder on every robot (``sensor_msgs/Range``)."""

    name: ClassVar[str] = "rangefinder"
    requires: ClassVar[tuple[str, ...]] = ("world", "fleet")
    tables: ClassVar[tuple[TableSpec, ...]] = (RANGES,)
    summary_keys: ClassVar[Mapping[str, SummaryKey]] = {
        "rangefinder_readings": SummaryKey("count", "readings taken, every robot's"),
        "rangefinder_closest_m": SummaryKey(
            "m", "closest thing any robot saw ahead (null: nothing in range)"
        ),
    }

    def __init__(self, run: RunContext) -> None:
        self.settings = run.settings(RangeFinderSettings)
        self.fleet = run.service(FleetState)
        segments = run.service(Warehouse).segments()
        self.scene = StaticScene(segments, cell_m=scene_cell_m(segments))
        self.dynamic = run.service(DynamicObstacles)
        half = math.radians(self.settings.fov_deg) / 2
        self.angles = np.linspace(-half, half, self.settings.rays)
        names = list(self.fleet.names)
        self.topics = [f"/{name}/range" for name in names]
        self.frames = [f"{name}/range" for name in names]
        self.hosts = [HostId(name) for name in names]
        self.table = run.recorder.table(RANGES)
        self.readings = 0
        for name in self.topics:
            run.bus.advertise(name, Range, TopicQos.SENSOR)

    def start(self, run: RunContext) -> None:
        """Start reading at the sensor's rate (SENSING stage, after physics)."""
        period = period_ns(self.settings.rate_hz)
        run.kernel.every(period, lambda now: self._read(run, now), stage=Stage.SENSING)

    def _read(self, run: RunContext, now_ns: int) -> None:
        fleet, s = self.fleet, self.settings
        bodies = np.stack([fleet.x, fleet.y, fleet.radius_m], axis=1)
        circles = np.vstack([bodies, self.dynamic.discs]) if len(self.dynamic) else bodies
        own = np.arange(len(bodies), dtype=np.int64)
        hits = cast_batch(
            self.scene, bodies[:, :2], fleet.yaw, self.angles, circles, own, s.range_max_m
        )
        nearest = hits.min(axis=1)
        nearest = np.where(nearest < s.range_min_m, s.range_min_m, nearest)
        fov = math.radians(s.fov_deg)
        messages: list[Message] = [
            Range(now_ns, frame, fov, s.range_min_m, s.range_max_m, float(r))
            for frame, r in zip(self.frames, nearest.tolist(), strict=True)
        ]
        run.bus.publish_many(self.topics, messages, self.hosts)
        self.table.extend(t_s=now_ns / NS_PER_S, robot=list(fleet.names), range_m=nearest)
        self.readings += 1

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        """How many readings, and the closest thing any robot saw ahead (m)."""
        ranges = self.table.column("range_m")
        closest = float(ranges.min()) if len(ranges) else math.inf
        return {
            "rangefinder_readings": self.readings * len(self.fleet),
            "rangefinder_closest_m": round(closest, 4) if math.isfinite(closest) else None,
        }
