"""Priority Inheritance with Backtracking (PIBT): one step of many robots on a roadmap.

After Okumura, Machida, Défago and Tamura, "Priority inheritance with backtracking for
iterative multi-agent path finding", Artificial Intelligence 310 (2022) (IJCAI 2019).
Robots, highest priority first, each pick the neighbouring node (or their own) nearest
their goal that no one has claimed for the next step. A robot that picks a node where a
lower-priority robot stands lends it its priority: that robot must move away first (to
anywhere but the asker's node, so no two robots swap), and if it cannot, the asker tries
its next choice. With priorities that grow while a robot has not reached its goal, the
highest-priority robot always moves nearer, and so each robot in turn reaches its goal
on a roadmap where every node lies on a cycle (the paper's Theorem 1).

Here the step is taken asynchronously, for the robots that stand on a node; robots
still driving between two nodes hold both, and the step plans round them. A robot does
not move onto the node of a robot planned before it (that could close a cycle of robots
each waiting for the next to leave): it only follows robots it asked to make way.
Usage: build one :class:`Pibt` per step and call :meth:`Pibt.move` for each robot in
priority order that is not in :attr:`Pibt.nxt` yet.
"""

from __future__ import annotations

from collections.abc import Callable, Collection, Mapping

from models.arrays import IntArray

DETOUR = 5
"""Steps longer than its best way that a robot asked to make way behind a robot driving off
will not take (see ``leaving`` in :class:`Pibt`)."""


class Pibt:
    """One PIBT step, robot by robot.

    Args:
        at: node each robot to be planned stands on.
        neighbours: (m, 4) neighbouring nodes of every node, -1 where there is none.
        rank: ``rank(robot, node)``: sort key of a candidate node for a robot (lower is
            better: hops to its goal first).
        held: nodes held by robots between two nodes, and by whom (-1: by several): no
            one else may move to them this step; their holder may go back.
        leaving: held nodes whose holder is driving off them (free in a moment). A robot
            asked to make way whose best node is one of them does not take a way longer
            than five steps more (the first element of ``rank``; round the block is
            20-30 steps in fleet50): it follows the robot leaving instead, and the asker
            tries its next choice. (One step more, robots kept in line behind robots
            leaving gave up 6 goals in fleet50, 20 seeds x 300 s, against 2 without.)

    Attributes:
        claimed: nodes claimed for the next step (node -> robot).
        nxt: the next node of every robot planned so far (its own when it stays).
    """

    def __init__(
        self,
        at: Mapping[int, int],
        neighbours: IntArray,
        rank: Callable[[int, int], tuple[float, ...]],
        held: Mapping[int, int],
        leaving: Collection[int] = (),
    ) -> None:
        self.at = at
        self.neighbours = neighbours
        self.rank = rank
        self.held = held
        self.leaving = leaving
        self.claimed: dict[int, int] = {}
        self.nxt: dict[int, int] = {}
        self.standing = {v: r for r, v in at.items()}

    def free(self, node: int, robot: int = -1) -> bool:
        """Whether no one (but ``robot``) holds ``node``, and no one has claimed it."""
        return node not in self.claimed and self.held.get(node, robot) == robot

    def claim(self, robot: int, node: int) -> None:
        """Claim ``node`` for ``robot`` outside the search (a final approach)."""
        self.claimed[node] = robot

    def occupant(self, node: int) -> int | None:
        """The robot standing on ``node`` that has not been planned yet, if any."""
        other = self.standing.get(node)
        return None if other is None or other in self.nxt else other

    def let_through(self, robot: int, other: int) -> None:
        """Plan ``robot`` and ``other`` again, ``other`` first: ``robot`` gives way.

        For a robot whose plan left ``other`` with no way on (a robot waiting to drive off
        its place onto its goal, whose neighbour can only leave through its place):
        ``other`` may now ask ``robot`` to make way. Their claims are dropped first.

        Raises:
            ValueError: unless both are planned to stay where they stand (a robot that
                leaves may have a follower, whose step would no longer hold).
        """
        if any(self.nxt.get(r) != self.at[r] for r in (robot, other)):
            raise ValueError(f"robots {robot} and {other} must both be planned to stay")
        for node, owner in list(self.claimed.items()):
            if owner in (robot, other):
                del self.claimed[node]
        self.nxt.pop(robot, None)
        self.nxt.pop(other, None)
        self.move(other)
        if robot not in self.nxt:
            self.move(robot)

    def _take(self, robot: int, node: int) -> None:
        old = self.nxt.get(robot)
        if old is not None and self.claimed.get(old) == robot:
            del self.claimed[old]
        self.nxt[robot] = node
        self.claimed[node] = robot

    def move(self, robot: int, asker: int | None = None) -> bool:
        """Plan ``robot``'s next node; False when it has to stay where it stands.

        Args:
            robot: a robot in ``at`` not planned yet.
            asker: the robot that needs ``robot``'s node, if any (``robot`` will not move
                onto the asker's node).
        """
        here = self.at[robot]
        options = [here] + [int(u) for u in self.neighbours[here] if u >= 0]
        options.sort(key=lambda u: self.rank(robot, u))
        # asked to make way while the robot ahead drives off its best node: no detour
        best = self.rank(robot, options[0])[0] if options[0] in self.leaving else None
        for u in options:
            if not self.free(u, robot):
                continue
            if asker is not None and best is not None and self.rank(robot, u)[0] > best + DETOUR:
                break
            if asker is not None and u == self.at.get(asker):
                continue  # no swaps
            other = self.standing.get(u)
            if other is not None and other != robot and other in self.nxt:
                continue  # planned already: following it could close a cycle
            self._take(robot, u)
            if other is None or other == robot or self.move(other, robot):
                return True
            # it could not make way: it stays, and ``u`` is its
        self._take(robot, here)
        return False
