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

Those are *measurement* rejections: a real system sends NaN for a lost body, a stale or
jumping pose, a body outside the room, and a robot's software must live with it. What is
not a pose at all is a fault of the source's code and ends the run (a
:class:`~cosim.core.plugins.PluginError` naming the source, the robot, the value and what
was expected): a robot index that is not an int of the fleet, a stamp that is not an int
(ns), coordinates that are not numbers (a string, None, an array; ``bool`` neither).
Floats pass at the cost of one type comparison each.
"""

from __future__ import annotations

import math
from numbers import Integral, Real
from typing import Any

from adapters.fleet.mirror import Mirrors
from adapters.mocap.settings import MocapConfig
from adapters.mocap.tables import MocapRecords
from adapters.mocap.topics import pose_topic
from cosim.core.adapter import RunContext
from cosim.core.hosts import HostId
from cosim.core.messages import PoseStamped
from cosim.core.plugins import PluginError, refuse
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
        source: the pose source class whose code submits (named in errors), or None.
    """

    def __init__(self, run: RunContext, host: HostId, source: Any = None) -> None:
        self.source = source
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

        Raises:
            PluginError: ``index``, ``stamp_ns`` or the coordinates are not numbers of the
                kind expected (see the module docstring).
        """
        if type(index) is not int or not 0 <= index < len(self.names):
            index = self._robot(index)
        if type(stamp_ns) is not int:
            stamp_ns = self._integer(index, stamp_ns)
        if type(x_m) is not float or type(y_m) is not float or type(yaw_rad) is not float:
            x_m, y_m, yaw_rad = self._numbers(index, x_m, y_m, yaw_rad)
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

    def _robot(self, index: Any) -> int:
        integral = isinstance(index, Integral) and not isinstance(index, bool)
        if integral and 0 <= int(index) < len(self.names):
            return int(index)
        expected = f"a robot index 0 to {len(self.names) - 1} (an int, in fleet order)"
        raise self._refuse(f"a pose for robot index {index!r}", expected, "")

    def _integer(self, index: int, stamp_ns: Any) -> int:
        if isinstance(stamp_ns, Integral) and not isinstance(stamp_ns, bool):
            return int(stamp_ns)
        what = f"stamp_ns = {stamp_ns!r} ({type(stamp_ns).__name__})"
        raise self._refuse(what, "an int (kernel ns)", self.names[index])

    def _numbers(self, index: int, *values: Any) -> tuple[float, float, float]:
        for key, value in zip(("x_m", "y_m", "yaw_rad"), values, strict=True):
            if not isinstance(value, Real) or isinstance(value, bool):
                what = f"{key} = {value!r} ({type(value).__name__})"
                raise self._refuse(what, "a number (m, rad)", self.names[index])
        x_m, y_m, yaw_rad = (float(v) for v in values)
        return x_m, y_m, yaw_rad

    def _refuse(self, what: str, expected: str, robot: str) -> PluginError:
        problem = f"submitted {what}{' for ' + robot if robot else ''}; expected {expected}"
        doing = f"taking in {robot}'s pose" if robot else "taking in a pose"
        if self.source is None:
            return PluginError(None, problem, doing=doing)
        return refuse(self.source, problem, doing=doing)

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
