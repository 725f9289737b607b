"""Recovery of halted robots: wait, rotate, back up, replan (Nav2's recovery behaviours).

A robot with a goal that the local controller leaves standing for ``BLOCKED_REPLAN_S``
replans, then cycles through the steps of :data:`RECOVERY_STEPS` and replans again. The
wait lasts a random 0.5-2.5 s drawn from the robot's own stream, so two robots halted
nose to nose do not recover in lockstep and one of them gets going first. It rotates
towards the side with more room and backs up only if the latest scan shows room behind.
:class:`StallWatch` finds robots that stand still whatever they command.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from adapters.navigation.scan_memory import ScanMemory
from cosim.core.timebase import s_to_ns
from models.arrays import BoolArray, FloatArray
from models.fleet.kinematics import DriveLimits

RECOVERY_STEPS = (("wait", 1.0), ("rotate", 1.5), ("back_up", 1.5))
"""The recovery cycle: (behaviour, duration in s; the wait's is drawn), then a replan."""
BLOCKED_REPLAN_S = 1.0
"""Halted this long, a robot replans and starts recovering (s)."""
BACK_UP_ROOM_M = 0.4
"""How far behind its centre a backing robot's footprint must stay clear (m)."""
BACK_UP_MARGIN_M = 0.15
"""Clearance kept around the swept footprint when backing up (m)."""
STALL_M = 0.1
"""A robot with a goal whose pose moves less than this (m)..."""
STALL_RAD = 0.5
"""...and turns less than this (rad)..."""
STALL_S = 2.0
"""...for this long has stalled, whatever it commands (s)."""


class StallWatch:
    """Robots with a goal that have hardly moved or turned for ``STALL_S``.

    The controller's commands alone miss a livelock seen in ``fleet50``: two robots nose
    to nose, each turning left and right by turns (0.15 rad/s, above the halt threshold)
    and never moving, stood for 30 s without a recovery until ``stuck`` gave their goals
    up. A stalled robot counts as halted, so it recovers (Nav2's progress checker watches
    the pose in the same way: it must move some distance within a time).

    Args:
        poses: (n, 3) initial poses ``x, y, yaw`` in ``map`` (m, rad).
    """

    def __init__(self, poses: FloatArray) -> None:
        self.anchor = np.array(poses, dtype=float, copy=True)
        self.since_ns = np.zeros(len(poses), dtype=np.int64)

    def reset(self, i: int, pose: FloatArray, now_ns: int) -> None:
        """Start watching robot ``i`` afresh from ``pose`` (a new goal)."""
        self.anchor[i] = pose
        self.since_ns[i] = now_ns

    def update(self, now_ns: int, poses: FloatArray, active: BoolArray) -> BoolArray:
        """The robots with a goal stalled at ``now_ns``, given their ``poses`` (n, 3).

        A robot that moved more than ``STALL_M`` or turned more than ``STALL_RAD`` since
        its anchor, or has no goal, is anchored anew where it is.
        """
        turn = np.abs(np.angle(np.exp(1j * (poses[:, 2] - self.anchor[:, 2]))))
        moved = np.hypot(poses[:, 0] - self.anchor[:, 0], poses[:, 1] - self.anchor[:, 1])
        fresh = ~active | (moved > STALL_M) | (turn > STALL_RAD)
        self.anchor[fresh] = poses[fresh]
        self.since_ns[fresh] = now_ns
        stalled: BoolArray = now_ns - self.since_ns >= s_to_ns(STALL_S)
        return stalled


class Recovery:
    """The recovery state of every robot.

    Args:
        robots: number of robots.
        memory: the robots' latest scans (to look for room).
        limits: drive limits (recovery speeds are fractions of them).
        radius_m: footprint radius (m).
        rngs: one random stream per robot (wait durations).
    """

    def __init__(
        self,
        robots: int,
        memory: ScanMemory,
        limits: DriveLimits,
        radius_m: float,
        rngs: list[np.random.Generator],
    ) -> None:
        self.memory = memory
        self.limits = limits
        self.radius_m = radius_m
        self.rngs = rngs
        self.halted_ns = np.full(robots, -1, dtype=np.int64)
        self.step = np.full(robots, -1, dtype=np.int64)
        self.until_ns = np.zeros(robots, dtype=np.int64)
        self.turn_sign = np.ones(robots)

    def reset(self, i: int) -> None:
        """Forget robot ``i``'s recovery (a new goal)."""
        self.halted_ns[i] = -1
        self.step[i] = -1

    def apply(
        self,
        now_ns: int,
        halted: np.ndarray,
        active: np.ndarray,
        v: np.ndarray,
        w: np.ndarray,
        replan: Callable[[int], object],
        announce: Callable[[int, str], None],
    ) -> None:
        """Start and advance recoveries; overwrite the commands ``v``, ``w`` of recovering robots.

        Args:
            now_ns: current time (ns).
            halted: (n,) robots the local controller left standing.
            active: (n,) robots with a goal.
            v: (n,) forward speed commands (m/s), changed in place.
            w: (n,) yaw-rate commands (rad/s), changed in place.
            replan: plans robot ``i`` again.
            announce: records that robot ``i`` starts a recovery step (by name).
        """
        halted = halted & active
        idle = self.step < 0
        self.halted_ns[~halted & idle] = -1
        self.halted_ns[halted & (self.halted_ns < 0)] = now_ns
        due = halted & idle & (now_ns - self.halted_ns >= s_to_ns(BLOCKED_REPLAN_S))
        for i in np.flatnonzero(due).tolist():
            replan(i)
            self._begin(now_ns, i, 0, announce)
        for i in np.flatnonzero(self.step >= 0).tolist():
            if not active[i]:
                self.reset(i)
                continue
            if now_ns >= self.until_ns[i]:
                step = int(self.step[i]) + 1
                if step >= len(RECOVERY_STEPS):
                    self.reset(i)
                    replan(i)
                    continue
                self._begin(now_ns, i, step, announce)
            v[i], w[i] = self._command(i)

    def _begin(self, now_ns: int, i: int, step: int, announce: Callable[[int, str], None]) -> None:
        kind, duration = RECOVERY_STEPS[step]
        if kind == "wait":
            duration = float(self.rngs[i].uniform(0.5, 2.5))
        if kind == "rotate":
            left = self.memory.sector_min(i, 0.2, 1.8)
            right = self.memory.sector_min(i, -1.8, -0.2)
            self.turn_sign[i] = 1.0 if left >= right else -1.0
        self.step[i] = step
        self.until_ns[i] = now_ns + s_to_ns(duration)
        announce(i, kind)

    def _command(self, i: int) -> tuple[float, float]:
        kind = RECOVERY_STEPS[int(self.step[i])][0]
        if kind == "rotate":
            return 0.0, float(self.turn_sign[i] * 0.5 * self.limits.max_yaw_rate_radps)
        if kind == "back_up" and self._room_behind(i):
            return -0.5 * self.limits.max_reverse_mps, 0.0
        return 0.0, 0.0

    def _room_behind(self, i: int) -> bool:
        """Whether the footprint can back up ``BACK_UP_ROOM_M`` without coming near a hit.

        The footprint sweeps a capsule from the robot's centre backwards; no hit of the
        latest scan may lie within the radius plus the margin of that segment.
        """
        points = self.memory.local_points(i)
        if not len(points):
            return True
        back = np.clip(points[:, 0], -BACK_UP_ROOM_M, 0.0)
        gap = np.hypot(points[:, 0] - back, points[:, 1])
        return bool(gap.min() > self.radius_m + BACK_UP_MARGIN_M)


STUCK_KINDS = ("halted", "detoured", "slowed")
"""Why a robot reported ``stuck`` (:func:`stuck_kind`); the summary counts each as
``stuck_<kind>``."""
STUCK_HALTED_M = 1.0
"""A ``stuck`` robot that drove less than this since its last progress was halted (m)."""
STUCK_DETOURED_M = 5.0
"""A ``stuck`` robot that drove more, with a way left longer than its best by more than
this, was detoured (m)."""


def stuck_kind(driven_m: float, left_m: float, best_m: float) -> tuple[str, str]:
    """Why a robot made no progress: ``halted``, ``detoured`` or ``slowed``, and the figures.

    Args:
        driven_m: distance it drove since its last progress (m).
        left_m: length of the way it has left (m).
        best_m: the shortest way left it had (m).

    Returns:
        ``(kind, figures)``: *halted* when it hardly moved (blocked, or waiting), *detoured*
        when it drove but its way is now much longer than it was (planned round something),
        *slowed* when it drove without getting nearer (crawling in a crowd, dodging).
    """
    figures = f"drove {driven_m:.1f} m, {left_m:.1f} m to go, best {best_m:.1f} m"
    if driven_m < STUCK_HALTED_M:
        return "halted", figures
    if left_m > best_m + STUCK_DETOURED_M:
        return "detoured", figures
    return "slowed", figures
