"""Localization by measured poses instead of odometry.

Robots tracked by motion capture (or physical robots reporting their own pose) take
their pose from ``/<robot>/pose``.

A robot whose newest pose is older than ``mocap.max_age_ms`` stops: the controller's
command is replaced by zero velocity until a fresh pose arrives. Both transitions are
recorded in ``tables/mocap`` (``stale``, ``fresh``). A robot starts with its known initial
pose, stamped at time 0.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import numpy.typing as npt

from adapters.mocap.intake import pose_topic
from adapters.mocap.records import MocapRecords
from adapters.mocap.tracking import tracked_robots
from cosim.adapter import RunContext
from cosim.bus import Envelope
from cosim.hosts import HostId
from cosim.messages import Message, PoseStamped
from cosim.timebase import NS_PER_S, ms_to_ns


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
        self.max_age_ns = ms_to_ns(run.scenario.mocap.max_age_ms)
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
