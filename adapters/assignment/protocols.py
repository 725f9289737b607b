"""The assignment protocols a robot can run in an epoch, behind one small interface.

Each protocol instance belongs to one robot and one epoch (one assignment problem). Every
round it takes the protocol messages received since the last round and returns what to
broadcast; once it has *decided*, :meth:`task` is the task index it should serve (or
``None``). A decision may still change when late information arrives (the robot then
re-targets).
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from cosim.core.messages import AuctionBids, Message, SimplexBasis
from models.assignment.cbaa import CbaaAgent, scores_from_cost
from models.assignment.dsimplex import SharedBasis, agent_for
from models.assignment.greedy import nearest_free
from models.assignment.problem import AssignmentProblem


class BasisDecoder:
    """Wire bases turned into :class:`Column` tuples, once per sender and basis.

    A robot's basis message is delivered to each of its neighbours every round, and a
    sender keeps its wire tuple between basis changes: decoding it in every receiver every
    round built ~2.5 million columns a simulated second in ``fleet50`` (50 robots, 50 tasks,
    complete graph; 5 of 9 s of wall time). One decoder is shared by the fleet's protocols:
    a sender's tuple is decoded when it is a new object, and every receiver gets the same
    :class:`~models.assignment.dsimplex.SharedBasis` (a tuple, with its set of columns)
    until it changes.
    """

    def __init__(self) -> None:
        self._last: dict[str, tuple[tuple[tuple[int, int, int, float], ...], SharedBasis]] = {}

    def decode(self, message: SimplexBasis) -> SharedBasis:
        """The columns of ``message``'s basis (shared, immutable, with their set)."""
        known = self._last.get(message.robot)
        if known is not None and known[0] is message.columns:
            return known[1]
        columns = SharedBasis.from_rows(message.columns)
        self._last[message.robot] = (message.columns, columns)
        return columns


class AssignmentProtocol(Protocol):
    """One robot's side of an assignment protocol in one epoch."""

    def round(self, inbox: list[Message], now_ns: int) -> tuple[Message | None, bool]:
        """Run one round on the received messages; return (message to send, state changed)."""
        ...

    @property
    def decided(self) -> bool:
        """Whether the robot may act on :meth:`task`."""
        ...

    def task(self) -> int | None:
        """Index of the task this robot should serve, or None."""
        ...

    @property
    def rounds(self) -> int:
        """Rounds run so far."""
        ...

    def cost(self) -> float:
        """This robot's current view of the assignment objective (m + big-M terms)."""
        ...

    def view(self) -> dict[int, int]:
        """This robot's view of the whole assignment (robot index -> task index)."""
        ...


class SimplexProtocol:
    """Distributed simplex (Buerger et al. 2012): exchange bases, re-solve, halt."""

    def __init__(
        self,
        problem: AssignmentProblem,
        robot: int,
        name: str,
        epoch: int,
        diameter: int,
        decoder: BasisDecoder | None = None,
    ) -> None:
        self.problem = problem
        self.robot = robot
        self.name = name
        self.epoch = epoch
        self.agent = agent_for(problem, [robot], diameter, epoch)
        self.decoder = decoder if decoder is not None else BasisDecoder()
        self._columns: tuple[tuple[int, int, int, float], ...] | None = None

    def round(self, inbox: list[Message], now_ns: int) -> tuple[Message | None, bool]:
        """Merge neighbours' bases with own columns, re-solve, and send the basis."""
        received = [
            self.decoder.decode(m)
            for m in inbox
            if isinstance(m, SimplexBasis) and m.epoch == self.epoch
        ]
        changed = self.agent.merge_and_solve(received)
        # the basis only changes in merge_and_solve, which says so: its wire form is kept
        # between changes (most rounds of an epoch change nothing)
        if changed or self._columns is None:
            self._columns = self.agent.basis_rows()
        message = SimplexBasis(now_ns, self.epoch, self.name, self.agent.rounds, self._columns)
        return message, changed

    @property
    def decided(self) -> bool:
        """Halted: the basis did not change for 2 * diameter + 1 rounds."""
        return bool(self.agent.converged)

    def task(self) -> int | None:
        """This robot's task in the current basis."""
        return self.agent.assignment().get(self.robot)

    @property
    def rounds(self) -> int:
        """Rounds run so far."""
        return int(self.agent.rounds)

    def cost(self) -> float:
        """Objective of the current basis (columns at value 1)."""
        return float(self.agent.objective())

    def view(self) -> dict[int, int]:
        """The assignment of the current basis."""
        return dict(self.agent.assignment())


