"""``navigation.traffic = "pibt"``: a fleet manager that moves robots place by place.

The fleet manager lays a grid of robot-sized places over the building's map
(:mod:`models.navigation.roadmap`), with the narrow aisles one-way as with
``traffic = "lanes"`` and the open floor a grid of alternating one-way streets (no two
robots meet head-on anywhere), and lets each robot hold the place it stands on. At every control
tick the robots standing on a place take one PIBT step (:mod:`models.navigation.pibt`):
each in priority order claims the neighbouring place nearest its goal that no one holds
or has claimed, asking a robot standing there to make way. A robot drives to its claimed
place (:mod:`models.navigation.place_drive`: turn on the spot, then straight) and holds
the place it left until its body is :data:`RELEASE_M` away from it; a robot that follows
waits on its own place until then. Within :data:`ARRIVE_M` of its new place it takes its
next step, so a robot going straight on does not stop; among equally short ways it
prefers a free place, then straight on (a turn is a stop: +19 % goals reached in fleet50).
A goal is reached from the nearest place within :data:`GOAL_REACH` spacings with a clear
straight way to it: on that place the robot claims every place its body will touch on the
way and drives to the goal; after the goal it settles back on the place. Robots standing on
a place the approach needs are asked to make way (the places still free are left to them
as a way out, then kept for the approach: no one else moves in while it waits); one whose
only way on leads through the approaching robot's place goes first, and the approaching
robot makes way for it.

Priorities: PIBT's rule (Okumura et al. 2022) is the goal's age, which always lets the
robot waiting longest move nearer; here a robot on its goal's place goes first (it is a
few seconds from done, and on a one-way street a robot pushed on from there drives
round the block), then a robot that has made no progress for :data:`URGENT_S`, the
longest-stalled first, so that robots pushed about in a crowd get their turn before
``stuck`` (30 s) gives their goal up.

Goals given up in fleet50, 10 seeds x 300 s (seeds 1-10; 11-20 in brackets), as each
rule was added: 38 [-] before the one-way floor; 73 with it, 52 of them in one seed where
a robot taking its next step let go of a place its body still covered and two robots
stopped for each other for good; 14 [10] once such places stay held; 4 with free places
left to pushed robots; 2 [6] with robots let through; 3 [2] with robots on their goal's
place first; 1 [1] with the free places kept while waiting (arrivals 3,575 -> 3,856
[3,850]); 3 [-] once every lidar hit, not only moving ones, stops a robot; 1 [4] once a
robot may step back onto a place only its own body still covers (arrivals 3,827 [3,838]);
1 [1] once a robot that let another through off its goal's place keeps the places its
approach needs while it comes back (one robot whose goal lay in a stream of robots had
made way for each in turn); 0 [1] once a robot asked to make way does not go round the
block while the robot ahead of it drives off (:class:`~models.navigation.pibt.Pibt`'s
``leaving``; arrivals 3,831 [3,840]; on seeds 21-40, not looked at while choosing its
threshold, 3 given up with the rule and without it); 0 [3 on seeds 11-40, 4 before] once a
robot that has reached its next place also counts as driving off the place its body still
covers (seed 36: the robot behind it was pushed round the block; arrivals on seeds 1-40
15,242 against 15,248). The last ones: a robot pushed step by step off its way in a crowd
ends on a loop of 20-30 places round the racks; a robot whose goal lies in a through
street lets a robot through and the one it let through must go round. A robot that does
not push robots with a goal when they could only make way round the block (unless
stalled) gave 4 in 20 seeds instead of 5: no better than chance, so not kept.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import linear_sum_assignment

from cosim.errors import ConfigError
from cosim.scenario.model import Scenario
from cosim.timebase import s_to_ns
from models.arrays import BoolArray, FloatArray, IntArray, UInt8Array
from models.errors import ModelError
from models.kinematics import DriveLimits
from models.navigation.costmap import StaticCostmap
from models.navigation.pibt import Pibt
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
URGENT_S = 10.0
"""A robot with no progress for this long goes first (s). Goals given up as above (with
``RELEASE_M`` 0.73, ``ARRIVE_M`` 0.3): 3 s 22, 6 s 14, 10 s 11, 20 s 41; the goal's age
alone (PIBT's rule) 32; the time since progress alone 23."""
GOAL_REACH = 2.0
"""A goal is reached from a place at most this many spacings away."""
VIA_M = 0.03
"""A robot this close to the centre of the place it turns on has passed it (m)."""
STAND, MOVE, APPROACH, SETTLE = 0, 1, 2, 3
"""What a robot does: stands on its place, drives to its next place, drives from its
goal's place to the goal, drives back onto its place (after the goal, or at the start)."""


def check_localization(scenario: Scenario, tracked: BoolArray) -> None:
    """Refuse the fleet manager for robots that cannot tell where they are to within the gap.

    The places are :data:`GAP_M` apart beyond the robots' bodies, and each robot drives to
    them on its own pose estimate. Robots localizing on their own maps (``mapping.enabled``)
    or on drifting odometry alone (``odometry.drift`` > 0) are off by more: in fleet50 the
    maps put them 0.15-0.3 m off on average (50 robots mostly see each other), and with
    traffic "pibt" robots touched 5 times in 2 seeds x 120 s (9 in 4 with drift 0.02)
    where motion capture gave 0 contacts and 0 goals given up.

    Args:
        scenario: the run's scenario.
        tracked: (n,) robots localizing by measured poses (motion capture).

    Raises:
        ConfigError: with traffic "pibt", when a robot not tracked localizes by mapping or
            drifting odometry.
    """
    if scenario.navigation.traffic != "pibt" or tracked.all():
        return
    if scenario.mapping.enabled:
        how = "[mapping] enabled = true (robots localize on their own maps, 0.15-0.3 m off)"
    elif scenario.odometry.drift > 0:
        how = (
            f"[odometry] drift = {scenario.odometry.drift:g} (robots localize by odometry "
            "alone, whose error grows without bound)"
        )
    else:
        return
    raise ConfigError(
        f"{scenario.source}: [navigation] traffic = 'pibt' with {how}: expected every robot "
        f"localized to within centimetres ({int((~tracked).sum())} of {len(tracked)} are not "
        "tracked): the fleet manager keeps robots "
        f"{GAP_M:g} m apart on neighbouring places and trusts their poses. Set "
        "navigation.traffic = 'none' (each robot plans on what it knows) or track the robots "
        "by motion capture (mocap.source = 'simulated')"
    )


class FleetTraffic:
    """Places, holds and PIBT steps for the whole fleet.

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
        self.held: list[list[int]] = [self._touched(poses[i], int(self.node[i])) for i in range(n)]
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

    def _touched(self, point: FloatArray, node: int) -> list[int]:
        """``node`` and every place a robot driving from it to ``point`` comes too close to."""
        start = self.roadmap.xy[node]
        steps = max(2, int(np.ceil(np.hypot(*(point - start)) / 0.1)) + 1)
        found: list[int] = [node]
        for t in np.linspace(0.0, 1.0, steps):
            for u in self.roadmap.near(start + t * (point - start), self.reach_m):
                if u not in found:
                    found.append(u)
        return found

    def _hops(self, goal: int) -> Int32Array:
        """Hops from every place to place ``goal`` (cached per goal place)."""
        found = self.hops.get(goal)
        if found is None:
            found = self.roadmap.hops_to(goal)
            self.hops[goal] = found
        return found

    # -- goals --------------------------------------------------------------------------
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
        return float(self._ways(np.asarray(xy, dtype=float)[None], np.array([i]))[0])

    def end_goal(self, i: int) -> None:
        """Robot ``i``'s goal is reached, dropped or cancelled: it settles on its place."""
        self.goal[i] = np.nan
        self.goal_node[i] = -1
        self.returning[i] = False
        if self.mode[i] == APPROACH:
            self.mode[i] = SETTLE
            self.aim[i] = self.roadmap.xy[self.node[i]]

    # -- the step -------------------------------------------------------------------------
    def step(
        self, poses: FloatArray, active: BoolArray, progress_ns: IntArray, now_ns: int
    ) -> tuple[FloatArray, FloatArray]:
        """Advance holds and plan one PIBT step for the robots standing on a place.

        Args:
            poses: (n, 3) robot poses in ``map`` (m, m, rad).
            active: (n,) robots with a goal.
            progress_ns: (n,) when each robot last made progress (ns).
            now_ns: simulated time (ns).

        Returns:
            The (n, 2) point each robot drives to now (m, ``map``), and the (n,) way left
            to each goal along the places (m).
        """
        rm = self.roadmap
        xy = poses[:, :2]
        passed = np.hypot(*(xy - self.via).T) < VIA_M
        self.via[passed] = np.nan
        gap = np.hypot(*(xy - self.aim).T)
        moving = (self.mode == MOVE) | (self.mode == SETTLE)
        landed = moving & np.isnan(self.via[:, 0]) & (gap <= ARRIVE_M)
        self.mode[landed] = STAND
        self._release(xy)
        standing = np.flatnonzero(self.mode == STAND)
        # held places and their holders (-1: several); a robot may go back to a place
        # only its own body still covers (it made way, or turns back)
        held: dict[int, int] = {}
        leaving: set[int] = set()  # places robots have left, their bodies still over them
        mode = self.mode.tolist()
        for i in range(len(xy)):
            node = int(self.node[i])
            mine = self.held[i] if mode[i] == STAND else [*self.held[i], node]
            for u in mine:
                held[u] = i if held.get(u, i) == i else -1
            if mode[i] == MOVE or mode[i] == STAND:
                leaving.update(u for u in self.held[i] if u != node)
        at = {int(i): int(self.node[i]) for i in standing}
        occupied = set(at.values())
        for u in occupied:
            held.pop(u, None)
        goal_node = self.goal_node

        def rank(robot: int, u: int) -> tuple[float, ...]:
            here = at[robot]
            if goal_node[robot] < 0:  # no goal: keep to its place, make way when asked
                return (0.0 if u == here else 1.0, float(u in occupied), float(u))
            hops = float(self._hops(int(goal_node[robot]))[u])
            # among equally short ways: a free place, then straight on (a turn is a stop)
            heading = rm.xy[here] - rm.xy[self.came_from[robot]]
            turn = float(u != here and float(np.dot(heading, rm.xy[u] - rm.xy[here])) <= 0.0)
            return (hops, float(u in occupied and u != here), turn, float(u))

        pibt = Pibt(at, rm.neighbours, rank, held, leaving)
        self._keep_for_returning(pibt)
        order = self._order(standing, active, progress_ns, now_ns)
        for i in order:
            if i in pibt.nxt:
                continue
            if goal_node[i] == self.node[i]:
                self._approach(pibt, i)
            else:
                pibt.move(i)
        for i, u in pibt.nxt.items():
            if self.mode[i] == APPROACH:
                continue
            here = int(self.node[i])
            if u != here:
                heading = rm.xy[here] - rm.xy[self.came_from[i]]
                step = rm.xy[u] - rm.xy[here]
                off = xy[i] - rm.xy[here]
                aside = abs(step[0] * off[1] - step[1] * off[0]) / rm.spacing_m
                turn = self.came_from[i] == here or not np.allclose(heading, step)
                if turn or aside > VIA_M:
                    # a turn, or a robot off the line (after settling): through the centre,
                    # no corner cut (a cut corner passes within reach of the next place)
                    self.via[i] = rm.xy[here]
                # the places its body still covers stay held (as after a goal's approach)
                under = [
                    v
                    for v in self.held[i]
                    if v != here and np.hypot(*(xy[i] - rm.xy[v])) < RELEASE_M
                ]
                self.held[i] = [here, *under]
                self.came_from[i] = here
                self.node[i] = u
                self.mode[i] = MOVE
            self.aim[i] = rm.xy[u]
        drive = np.where(np.isnan(self.via), self.aim, self.via)
        # a robot whose next place another robot's body still covers waits on its own
        owner = {u: j for j in range(len(xy)) for u in self.held[j]}
        for i in np.flatnonzero(self.mode == MOVE).tolist():
            j = owner.get(int(self.node[i]))
            if j is not None and j != i:
                drive[i] = rm.xy[self.came_from[i]]
        return drive, self._remaining(xy, active)

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

    def _order(
        self, standing: IntArray, active: BoolArray, progress_ns: IntArray, now_ns: int
    ) -> list[int]:
        """Robots standing on a place, first to plan first.

        Stalled for :data:`URGENT_S` (longest first), then by the goal's age, then those
        without a goal.
        """
        with_goal = standing[active[standing] & (self.goal_node[standing] >= 0)]
        stalled = now_ns - progress_ns[with_goal] >= s_to_ns(URGENT_S)
        first = np.where(stalled, progress_ns[with_goal], now_ns)
        there = self.goal_node[with_goal] == self.node[with_goal]
        order: list[int] = with_goal[
            np.lexsort((with_goal, self.since_ns[with_goal], first, ~there))
        ].tolist()
        planned = set(order)
        return order + [int(i) for i in standing.tolist() if int(i) not in planned]

    def _release(self, xy: FloatArray) -> None:
        """Let go of the places a robot's body has left (all but its own place)."""
        rm = self.roadmap
        for i in range(len(xy)):
            if not self.held[i] or self.mode[i] == APPROACH:
                continue
            keep = [
                u
                for u in self.held[i]
                if u == self.node[i] or np.hypot(*(xy[i] - rm.xy[u])) < RELEASE_M
            ]
            self.held[i] = keep

    def _approach(self, pibt: Pibt, i: int) -> None:
        """Robot ``i`` on its goal's place claims what its body touches at the goal."""
        here = int(self.node[i])
        touched = self._touched(self.goal[i], here)
        if not all(pibt.free(u, i) or u == here for u in touched):
            pibt.move(i)  # a robot drives through: wait (or make way) this step
            if pibt.nxt.get(i) == here:  # it waits: no one else moves in meanwhile
                self._keep(pibt, i, touched)
            return
        pibt.claim(i, here)
        pibt.nxt[i] = here
        others = [pibt.occupant(u) for u in touched[1:]]
        pushed = [o for o in others if o is not None]
        for u, other in zip(touched[1:], others, strict=True):
            if other is not None or not pushed:  # the free ones stay a way out for them
                pibt.claim(i, u)
        for other in pushed:  # ask them to make way: the approach starts once they left
            pibt.move(other, i)
        for u in touched[1:]:
            if pibt.claimed.get(u) == i:
                del pibt.claimed[u]
        if pushed:
            # one with no way out but through this place: it goes first
            stuck = [o for o in pushed if pibt.nxt.get(o) == pibt.at[o]]
            if stuck:
                pibt.let_through(i, stuck[0])
                self.returning[i] = pibt.nxt.get(i) != here
            else:
                self._keep(pibt, i, touched)
            return
        self.mode[i] = APPROACH
        self.held[i] = touched
        self.aim[i] = self.goal[i]
        self.via[i] = self.roadmap.xy[here]

    def _keep_for_returning(self, pibt: Pibt) -> None:
        """Robots that let a robot through off their goal's place keep what they need there.

        As while waiting on the place (:meth:`_keep`): the places its approach touches are
        claimed as they come free, so the next robot in the stream does not move in
        while it comes back. Only while it is one step from the place; standing on it
        again, it approaches or waits as any robot there.
        """
        for i in np.flatnonzero(self.returning).tolist():
            goal = int(self.goal_node[i])
            back = self.node[i] == goal and self.mode[i] == STAND
            if back or goal < 0 or self._hops(goal)[self.node[i]] > 1:
                self.returning[i] = False
                continue
            self._keep(pibt, i, self._touched(self.goal[i], goal))

    @staticmethod
    def _keep(pibt: Pibt, i: int, touched: list[int]) -> None:
        """Robot ``i``, waiting on its goal's place, keeps the free places it needs."""
        for u in touched[1:]:
            if pibt.free(u, i) and pibt.occupant(u) is None:
                pibt.claim(i, u)

    def _remaining(self, xy: FloatArray, active: BoolArray) -> FloatArray:
        """Way left to each goal (m), 0 for robots without one (see :meth:`_ways`)."""
        out = np.zeros(len(xy))
        going = np.flatnonzero(active & (self.goal_node >= 0))
        if len(going):
            out[going] = self._ways(xy[going], going)
        return out

    def _ways(self, xy: FloatArray, robots: IntArray) -> FloatArray:
        """Way left (m) of ``robots`` standing at ``xy`` (a row each).

        To the next place, along the places, to the goal; straight to the goal while
        approaching it.
        """
        rm = self.roadmap
        goal_node = self.goal_node[robots]
        hops = np.array(
            [self._hops(int(g))[u] for g, u in zip(goal_node, self.node[robots], strict=True)],
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
