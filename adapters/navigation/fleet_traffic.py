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

from adapters.navigation.places import (
    APPROACH,
    ARRIVE_M,
    MOVE,
    RELEASE_M,
    SETTLE,
    STAND,
    VIA_M,
    FleetPlaces,
)
from cosim.core.timebase import s_to_ns
from models.arrays import BoolArray, FloatArray, IntArray
from models.navigation.pibt import Pibt

URGENT_S = 10.0
"""A robot with no progress for this long goes first (s). Goals given up as above (with
``RELEASE_M`` 0.73, ``ARRIVE_M`` 0.3): 3 s 22, 6 s 14, 10 s 11, 20 s 41; the goal's age
alone (PIBT's rule) 32; the time since progress alone 23."""


class FleetTraffic:
    """PIBT steps for the whole fleet over its places.

    Args:
        places: the fleet's places, holds and goals (stepped in place).
    """

    def __init__(self, places: FleetPlaces) -> None:
        self.places = places

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
        places = self.places
        rm = places.roadmap
        xy = poses[:, :2]
        passed = np.hypot(*(xy - places.via).T) < VIA_M
        places.via[passed] = np.nan
        gap = np.hypot(*(xy - places.aim).T)
        moving = (places.mode == MOVE) | (places.mode == SETTLE)
        landed = moving & np.isnan(places.via[:, 0]) & (gap <= ARRIVE_M)
        places.mode[landed] = STAND
        places.release(xy)
        standing = np.flatnonzero(places.mode == STAND)
        # held places and their holders (-1: several); a robot may go back to a place
        # only its own body still covers (it made way, or turns back)
        held: dict[int, int] = {}
        leaving: set[int] = set()  # places robots have left, their bodies still over them
        mode = places.mode.tolist()
        for i in range(len(xy)):
            node = int(places.node[i])
            mine = places.held[i] if mode[i] == STAND else [*places.held[i], node]
            for u in mine:
                held[u] = i if held.get(u, i) == i else -1
            if mode[i] == MOVE or mode[i] == STAND:
                leaving.update(u for u in places.held[i] if u != node)
        at = {int(i): int(places.node[i]) for i in standing}
        occupied = set(at.values())
        for u in occupied:
            held.pop(u, None)
        goal_node = places.goal_node

        def rank(robot: int, u: int) -> tuple[float, ...]:
            here = at[robot]
            if goal_node[robot] < 0:  # no goal: keep to its place, make way when asked
                return (0.0 if u == here else 1.0, float(u in occupied), float(u))
            hops = float(places.hops_to(int(goal_node[robot]))[u])
            # among equally short ways: a free place, then straight on (a turn is a stop)
            heading = rm.xy[here] - rm.xy[places.came_from[robot]]
            turn = float(u != here and float(np.dot(heading, rm.xy[u] - rm.xy[here])) <= 0.0)
            return (hops, float(u in occupied and u != here), turn, float(u))

        pibt = Pibt(at, rm.neighbours, rank, held, leaving)
        self._keep_for_returning(pibt)
        order = self._order(standing, active, progress_ns, now_ns)
        for i in order:
            if i in pibt.nxt:
                continue
            if goal_node[i] == places.node[i]:
                self._approach(pibt, i)
            else:
                pibt.move(i)
        for i, u in pibt.nxt.items():
            if places.mode[i] == APPROACH:
                continue
            here = int(places.node[i])
            if u != here:
                heading = rm.xy[here] - rm.xy[places.came_from[i]]
                step = rm.xy[u] - rm.xy[here]
                off = xy[i] - rm.xy[here]
                aside = abs(step[0] * off[1] - step[1] * off[0]) / rm.spacing_m
                turn = places.came_from[i] == here or not np.allclose(heading, step)
                if turn or aside > VIA_M:
                    # a turn, or a robot off the line (after settling): through the centre,
                    # no corner cut (a cut corner passes within reach of the next place)
                    places.via[i] = rm.xy[here]
                # the places its body still covers stay held (as after a goal's approach)
                under = [
                    v
                    for v in places.held[i]
                    if v != here and np.hypot(*(xy[i] - rm.xy[v])) < RELEASE_M
                ]
                places.held[i] = [here, *under]
                places.came_from[i] = here
                places.node[i] = u
                places.mode[i] = MOVE
            places.aim[i] = rm.xy[u]
        drive = np.where(np.isnan(places.via), places.aim, places.via)
        # a robot whose next place another robot's body still covers waits on its own
        owner = {u: j for j in range(len(xy)) for u in places.held[j]}
        for i in np.flatnonzero(places.mode == MOVE).tolist():
            j = owner.get(int(places.node[i]))
            if j is not None and j != i:
                drive[i] = rm.xy[places.came_from[i]]
        return drive, places.remaining(xy, active)

    def _order(
        self, standing: IntArray, active: BoolArray, progress_ns: IntArray, now_ns: int
    ) -> list[int]:
        """Robots standing on a place, first to plan first.

        Stalled for :data:`URGENT_S` (longest first), then by the goal's age, then those
        without a goal.
        """
        places = self.places
        with_goal = standing[active[standing] & (places.goal_node[standing] >= 0)]
        stalled = now_ns - progress_ns[with_goal] >= s_to_ns(URGENT_S)
        first = np.where(stalled, progress_ns[with_goal], now_ns)
        there = places.goal_node[with_goal] == places.node[with_goal]
        order: list[int] = with_goal[
            np.lexsort((with_goal, places.since_ns[with_goal], first, ~there))
        ].tolist()
        planned = set(order)
        return order + [int(i) for i in standing.tolist() if int(i) not in planned]

    def _approach(self, pibt: Pibt, i: int) -> None:
        """Robot ``i`` on its goal's place claims what its body touches at the goal."""
        places = self.places
        here = int(places.node[i])
        touched = places.touched(places.goal[i], here)
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
                places.returning[i] = pibt.nxt.get(i) != here
            else:
                self._keep(pibt, i, touched)
            return
        places.mode[i] = APPROACH
        places.held[i] = touched
        places.aim[i] = places.goal[i]
        places.via[i] = places.roadmap.xy[here]

    def _keep_for_returning(self, pibt: Pibt) -> None:
        """Robots that let a robot through off their goal's place keep what they need there.

        As while waiting on the place (:meth:`_keep`): the places its approach touches are
        claimed as they come free, so the next robot in the stream does not move in
        while it comes back. Only while it is one step from the place; standing on it
        again, it approaches or waits as any robot there.
        """
        places = self.places
        for i in np.flatnonzero(places.returning).tolist():
            goal = int(places.goal_node[i])
            back = places.node[i] == goal and places.mode[i] == STAND
            if back or goal < 0 or places.hops_to(goal)[places.node[i]] > 1:
                places.returning[i] = False
                continue
            self._keep(pibt, i, places.touched(places.goal[i], goal))

    @staticmethod
    def _keep(pibt: Pibt, i: int, touched: list[int]) -> None:
        """Robot ``i``, waiting on its goal's place, keeps the free places it needs."""
        for u in touched[1:]:
            if pibt.free(u, i) and pibt.occupant(u) is None:
                pibt.claim(i, u)
