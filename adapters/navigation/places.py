"""The fleet manager's places: a grid of robot-sized places, who stands on and holds which.

The fleet manager (``navigation.traffic = "pibt"``, :mod:`adapters.navigation.fleet_traffic`)
lays a grid of robot-sized places over the building's map (:mod:`models.navigation.roadmap`),
the narrow aisles one-way as with ``traffic = "lanes"`` and the open floor a grid of
alternating one-way streets, and lets each robot hold the place it stands on. A robot drives
to its next place (:mod:`models.navigation.place_drive`: turn on the spot, then straight)
and holds the place it left until its body is :data:`RELEASE_M` away from it. A goal is
reached from the nearest place within :data:`GOAL_REACH` spacings with a clear straight way
to it.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import linear_sum_assignment

from models.arrays import BoolArray, FloatArray, IntArray, UInt8Array
from models.errors import ModelError
from models.fleet.kinematics import DriveLimits
from models.navigation.costmap import StaticCostmap
from models.navigation.place_drive import place_drive
from models.navigation.roadmap import (
    UNREACHABLE,
    Int32Array,
    Roadmap,
    build_roadmap,
    one_way,
    one_way_floor,
    segment_clear,
)

GAP_M = 0.14
"""Gap between two robots standing on neighbouring places (m): spacing is 2 r + gap (0.8 m
for Jackals, a third of the 2.4 m pitch of the paper's rows of racks)."""
CLEARANCE_M = 0.1
"""Margin between a place, or the straight way between two, and a static obstacle (m)."""
ARRIVE_M = 0.45
"""A robot this close to the place it drives to stands on it and takes its next step (m)."""
RELEASE_M = 0.5
"""A robot lets go of the place it left once this far from its centre (m); a robot
driving in stops for it (:func:`~models.navigation.place_drive.place_drive`) if it is
slow to leave. Goals given up in fleet50, seeds 1-4 x 300 s: 0.4 m 45, 0.5 m 4, 0.55 m 13,
0.6 m 25; 0.73 m (its body clear of a robot standing there; with ``ARRIVE_M`` 0.3) 11, with
7 % fewer arrivals."""
GOAL_REACH = 2.0
"""A goal is reached from a place at most this many spacings away."""
VIA_M = 0.03
"""A robot this close to the centre of the place it turns on has passed it (m)."""
STAND, MOVE, APPROACH, SETTLE = 0, 1, 2, 3
"""What a robot does: stands on its place, drives to its next place, drives from its
goal's place to the goal, drives back onto its place (after the goal, or at the start)."""


class FleetPlaces:
    """The places of the whole fleet: who stands on, drives to and holds which, and goals.

    Args:
        static: the building's static costmap.
        lanes: one-way lanes on the static costmap's cells
            (:func:`models.navigation.lanes.aisle_lanes`).
        poses: (n, 2) start positions (m) in ``map``.
        radius_m: robot footprint radius (m).

    Raises:
        ModelError: when the floor has fewer places than robots.
    """

    def __init__(
        self, static: StaticCostmap, lanes: UInt8Array, poses: FloatArray, radius_m: float
    ) -> None:
        self.radius_m = radius_m
        self.footprint_clear = static.distance_m >= radius_m  # cells a robot centre may be on
        self.grid = (static.origin_xy_m, static.resolution_m)
        self.spacing_m = 2 * radius_m + GAP_M
        self.reach_m = 2 * radius_m + GAP_M / 2  # places a robot at a point touches
        self.roadmap: Roadmap = build_roadmap(
            static.distance_m,
            static.origin_xy_m,
            static.resolution_m,
            self.spacing_m,
            radius_m + CLEARANCE_M,
        )
        self.roadmap = one_way(self.roadmap, lanes, static.origin_xy_m, static.resolution_m)
        self.roadmap = one_way_floor(self.roadmap, lanes, static.origin_xy_m, static.resolution_m)
        n = len(poses)
        self.node = self._start_places(poses)
        self.mode = np.full(n, SETTLE, dtype=np.int64)
        self.held: list[list[int]] = [self.touched(poses[i], int(self.node[i])) for i in range(n)]
        self.aim = self.roadmap.xy[self.node].copy()
        self.came_from = self.node.copy()  # the place a robot standing on its place came from
        self.via = np.full((n, 2), np.nan)  # a place's centre to pass before turning off
        self.goal = np.full((n, 2), np.nan)
        self.goal_node = np.full(n, -1, dtype=np.int64)
        self.since_ns = np.zeros(n, dtype=np.int64)
        self.returning = np.zeros(n, dtype=bool)  # let a robot through off its goal's place
        self.hops: dict[int, Int32Array] = {}

    def _start_places(self, xy: FloatArray) -> IntArray:
        """A distinct place for every robot, nearest overall.

        A Hungarian assignment among the places near the robots.
        """
        rm = self.roadmap
        if len(xy) > len(rm):
            raise ModelError(
                "robots.count", len(xy), f"at most {len(rm)} robots: the places of traffic 'pibt'"
            )
        near = np.unique(rm.nearest_k(xy, min(len(rm), 9)))
        d = np.hypot(*(xy[:, None, :] - rm.xy[near][None, :, :]).transpose(2, 0, 1))
        _, cols = linear_sum_assignment(d)
        places: IntArray = near[cols].astype(np.int64)
        return places

    def touched(self, point: FloatArray, node: int) -> list[int]:
        """``node`` and every place a robot driving from it to ``point`` comes too close to."""
        start = self.roadmap.xy[node]
        steps = max(2, int(np.ceil(np.hypot(*(point - start)) / 0.1)) + 1)
        found: list[int] = [node]
        for t in np.linspace(0.0, 1.0, steps):
            for u in self.roadmap.near(start + t * (point - start), self.reach_m):
                if u not in found:
                    found.append(u)
        return found

    def hops_to(self, goal: int) -> Int32Array:
        """Hops from every place to place ``goal`` (cached per goal place)."""
        found = self.hops.get(goal)
        if found is None:
            found = self.roadmap.hops_to(goal)
            self.hops[goal] = found
        return found

    def goal_place(self, i: int, goal: FloatArray) -> int:
        """The place robot ``i`` reaches ``goal`` from, or -1 if none.

        The nearest of robot ``i``'s places within :data:`GOAL_REACH` spacings of the goal
        from which the straight way to the goal keeps the footprint off static obstacles.
        """
        rm = self.roadmap
        mine = rm.component[self.node[i]]
        near = [u for u in rm.near(goal, GOAL_REACH * rm.spacing_m) if rm.component[u] == mine]
        near.sort(key=lambda u: (float(np.hypot(*(rm.xy[u] - goal))), u))  # ties: lowest first
        for u in near:
            if segment_clear(self.footprint_clear, rm.xy[u][None], goal[None], *self.grid)[0]:
                return int(u)
        return -1

    def set_goal(self, i: int, goal: FloatArray, place: int, now_ns: int) -> None:
        """Robot ``i`` drives to ``goal`` (m) by way of ``place`` from now."""
        self.end_goal(i)
        self.goal[i] = goal
        self.goal_node[i] = place
        self.since_ns[i] = now_ns

    def way_left(self, i: int, xy: FloatArray) -> float:
        """Robot ``i``'s way (m) from ``xy`` to its goal along the places (inf if none)."""
        return float(self.ways(np.asarray(xy, dtype=float)[None], np.array([i]))[0])

    def end_goal(self, i: int) -> None:
        """Robot ``i``'s goal is reached, dropped or cancelled: it settles on its place."""
        self.goal[i] = np.nan
        self.goal_node[i] = -1
        self.returning[i] = False
        if self.mode[i] == APPROACH:
            self.mode[i] = SETTLE
            self.aim[i] = self.roadmap.xy[self.node[i]]

    def commands(
        self,
        poses: FloatArray,
        points: FloatArray,
        settle: tuple[FloatArray, FloatArray, BoolArray] | None,
        free_m: FloatArray,
        limits: DriveLimits,
    ) -> tuple[FloatArray, FloatArray]:
        """Speed and yaw-rate commands: straight from place to place.

        See :func:`~models.navigation.place_drive.place_drive`. Robots settling onto a
        place from off it (at the start, after a goal) take the local controller's speed
        and yaw rate from ``settle`` (needed when any robot is :attr:`settling`).
        """
        v, w = place_drive(poses, points, limits, free_m)
        if settle is None:
            return v, w
        settling = self.settling
        return np.where(settling, settle[0], v), np.where(settling, settle[1], w)

    @property
    def settling(self) -> BoolArray:
        """(n,) robots settling onto a place from off it."""
        settling: BoolArray = self.mode == SETTLE
        return settling

    def release(self, xy: FloatArray) -> None:
        """Let go of the places a robot's body has left (all but its own place)."""
        robots: list[int] = []
        places: list[int] = []
        for i in range(len(xy)):
            if self.held[i] and self.mode[i] != APPROACH:
                robots += [i] * len(self.held[i])
                places += self.held[i]
        if not robots:
            return
        # every held place's distance at once (the same numbers as one place at a time)
        gap = np.hypot(*(xy[robots] - self.roadmap.xy[places]).T).tolist()
        k = 0
        for i in dict.fromkeys(robots):
            held = self.held[i]
            near = gap[k : k + len(held)]
            k += len(held)
            self.held[i] = [
                u for u, d in zip(held, near, strict=True) if u == self.node[i] or d < RELEASE_M
            ]

    def remaining(self, xy: FloatArray, active: BoolArray) -> FloatArray:
        """Way left to each goal (m), 0 for robots without one (see :meth:`_ways`)."""
        out = np.zeros(len(xy))
        going = np.flatnonzero(active & (self.goal_node >= 0))
        if len(going):
            out[going] = self.ways(xy[going], going)
        return out

    def ways(self, xy: FloatArray, robots: IntArray) -> FloatArray:
        """Way left (m) of ``robots`` standing at ``xy`` (a row each).

        To the next place, along the places, to the goal; straight to the goal while
        approaching it.
        """
        rm = self.roadmap
        goal_node = self.goal_node[robots]
        hops = np.array(
            [self.hops_to(int(g))[u] for g, u in zip(goal_node, self.node[robots], strict=True)],
            dtype=float,
        )
        hops[hops == UNREACHABLE] = np.inf
        goal = self.goal[robots]
        along = (
            np.hypot(*(xy - self.aim[robots]).T)
            + hops * rm.spacing_m
            + np.hypot(*(rm.xy[goal_node] - goal).T)
        )
        approaching = self.mode[robots] == APPROACH
        ways: FloatArray = np.where(approaching, np.hypot(*(xy - goal).T), along)
        return ways
