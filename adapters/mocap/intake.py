"""The pose intake: every measured pose is checked before a robot's software or a twin uses it.

Measured poses come from the simulated motion capture, a replayed recording, a live mocap
system or a real robot over DDS. Each goes through the same checks, as a robot's
localization would apply them: the values must be a pose (finite numbers), the stamp must
be newer than the last accepted one, the pose must lie in the world (the room and its
walls, ``world.size_m`` and ``world.wall_thickness_m``: a tracked body outside it is not
where the robot can be, and no map covers it), and the displacement must be one the robot
can drive in the time between the two stamps (:class:`models.mocap.gate.PoseGate`). A
rejected pose is recorded (``tables/mocap``) and dropped; poses outside the world are
recorded once when a robot's poses leave it and once when they come back (``off_map`` /
``on_map`` in ``tables/mocap``, ``pose_off_map`` / ``pose_on_map`` events), all of them
counted (``mocap_rejected_off_map``). A dropped pose leaves the robot with its last good
one, which goes stale after ``mocap.max_age_ms``: its navigation stops it (and a twin
stays where it was last seen). An accepted one is published on
``/<robot>/pose`` (``geometry_msgs/PoseStamped`` in ``map``) and, for a twin, becomes its
ground truth.
"""

from __future__ import annotations

import math

from adapters.fleet.mirror import Mirrors
from adapters.mocap.settings import MocapConfig
from adapters.mocap.tables import MocapRecords
from adapters.mocap.topics import pose_topic
from cosim.core.adapter import RunContext
from cosim.core.hosts import HostId
from cosim.core.messages import PoseStamped
from cosim.core.timebase import NS_PER_S
from cosim.scenario.sections import RobotsConfig, WorldConfig
from models.fleet.kinematics import FleetState
from models.mocap.gate import PoseGate

JUMP_TOLERANCE_RAD = 0.2
"""Yaw change allowed beyond the yaw-rate limit between two poses (rad)."""


class PoseIntake:
    """Checks measured poses, records the rejected ones, publishes the accepted ones.

    Args:
        run: the run.
        host: the host the poses are published from (the mocap server, or a robot).
    """

    def __init__(self, run: RunContext, host: HostId) -> None:
        fleet = run.service(FleetState)
        robots = run.settings(RobotsConfig)
        self.run = run
        self.host = host
        self.names = list(fleet.names)
        self.index = {name: i for i, name in enumerate(self.names)}
        self.gate = PoseGate(
            max_speed_mps=max(robots.max_speed_mps, robots.max_reverse_mps),
            max_yaw_rate_radps=robots.max_yaw_rate_radps,
            tolerance_m=run.settings(MocapConfig).jump_tolerance_m,
            tolerance_rad=JUMP_TOLERANCE_RAD,
        )
        n = len(self.names)
        self.last = [(0.0, 0.0, 0.0)] * n
        self.last_stamp_ns = [0] * n
        self.has_last = [False] * n
        self.records = MocapRecords.of(run)
        self.recorder = run.recorder
        world = run.settings(WorldConfig)
        wall = world.wall_thickness_m
        self.world_m = (-wall, -wall, world.size_m[0] + wall, world.size_m[1] + wall)
        """(xmin, ymin, xmax, ymax) of the world in ``map`` (m): the room and its walls."""
        self.off_map = [False] * n
        """Whether robot i's latest pose lay outside the world."""
        self.mirrors = run.service(Mirrors)
        self.topics = [pose_topic(name) for name in self.names]
        self._advertised: set[int] = set()

    def advertise(self, index: int) -> None:
        """Announce robot ``index``'s pose topic (once)."""
        if index not in self._advertised:
            self.run.bus.advertise(self.topics[index], PoseStamped)
            self._advertised.add(index)

    def submit(
        self,
        index: int,
        stamp_ns: int,
        x_m: float,
        y_m: float,
        yaw_rad: float,
        *,
        mirror: bool,
        now_ns: int | None = None,
        host: HostId | None = None,
    ) -> bool:
        """Check one pose of robot ``index`` taken at ``stamp_ns``; publish it if good.

        Args:
            index: the robot.
            stamp_ns: when the pose was measured (kernel ns).
            x_m: x of the pose in ``map`` (m).
            y_m: y of the pose in ``map`` (m).
            yaw_rad: heading in ``map`` (rad).
            mirror: the robot is a twin: an accepted pose becomes its ground truth.
            now_ns: the kernel time (defaults to the kernel's now), for the records.
            host: publish from this host instead of the intake's.

        Returns:
            Whether the pose was accepted.
        """
        now = self.run.kernel.now_ns if now_ns is None else now_ns
        name = self.names[index]
        if not all(math.isfinite(v) for v in (x_m, y_m, yaw_rad)):
            self.records.row(now, name, "invalid", f"pose ({x_m}, {y_m}, {yaw_rad})")
            return False
        if not self._in_world(now, index, x_m, y_m):
            return False
        last = self.last[index] if self.has_last[index] else None
        verdict = self.gate.check_one(
            last, self.last_stamp_ns[index], (x_m, y_m, yaw_rad), stamp_ns
        )
        if verdict == "out_of_order":
            last_s = self.last_stamp_ns[index] / NS_PER_S
            detail = f"stamp {stamp_ns / NS_PER_S:.6f} s not after {last_s:.6f} s"
            self.records.row(now, name, "out_of_order", detail)
            return False
        if verdict == "jump":
            assert last is not None
            moved = math.hypot(x_m - last[0], y_m - last[1])
            dt = (stamp_ns - self.last_stamp_ns[index]) / NS_PER_S
            self.records.row(now, name, "jump", f"{moved:.3f} m in {dt:.3f} s")
            return False
        self.last[index] = (x_m, y_m, yaw_rad)
        self.last_stamp_ns[index] = stamp_ns
        self.has_last[index] = True
        if mirror:
            self.mirrors.set(index, x_m, y_m, yaw_rad)
        self.records.count("poses")
        self.run.bus.publish(
            self.topics[index],
            PoseStamped(stamp_ns, "map", x_m, y_m, yaw_rad),
            self.host if host is None else host,
        )
        return True

    def _in_world(self, now_ns: int, index: int, x_m: float, y_m: float) -> bool:
        """Whether the pose lies in the world; leaving it and coming back recorded once."""
        xmin, ymin, xmax, ymax = self.world_m
        inside = xmin <= x_m <= xmax and ymin <= y_m <= ymax
        if inside == (not self.off_map[index]):
            if not inside:
                self.records.count("off_map_poses")
            return inside
        name = self.names[index]
        self.off_map[index] = not inside
        where = f"pose ({x_m:.2f}, {y_m:.2f}) m"
        if inside:
            detail = f"{where}: back in the world"
            self.records.row(now_ns, name, "on_map", detail)
            self.recorder.event(now_ns, name, "pose_on_map", detail)
            return True
        world = f"[{xmin:g}, {xmax:g}] x [{ymin:g}, {ymax:g}] m"
        detail = f"{where} outside the world {world}: rejected, the robot holds its last pose"
        self.records.row(now_ns, name, "off_map", detail)
        self.recorder.event(now_ns, name, "pose_off_map", detail)
        self.records.count("off_map_poses")
        return False
