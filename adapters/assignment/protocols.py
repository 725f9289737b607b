"""cosim's own assignment protocols, registered in ``cosim.protocols`` as a plugin's are.

- ``distributed_simplex``: distributed simplex (Buerger, Notarstefano, Bullo, Allgoewer
  2012), the protocol of ChoiRbot and VirTooS: robots exchange bases and halt together;
- ``cbba``: a consensus-based auction (CBBA with one task per robot, Choi, Brunet, How 2009);
- ``greedy``: each robot takes the nearest task nobody has claimed, exchanging nothing;
- ``hungarian``: the centralized optimum (Kuhn's Hungarian method, scipy) on the base station.

Each agent (``SimplexProtocol``, ...) belongs to one robot and one epoch (one assignment
problem); see :mod:`adapters.assignment.contract` for what a protocol and its agents do.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any, ClassVar

import numpy as np

from adapters.assignment.contract import EpochView, ProtocolAgent, ProtocolBase, ProtocolFleet
from adapters.assignment.topics import BASES, BIDS
from cosim.core.messages import CbbaBids, Message, SimplexBasis, TaskInfo
from cosim.core.summary import SummaryKey
from models.assignment.cbba import CbbaAgent, scores_from_cost
from models.assignment.dsimplex import SharedBasis, agent_for
from models.assignment.greedy import nearest_free
from models.assignment.problem import AssignmentProblem, hungarian


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
    """CBBA, one task per robot (Choi, Brunet, How 2009), with bids = reward - cost.

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
        self.agent = CbbaAgent(robot, scores[robot], len(problem.robots))

    def round(self, inbox: list[Message], now_ns: int) -> tuple[Message | None, bool]:
        """Bid, then reach consensus on the winners with the neighbours' views."""
        received = [
            (np.asarray(m.bids, dtype=float), np.asarray(m.winners, dtype=np.int64))
            for m in inbox
            if isinstance(m, CbbaBids) and m.epoch == self.epoch
        ]
        changed = self.agent.bid()
        changed = self.agent.consensus(received) or changed
        y, z = self.agent.message()
        message = CbbaBids(
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


class DistributedSimplex(ProtocolBase):
    """Distributed simplex (Buerger et al. 2012, as in ChoiRbot): robots exchange LP bases."""

    name: ClassVar[str] = "distributed_simplex"
    message: ClassVar[type[Message] | None] = SimplexBasis
    topic: ClassVar[str | None] = BASES
    compare_to_optimum: ClassVar[bool] = True

    def __init__(self, fleet: ProtocolFleet) -> None:
        super().__init__(fleet)
        # one decoder for the fleet: a sender's wire basis is laid out once for all receivers
        self.decoder = BasisDecoder()

    def agent(self, epoch: EpochView) -> ProtocolAgent:
        """A simplex agent on the robot's own columns."""
        return SimplexProtocol(
            epoch.problem, epoch.robot, epoch.name, epoch.epoch, self.fleet.diameter, self.decoder
        )


class Cbba(ProtocolBase):
    """CBBA, one task per robot (Choi, Brunet, How 2009): robots exchange their bids."""

    name: ClassVar[str] = "cbba"
    message: ClassVar[type[Message] | None] = CbbaBids
    topic: ClassVar[str | None] = BIDS
    compare_to_optimum: ClassVar[bool] = True

    def __init__(self, fleet: ProtocolFleet) -> None:
        super().__init__(fleet)
        # a common bid reward above any travel cost in the hall (paths included)
        width, height = fleet.hall_size_m
        self.reward_m = 10.0 * float(math.hypot(width, height))

    def agent(self, epoch: EpochView) -> ProtocolAgent:
        """An auction agent bidding reward minus cost."""
        return CbbaProtocol(
            epoch.problem, epoch.robot, epoch.name, epoch.epoch, self.fleet.diameter, self.reward_m
        )


class Greedy(ProtocolBase):
    """Nearest free task: each robot decides alone from the claims it has heard of."""

    name: ClassVar[str] = "greedy"

    def agent(self, epoch: EpochView) -> ProtocolAgent:
        """The robot's nearest task that nobody else holds or claims."""
        return GreedyProtocol(epoch.problem, epoch.robot, set(epoch.taken))


class Hungarian(ProtocolBase):
    """Centralized optimum on the base station (Hungarian method) from reported poses."""

    name: ClassVar[str] = "hungarian"
    central: ClassVar[bool] = True
    summary_keys: ClassVar[Mapping[str, SummaryKey]] = {
        "optimality_gap": SummaryKey(
            "ratio", "0: the base station solves each instance to its optimum"
        ),
    }

    def agent(self, epoch: EpochView) -> ProtocolAgent | None:
        """None: orders come from the base station."""
        return None

    def orders(
        self, tasks: Sequence[TaskInfo], poses: Mapping[str, tuple[float, float]]
    ) -> dict[str, tuple[int, float]]:
        """The optimum of straight-line costs among eligible pairs; -1 for robots left over."""
        robots = list(poses)
        if not robots or not tasks:
            return {}
        cost = np.full((len(robots), len(tasks)), np.inf)
        for i, robot in enumerate(robots):
            x, y = poses[robot]
            for j, task in enumerate(tasks):
                if robot in task.eligible:
                    cost[i, j] = float(np.hypot(task.x_m - x, task.y_m - y))
        problem = AssignmentProblem(tuple(robots), tuple(t.task_id for t in tasks), cost)
        assignment, _ = hungarian(problem)
        found = {}
        for i, robot in enumerate(robots):
            chosen = assignment.get(i)
            found[robot] = (
                (tasks[chosen].task_id, float(cost[i, chosen])) if chosen is not None else (-1, 0.0)
            )
        return found

    def summary(self) -> Mapping[str, Any]:
        """The base station's instance is solved to its optimum: no gap by construction."""
        return {"optimality_gap": 0.0}
