"""Where each robot's software believes it is: odometry, its map's correction, or measured poses.

A robot localizes on its wheel odometry (``/<robot>/odom``), corrected by its own
mapping's ``map -> odom`` transform (``/<robot>/tf``) when it maps. Robots tracked by
motion capture (or physical robots reporting their own pose) take their pose from
``/<robot>/pose`` instead.

A robot whose newest pose is older than ``mocap.max_age_ms`` stops: the controller's
command is replaced by zero velocity until a fresh pose arrives. Both transitions are
recorded in ``tables/mocap`` (``stale``, ``fresh``). A robot starts with its known initial
pose, stamped at time 0.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import numpy.typing as npt

from adapters.fleet.topics import odom_topic
from adapters.mapping.topics import correction_topic
from adapters.mocap.settings import MocapConfig
from adapters.mocap.tables import MocapRecords
from adapters.mocap.topics import pose_topic
from adapters.mocap.tracking import tracked_robots
from cosim.core.adapter import RunContext
from cosim.core.bus import Envelope
from cosim.core.hosts import HostId
from cosim.core.messages import Message, Odometry, PoseStamped, TFMessage
from cosim.core.timebase import NS_PER_S, ms_to_ns
from models.arrays import FloatArray
from models.fleet.kinematics import FleetState
from models.geometry.se2 import compose


class MeasuredPoses:
    """Which robots localize by measured poses, their newest stamps, and who is stale.

    Args:
        run: the run.
        names: the robots, by index.
    """

    def __init__(self, run: RunContext, names: list[str]) -> None:
        n = len(names)
        self.names = names
        self.tracked = np.zeros(n, dtype=bool)
        for name in tracked_robots(run.scenario, names):
            self.tracked[names.index(name)] = True
        self.max_age_ns = ms_to_ns(run.settings(MocapConfig).max_age_ms)
        self.stamp_ns = np.zeros(n, dtype=np.int64)
        self.stale = np.zeros(n, dtype=bool)
        self.records = MocapRecords.of(run) if self.tracked.any() else None

    def subscribe(
        self,
        run: RunContext,
        hosts: list[HostId],
        on_pose: Callable[[int, float, float, float], None],
    ) -> None:
        """Subscribe every tracked robot's software to its poses."""
        for i in np.flatnonzero(self.tracked).tolist():
            run.bus.subscribe(pose_topic(self.names[i]), hosts[i], self._handler(i, on_pose))

    def _handler(
        self, i: int, on_pose: Callable[[int, float, float, float], None]
    ) -> Callable[[Message, Envelope], None]:
        def on_message(message: Message, _envelope: Envelope) -> None:
            assert isinstance(message, PoseStamped)
            if message.stamp_ns >= self.stamp_ns[i]:
                self.stamp_ns[i] = message.stamp_ns
                on_pose(i, message.x_m, message.y_m, message.yaw_rad)

        return on_message

    def check(self, now_ns: int) -> npt.NDArray[np.bool_]:
        """The robots that must stop now: tracked and with a pose older than the limit."""
        stale = self.tracked & (now_ns - self.stamp_ns > self.max_age_ns)
        changed = stale != self.stale
        if changed.any() and self.records is not None:
            for i in np.flatnonzero(changed).tolist():
                age_s = (now_ns - int(self.stamp_ns[i])) / NS_PER_S
                event = "stale" if stale[i] else "fresh"
                self.records.row(now_ns, self.names[i], event, f"pose age {age_s:.3f} s")
        self.stale = stale
        return stale


class Localization:
    """Every robot's pose estimate and measured velocity, kept up to date from the bus.

    Args:
        run: the run.
        fleet: the fleet (names and start poses: every robot knows where it starts).
        mapping: robots correct their odometry with their own map's ``map -> odom``.
    """

    def __init__(self, run: RunContext, fleet: FleetState, *, mapping: bool) -> None:
        self.names = list(fleet.names)
        self.mapping = mapping
        self.pose: FloatArray = np.stack([fleet.x, fleet.y, fleet.yaw], axis=1)
        """(n, 3) pose estimates in ``map`` (m, rad), updated in place."""
        self.vel: FloatArray = np.zeros((len(self.names), 2))
        """(n, 2) measured speeds and yaw rates (m/s, rad/s), updated in place."""
        self.correction = [(0.0, 0.0, 0.0)] * len(self.names)
        """Per robot ``map -> odom`` from its mapping (identity without mapping)."""
        self.measured = MeasuredPoses(run, self.names)
        """Robots localizing by motion capture (or their own reported pose)."""

    def subscribe(self, run: RunContext, hosts: list[HostId]) -> None:
        """Subscribe every robot's software to its odometry, corrections and poses."""
        bus = run.bus
        for i, (name, host) in enumerate(zip(self.names, hosts, strict=True)):
            bus.subscribe(odom_topic(name), host, self._on_odom(i))
            if self.mapping:
                bus.subscribe(correction_topic(name), host, self._on_correction(i))
        self.measured.subscribe(run, hosts, self._on_measured_pose)

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