class CbbaProtocol:
    """Consensus-based auction (CBAA, Choi, Brunet, How 2009) with bids = reward - cost.

    Bids of different robots are compared, so the reward must be the same for everyone:
    a constant above any cost in the hall (``reward_m``), not derived from a robot's own row.
    """

    def __init__(
        self,
        problem: AssignmentProblem,
        robot: int,
        name: str,
        epoch: int,
        diameter: int,
        reward_m: float,
    ) -> None:
        self.problem = problem
        self.robot = robot
        self.name = name
        self.epoch = epoch
        self.diameter = diameter
        scores = scores_from_cost(problem.cost, reward_m)
        self.agent = CbaaAgent(robot, scores[robot], len(problem.robots))

    def round(self, inbox: list[Message], now_ns: int) -> tuple[Message | None, bool]:
        """Bid, then reach consensus on the winners with the neighbours' views."""
        received = [
            (np.asarray(m.bids, dtype=float), np.asarray(m.winners, dtype=np.int64))
            for m in inbox
            if isinstance(m, AuctionBids) and m.epoch == self.epoch
        ]
        changed = self.agent.bid()
        changed = self.agent.consensus(received) or changed
        y, z = self.agent.message()
        message = AuctionBids(
            now_ns, self.epoch, self.name, tuple(float(v) for v in y), tuple(int(v) for v in z)
        )
        return message, changed

    @property
    def decided(self) -> bool:
        """Nothing changed for diameter + 1 rounds."""
        return bool(self.agent.converged(self.diameter))

    def task(self) -> int | None:
        """The task this robot holds."""
        return self.agent.x

    @property
    def rounds(self) -> int:
        """Rounds run so far."""
        return int(self.agent.rounds)

    def cost(self) -> float:
        """Cost of the assignment this robot believes in (winners it knows)."""
        z = self.agent.z
        cost = self.problem.cost
        return float(sum(cost[int(r), j] for j, r in enumerate(z) if r >= 0))

    def view(self) -> dict[int, int]:
        """The winners this robot knows."""
        return {int(r): j for j, r in enumerate(self.agent.z) if r >= 0}


class GreedyProtocol:
    """Nearest free task: decides at once, from the claims this robot has heard of."""

    def __init__(self, problem: AssignmentProblem, robot: int, taken: set[int]) -> None:
        self.problem = problem
        self.robot = robot
        free = [j for j in range(len(problem.tasks)) if j not in taken]
        self.choice = nearest_free(problem.cost, free, robot)

    def round(self, inbox: list[Message], now_ns: int) -> tuple[Message | None, bool]:
        """No messages: the claims are the coordination."""
        return None, False

    @property
    def decided(self) -> bool:
        """Always."""
        return True

    def task(self) -> int | None:
        """The nearest free eligible task."""
        return self.choice

    @property
    def rounds(self) -> int:
        """No rounds."""
        return 0

    def cost(self) -> float:
        """This robot's cost for its choice."""
        return float(self.problem.cost[self.robot, self.choice]) if self.choice is not None else 0.0

    def view(self) -> dict[int, int]:
        """Only this robot's own choice."""
        return {self.robot: self.choice} if self.choice is not None else {}
