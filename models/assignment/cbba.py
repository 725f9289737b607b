"""CBBA with one task per robot: the consensus-based auction of single assignment.

Reference: H.-L. Choi, L. Brunet, J. P. How, "Consensus-Based Decentralized Auctions for
Robust Task Allocation", IEEE Trans. Robotics 25(4):912-926, 2009. With one task per robot
CBBA (Sec. IV, the bundle algorithm) is the single-assignment auction of Sec. III, which
the paper calls CBAA; cosim names it CBBA throughout, as its scenario key does
(``assignment.protocol = "cbba"``).

Each robot is an agent that repeats, in rounds, two phases:

1. **Auction (bid)**, the paper's Algorithm 1: an agent without a task bids on the task
   that maximizes its score among those it can still win, and records itself as winner.
2. **Consensus**, the paper's Algorithm 2: it receives the (bid, winner) lists of its
   neighbours, keeps per task the best pair, and releases its own task if it was outbid.

What is implemented, precisely:

- Scores are rewards: ``score[i, j] = reward - cost[i, j]`` with ``reward`` larger than
  every finite cost, so every eligible score is > 0; ineligible pairs never bid. The
  initial known bid is 0 with no winner (-1).
- Bids are compared as the pair (score, robot): the higher score wins, and between equal
  scores the **lower robot index** wins. An agent can win task j when its pair beats the
  known pair of j (the paper's ``c_ij > y_ij``, with this tie rule added). Among the tasks
  it can win it takes the highest score, ties to the **lowest task index**.
- Winners are tracked per task (``z``, as CBBA does) and consensus is the lexicographic
  max of (bid, winner) over the agent and its neighbours: the synchronous rule of the
  paper's Algorithm 2 with the winner carried along, which is also the CBBA "update"
  action for an agent that hears of a better bid. No time stamps are kept. None are
  needed in CBBA: a bid is never withdrawn, so the known pair of a task only grows, and
  the merge is a join (commutative, associative, idempotent). Messages that arrive late,
  twice or out of order therefore cannot undo newer information; they only delay it.
  (CBBA needs time stamps because releasing a bundle resets later bids; CBBA has no
  bundles.)

Properties (consistent scores: each agent's scores are fixed; Sec. III of the paper):

- The outcome is conflict-free and every agent agrees on the winners.
- The fixed point is the assignment of the sequential greedy algorithm (SGA): repeatedly
  take the best remaining (robot, task) score (the paper's Lemma 1, stated there for
  scores without ties; with the tie rules above the order of pairs is strict and the same
  argument applies). See :func:`sequential_greedy_auction`.
- With synchronous rounds over a static connected network of diameter D, it converges
  within ``N_min * D`` rounds, ``N_min = min(R, T)`` (the paper's Theorem 1).
- As a greedy matching, its total score is at least half of the optimal total score (the
  paper's 50 % worst-case guarantee). In total cost it is not optimal: the Hungarian
  method, or the distributed simplex, can do strictly better.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
import numpy.typing as npt

from models.arrays import FloatArray, IntArray
from models.assignment.greedy import Assignment, check_cost, greedy_global
from models.network.topology import hops_from

NO_WINNER = -1


class CbbaMessage(NamedTuple):
    """What an agent sends its neighbours: its known winning bids and winners.

    Attributes:
        y: (T,) the best bid known per task (score units; 0 when none).
        z: (T,) the robot that placed it (-1 when none).
    """

    y: FloatArray
    z: IntArray


class CbbaAgent:
    """One robot's CBBA state machine, without time or transport.

    A round is :meth:`bid` followed by :meth:`consensus` with the messages received in
    that round; :meth:`consensus` closes the round and updates :attr:`unchanged_rounds`.

    Args:
        robot: this agent's index in [0, n_robots).
        scores_row: (T,) this robot's scores; a finite score must be > 0, and ``nan`` or
            ``-inf`` marks a task the robot is not eligible for.
        n_robots: the number of robots (winner indices lie in [0, n_robots)).

    Attributes:
        robot: this agent's index.
        scores: (T,) the scores, ``-inf`` where ineligible.
        x: the task this agent holds, or ``None``.
        y: (T,) the best bid known per task (0 when none).
        z: (T,) the winner known per task (-1 when none).
        unchanged_rounds: consecutive closed rounds in which nothing changed.
        rounds: closed rounds so far.

    Raises:
        ValueError: for a robot index out of range, scores that are not 1-D, ``+inf`` or
            not > 0.
    """

    __slots__ = (
        "_bid_changed",
        "n_robots",
        "robot",
        "rounds",
        "scores",
        "unchanged_rounds",
        "x",
        "y",
        "z",
    )

    def __init__(self, robot: int, scores_row: npt.ArrayLike, n_robots: int) -> None:
        if not 0 <= robot < n_robots:
            raise ValueError(f"robot = {robot}: expected an index in [0, {n_robots})")
        row = np.asarray(scores_row, dtype=np.float64)
        if row.ndim != 1:
            raise ValueError(f"scores_row must be a (T,) array, got shape {row.shape}")
        eligible = np.isfinite(row)
        if np.isposinf(row).any() or (row[eligible] <= 0.0).any():
            raise ValueError(
                f"robot {robot}: scores must be finite and > 0, or nan/-inf when ineligible"
            )
        self.robot = robot
        self.n_robots = n_robots
        self.scores: FloatArray = np.where(eligible, row, -np.inf)
        self.x: int | None = None
        self.y: FloatArray = np.zeros(row.size)
        self.z: IntArray = np.full(row.size, NO_WINNER, dtype=np.int64)
        self.unchanged_rounds = 0
        self.rounds = 0
        self._bid_changed = False

    def _winner_rank(self, z: IntArray) -> IntArray:
        """Winner indices with "no winner" ranked after every robot."""
        return np.where(z < 0, self.n_robots, z)

    def bid(self) -> bool:
        """Auction phase: an agent without a task bids on the best task it can win.

        It can win task j when ``score[j] > y[j]``, or ``score[j] == y[j]`` and its index
        is lower than the known winner's. Among those it takes the highest score, ties to
        the lowest task index, and sets ``x``, ``y[j] = score[j]``, ``z[j] = robot``.

        Returns:
            Whether the state changed (a bid was placed).
        """
        if self.x is not None:
            return False
        s = self.scores
        winnable = (s > self.y) | ((s == self.y) & (self.robot < self._winner_rank(self.z)))
        if not winnable.any():
            return False
        task = int(np.argmax(np.where(winnable, s, -np.inf)))  # first maximum: lowest index
        self.x = task
        self.y[task] = s[task]
        self.z[task] = self.robot
        self._bid_changed = True
        return True

    def consensus(self, received: Sequence[tuple[FloatArray, IntArray]]) -> bool:
        """Consensus phase: merge the neighbours' (y, z) and release an outbid task.

        Per task, the kept pair is the best of this agent's and the received ones: the
        highest bid, and between equal bids the lowest winner index. If the kept winner of
        this agent's task is another robot, the agent releases it (``x = None``). This
        closes the round: :attr:`unchanged_rounds` is reset if the bid or this merge
        changed anything, and incremented otherwise.

        Args:
            received: the neighbours' messages ``(y, z)``, in any order.

        Returns:
            Whether this merge changed the state.

        Raises:
            ValueError: for a message of the wrong shape or with an unknown winner.
        """
        n_tasks = self.y.size
        ys = [self.y]
        zs = [self.z]
        for y, z in received:
            y_in = np.asarray(y, dtype=np.float64)
            z_in = np.asarray(z, dtype=np.int64)
            if y_in.shape != (n_tasks,) or z_in.shape != (n_tasks,):
                raise ValueError(
                    f"message shapes {y_in.shape}, {z_in.shape}: expected ({n_tasks},)"
                )
            if ((z_in < NO_WINNER) | (z_in >= self.n_robots)).any():
                raise ValueError(
                    f"message winners {z_in.tolist()}: expected -1 or [0, {self.n_robots})"
                )
            ys.append(y_in)
            zs.append(z_in)
        y_all = np.stack(ys)
        best_y = y_all.max(axis=0)
        rank = np.where(y_all == best_y, self._winner_rank(np.stack(zs)), self.n_robots).min(axis=0)
        best_z = np.where(rank == self.n_robots, NO_WINNER, rank)
        changed = not (np.array_equal(best_y, self.y) and np.array_equal(best_z, self.z))
        self.y, self.z = best_y, best_z
        if self.x is not None and self.z[self.x] != self.robot:
            self.x = None
            changed = True
        round_changed = changed or self._bid_changed
        self._bid_changed = False
        self.rounds += 1
        self.unchanged_rounds = 0 if round_changed else self.unchanged_rounds + 1
        return changed

    def message(self) -> CbbaMessage:
        """A copy of (y, z) to send to the neighbours."""
        return CbbaMessage(self.y.copy(), self.z.copy())

    def converged(self, diameter: int) -> bool:
        """Whether nothing changed for ``diameter + 1`` rounds (no news can still be on its way)."""
        return self.unchanged_rounds > diameter

    def assignment(self) -> Assignment:
        """The winners as this agent knows them: robot -> task, in robot order."""
        return dict(sorted((int(r), j) for j, r in enumerate(self.z.tolist()) if r != NO_WINNER))


@dataclass(frozen=True)
class CbbaResult:
    """The outcome of :func:`run_synchronous`.

    Attributes:
        rounds: the last round in which some agent's state changed (0 if none ever did):
            the convergence time, to compare with :attr:`bound`.
        rounds_run: the rounds executed, including the ``diameter + 1`` quiet rounds that
            show convergence.
        assignment: robot -> task, from each agent's own held task, in robot order.
        agents: the final per-agent states, in robot order.
        diameter: the communication graph's diameter (hops).
        bound: the paper's convergence bound ``min(R, T) * max(diameter, 1)`` (rounds).
    """

    rounds: int
    rounds_run: int
    assignment: Assignment
    agents: tuple[CbbaAgent, ...]
    diameter: int
    bound: int


def scores_from_cost(cost: npt.ArrayLike, reward: float | None = None) -> FloatArray:
    """The CBBA scores ``reward - cost``, ``-inf`` where the cost is ``inf``.

    Args:
        cost: (R, T) travel costs (m), ``inf`` where ineligible.
        reward: the reward of serving a task (m); must exceed every finite cost so that
            every eligible score is > 0. Default: the largest finite cost + 1.

    Raises:
        ValueError: for a malformed cost matrix or a reward not above every finite cost.
    """
    matrix = check_cost(cost)
    finite = np.isfinite(matrix)
    largest = float(matrix[finite].max()) if finite.any() else 0.0
    if reward is None:
        reward = largest + 1.0
    if not (np.isfinite(reward) and reward > largest):
        raise ValueError(
            f"reward = {reward}: expected a finite number > the largest cost {largest}"
        )
    return np.where(finite, reward - matrix, -np.inf)


def sequential_greedy_auction(scores: npt.ArrayLike) -> Assignment:
    """SGA: the best remaining (robot, task) score first, repeated; CBBA's fixed point.

    Pairs are taken by decreasing score, equal scores by increasing robot then task index
    (the tie rules of :class:`CbbaAgent`); ``nan``/``-inf`` pairs never.
    """
    s = np.asarray(scores, dtype=np.float64)
    return greedy_global(np.where(np.isfinite(s), -s, np.inf))


def convergence_bound(n_robots: int, n_tasks: int, diameter: int) -> int:
    """Theorem 1 of Choi et al. (2009): ``min(R, T) * D`` synchronous rounds.

    A single robot (D = 0) still needs one round to bid, hence ``max(D, 1)``.
    """
    return min(n_robots, n_tasks) * max(diameter, 1)


def graph_diameter(n_robots: int, edges: Iterable[tuple[int, int]]) -> tuple[list[list[int]], int]:
    """The sorted neighbour lists and the diameter (hops) of an undirected robot graph.

    Raises:
        ValueError: for an edge with an unknown robot or a self-loop, or a graph that is
            not connected (CBBA then cannot agree across the parts).
    """
    adjacent: list[set[int]] = [set() for _ in range(n_robots)]
    for a, b in edges:
        if not (0 <= a < n_robots and 0 <= b < n_robots) or a == b:
            raise ValueError(f"edge ({a}, {b}): expected two different robots in [0, {n_robots})")
        adjacent[a].add(b)
        adjacent[b].add(a)
    neighbours = [sorted(s) for s in adjacent]
    longest = 0
    for start in range(n_robots):
        hops = hops_from(start, neighbours.__getitem__)
        if len(hops) < n_robots:
            raise ValueError(
                f"the communication graph is not connected: robot {start} reaches"
                f" {len(hops)} of {n_robots}"
            )
        longest = max(longest, *hops.values())
    return neighbours, longest


def run_synchronous(
    cost: npt.ArrayLike,
    edges: Iterable[tuple[int, int]],
    *,
    reward: float | None = None,
) -> CbbaResult:
    """Run CBBA in lock-step rounds over a static undirected graph.

    In every round, every agent bids; then every agent sends its message and merges those
    of its neighbours, all messages being taken after the bids and before any merge (the
    paper's synchronous iteration). The run stops when no agent has changed for
    ``diameter + 1`` consecutive rounds.

    Args:
        cost: (R, T) travel costs (m), ``inf`` where ineligible.
        edges: undirected links as pairs of robot indices; the graph must be connected.
        reward: see :func:`scores_from_cost`.

    Returns:
        The rounds, the assignment and the final agents.

    Raises:
        ValueError: for a malformed cost, reward or graph.
        RuntimeError: if the run does not settle within its termination bound (a bug):
            every (robot, task) pair is bid at most once, so at most ``pairs + 1`` waves
            of ``D`` rounds can carry news.
    """
    scores = scores_from_cost(cost, reward)
    n_robots, n_tasks = scores.shape
    neighbours, diameter = graph_diameter(n_robots, edges)
    agents = tuple(CbbaAgent(i, scores[i], n_robots) for i in range(n_robots))
    hops = max(diameter, 1)
    cap = (int(np.isfinite(scores).sum()) + 1) * hops + diameter + 1
    last_change = 0
    rounds_run = 0
    while not all(agent.converged(diameter) for agent in agents):
        if rounds_run >= cap:
            raise RuntimeError(f"CBBA did not settle within {cap} rounds ({n_robots}x{n_tasks})")
        rounds_run += 1
        for agent in agents:
            agent.bid()
        messages = [agent.message() for agent in agents]
        for agent in agents:
            agent.consensus([messages[k] for k in neighbours[agent.robot]])
        if any(agent.unchanged_rounds == 0 for agent in agents):
            last_change = rounds_run
    assignment = {agent.robot: agent.x for agent in agents if agent.x is not None}
    return CbbaResult(
        rounds=last_change,
        rounds_run=rounds_run,
        assignment=assignment,
        agents=agents,
        diameter=diameter,
        bound=convergence_bound(n_robots, n_tasks, diameter),
    )
