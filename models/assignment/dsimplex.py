"""The distributed simplex of Bürger, Notarstefano, Bullo and Allgöwer (Automatica, 2012).

Each agent owns some columns of the assignment LP (its robots' pair and idle columns) and
knows every big-M "unserved" column. It keeps one basis, starting from the identity basis.
In a round it receives its neighbours' bases, solves the LP restricted to its own columns,
its basis and the received bases with the lexicographic simplex
(:mod:`models.assignment.simplex`), and keeps the lexicographically optimal basis. The
lexicographic objective never increases along a round and the optimum of a column set is
unique, so the agents' bases converge in finite time to the one optimal basis of the whole
LP; an agent halts once its basis has not changed for ``2 * diameter_bound + 1``
consecutive rounds, which by the paper's Theorem (the stopping rule) means every agent
holds the optimal basis.

:class:`SimplexAgent` is the per-agent state machine (no time, no messages: the caller
moves bases between agents, tagged with :attr:`SimplexAgent.epoch`, and drops bases of
another epoch). :func:`run_synchronous` runs agents in lock step over a fixed graph, for
tests and benchmarks.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Iterator, Sequence
from typing import NamedTuple, overload

import numpy as np

from models.assignment.problem import (
    KINDS,
    AssignmentProblem,
    Column,
    ColumnKind,
    LpShape,
    identity_basis,
    unserved_columns,
)
from models.assignment.simplex import (
    RankedColumns,
    columns_of,
    ranked,
    ranked_rows,
    rows_of,
    solve_ranked,
    union,
)
from models.errors import ModelError
from models.network.topology import hops_from

Row = tuple[int, int, int, float]
"""A column in its wire form: ``(kind value, robot index, task index, cost)``."""


class SharedBasis(Sequence[Column]):
    """A basis as a neighbour sent it, merged by every agent that received it.

    Its m columns, and their ranks and costs (:meth:`ranked_in`) built on first use: 49
    agents merging one basis lay it out once instead of 49 times. A basis made
    :meth:`from_rows` (its wire form) builds its :class:`Column` objects only if they are
    read: merging never reads them. Do not build one from columns or rows that may change
    (tuples of tuples never do).
    """

    __slots__ = ("_columns", "_ranked", "_rows")

    def __init__(self, columns: Iterable[Column] = ()) -> None:
        self._columns: tuple[Column, ...] | None = tuple(columns)
        self._rows: Sequence[Row] = ()
        self._ranked: tuple[LpShape, RankedColumns] | None = None

    @classmethod
    def from_rows(cls, rows: Sequence[Row]) -> SharedBasis:
        """The basis of ``(kind, robot, task, cost)`` rows: its wire form, read lazily.

        Rows that are not columns are refused when the basis is first read or laid out.
        """
        basis = cls()
        basis._columns = None
        basis._rows = rows
        return basis

    @property
    def columns(self) -> tuple[Column, ...]:
        """The columns, in the order sent.

        Raises:
            ModelError: ``columns`` for a row that is not a column (its kind no
                :class:`ColumnKind` value, or not four fields).
        """
        if self._columns is None:
            try:
                self._columns = tuple(Column(KINDS[k], r, t, c) for k, r, t, c in self._rows)
            except (KeyError, TypeError, ValueError):
                raise ModelError(
                    "columns", self._rows, "rows (kind 0-2, robot, task, cost)"
                ) from None
        return self._columns

    def __len__(self) -> int:
        return len(self._rows) if self._columns is None else len(self._columns)

    @overload
    def __getitem__(self, index: int) -> Column: ...

    @overload
    def __getitem__(self, index: slice) -> tuple[Column, ...]: ...

    def __getitem__(self, index: int | slice) -> Column | tuple[Column, ...]:
        return self.columns[index]

    def __iter__(self) -> Iterator[Column]:
        return iter(self.columns)

    def __eq__(self, other: object) -> bool:
        if isinstance(other, SharedBasis | tuple | list):
            return self.columns == tuple(other)
        return NotImplemented

    __hash__ = None  # type: ignore[assignment]  # equal to tuples and lists, like a list

    def __repr__(self) -> str:
        return f"SharedBasis({list(self)!r})"

    def ranked_in(self, shape: LpShape) -> RankedColumns:
        """The columns' ranks and costs in an LP of ``shape`` (computed once per shape).

        Raises:
            ModelError: ``columns`` for a row that is not a column, a column out of range
                or a cost that is not finite.
        """
        known = self._ranked
        if known is not None and (known[0] is shape or known[0] == shape):
            return known[1]
        fast = None
        if self._columns is None:
            try:
                fast = ranked_rows(shape, np.array(self._rows, dtype=np.float64))
            except (TypeError, ValueError):
                fast = None  # not rows of four numbers: reading the columns says why
        laid_out = fast if fast is not None else ranked(shape, self.columns, "columns")
        self._ranked = (shape, laid_out)
        return laid_out


class SimplexAgent:
    """One agent of the distributed simplex.

    Args:
        shape: the LP's rows (numbers of robots and tasks), known to every agent.
        own_columns: the columns this agent owns (pairs and idle columns of its robots).
        diameter_bound: an upper bound on the communication graph's diameter (hops, >= 0).
        epoch: the task-set version this agent solves; bases of another epoch must not be
            handed to :meth:`merge_and_solve`.
        unserved_cost: the big-M cost of the unserved columns.

    Attributes:
        rounds: rounds run so far.
        unchanged: consecutive rounds, up to the last, in which the basis did not change.
        pivots: pivots of the last round's solve.
        solved: whether the last round ran the simplex; it is skipped when every
            candidate column was already a candidate of the last solve (the basis, optimal
            over that set, is optimal over any subset of it that holds it).

    Raises:
        ModelError: ``assignment.diameter_bound`` when negative.
    """

    def __init__(
        self,
        shape: LpShape,
        own_columns: Iterable[Column],
        diameter_bound: int,
        epoch: int,
        *,
        unserved_cost: float,
    ) -> None:
        if diameter_bound < 0:
            raise ModelError("assignment.diameter_bound", diameter_bound, "a hop count >= 0")
        self.shape = shape
        self.diameter_bound = diameter_bound
        self.epoch = epoch
        self._known = tuple(sorted(set(own_columns).union(unserved_columns(shape, unserved_cost))))
        self._known_ranked = union(shape, [ranked(shape, self._known, "own_columns")])
        start = identity_basis(shape, unserved_cost)
        self._basis: list[Column] | None = start
        self._ranked = ranked(shape, start, "start_basis")  # key order: idle, then unserved
        m = shape.rows
        # [x_B | B^-1 | 0] of the identity basis, rows in key order
        self._table = np.hstack([np.ones((m, 1)), np.eye(m), np.zeros((m, 1))])
        self._candidates: RankedColumns | None = None
        self._shared: SharedBasis | None = None
        # received bases (by identity, held so that ids stay theirs) whose columns are all
        # candidates: a neighbour resends the same basis object until it changes
        self._merged: dict[int, Sequence[Column]] = {}
        self.solved = False
        self.rounds = 0
        self.unchanged = 0
        self.pivots = 0

    @property
    def own_columns(self) -> tuple[Column, ...]:
        """The columns this agent always keeps: its own and the unserved ones, in key order."""
        return self._known

    @property
    def basis(self) -> list[Column]:
        """The current basis, m columns in key order (a copy); first the identity basis."""
        if self._basis is None:
            self._basis = columns_of(self.shape, self._ranked)
        return list(self._basis)

    def shared_basis(self) -> SharedBasis:
        """The current basis as a :class:`SharedBasis`, to send to the neighbours.

        The same object until the basis changes, laid out already: a receiver reads its
        ranks, and skips a round in which nothing it received is new.
        """
        shared = self._shared
        if shared is None:
            shared = SharedBasis.from_rows(self.basis_rows())
            shared._ranked = (self.shape, self._ranked)
            self._shared = shared
        return shared

    def basis_rows(self) -> tuple[Row, ...]:
        """The current basis in its wire form, ``(kind, robot, task, cost)`` rows, key order."""
        return tuple(rows_of(self.shape, self._ranked))

    @property
    def converged(self) -> bool:
        """Halted: the basis has not changed for ``2 * diameter_bound + 1`` rounds."""
        return self.unchanged >= 2 * self.diameter_bound + 1

    def merge_and_solve(self, received: Sequence[Sequence[Column]]) -> bool:
        """One round: solve over own columns, own basis and the received bases.

        Received bases overlap; columns are merged by key (one key with two costs is an
        error). Calling this after :attr:`converged` is harmless: the basis stays.

        Args:
            received: the neighbours' bases of this epoch, each m columns. A sequence
                passed again (the same object) is taken to be unchanged and not read again
                when it was merged before (wire bases are decoded once and shared).

        Returns:
            Whether the basis changed.

        Raises:
            ModelError: ``received`` when a basis does not have m columns; see also
                :func:`models.assignment.simplex.lex_simplex`.
        """
        m = self.shape.rows
        for basis in received:
            if len(basis) != m:
                raise ModelError("received", len(basis), f"bases of {m} columns")
        self.rounds += 1
        merged = self._merged
        # The basis is lexicographically optimal over the last candidate set, which held
        # it; over a subset that still holds it, it stays optimal: no need to solve. Own
        # columns and the basis are candidates since the first solve; bases received before
        # whose columns were all candidates still are (the set only changes on a solve).
        if self._candidates is not None and all(merged.get(id(b)) is b for b in received):
            self.solved = False
            self.pivots = 0
            self.unchanged += 1
            return False
        # ranks and costs: a received basis's arrays are built once for every agent that
        # merges it (SharedBasis); plain sequences overlap, and are laid out once together
        shape = self.shape
        parts = [self._known_ranked, self._ranked]
        parts += [b.ranked_in(shape) for b in received if isinstance(b, SharedBasis)]
        plain = [b for b in received if not isinstance(b, SharedBasis)]
        if plain:
            parts.append(ranked(shape, list(set().union(*plain)), "columns"))
        columns = union(shape, parts)
        self.solved = not _within(columns, self._candidates)
        if not self.solved:
            merged.update((id(b), b) for b in received)
            self.pivots = 0
            self.unchanged += 1
            return False
        self._candidates = columns
        self._merged = {id(b): b for b in received}
        solution = solve_ranked(shape, columns, self._ranked, self._table)
        best = solution.basis
        changed = not (
            np.array_equal(best.rank, self._ranked.rank)
            and np.array_equal(best.cost, self._ranked.cost)
        )
        if changed:
            self._ranked = best
            self._basis = None
            self._shared = None
        self._table = solution.table
        self.pivots = solution.pivots
        self.unchanged = 0 if changed else self.unchanged + 1
        return changed

    def assignment(self) -> dict[int, int]:
        """Robot index -> task index of the current basis (pair columns at value 1)."""
        return {c.robot: c.task for c in self._at_one() if c.kind is ColumnKind.PAIR}

    def objective(self) -> float:
        """The LP objective of the current basis: the exact sum of the costs at value 1.

        A basis also holds degenerate columns at value 0 (an unserved column among them
        would add a big-M), so summing the costs of all basic columns is wrong.
        """
        return math.fsum(self._ranked.cost[self._table[:, 0] > 0.5].tolist())

    def _at_one(self) -> list[Column]:
        """The basic columns at value 1 (``x_B = B^-1 1``, integral), in key order."""
        values = self._table[:, 0].tolist()
        return [c for c, v in zip(self.basis, values, strict=True) if v > 0.5]


def _within(columns: RankedColumns, candidates: RankedColumns | None) -> bool:
    """Whether every column (rank and cost) of ``columns`` is one of ``candidates``."""
    if candidates is None or columns.rank.size > candidates.rank.size:
        return False
    at = np.minimum(np.searchsorted(candidates.rank, columns.rank), candidates.rank.size - 1)
    return bool(
        np.all(candidates.rank[at] == columns.rank) and np.all(candidates.cost[at] == columns.cost)
    )


def agent_for(
    problem: AssignmentProblem, robots: Iterable[int], diameter_bound: int, epoch: int = 0
) -> SimplexAgent:
    """The agent that owns the columns of ``robots`` (robot indices) in ``problem``."""
    own = [c for i in sorted(set(robots)) for c in problem.columns_of(i)]
    return SimplexAgent(
        problem.shape, own, diameter_bound, epoch, unserved_cost=problem.unserved_cost
    )


class SyncResult(NamedTuple):
    """The outcome of :func:`run_synchronous`.

    Attributes:
        rounds: rounds until every agent had halted.
        bases: each agent's final basis (key order), by agent index.
        assignment: robot index -> task index read from agent 0's final basis.
        halted_at: the round in which each agent halted.
        last_change: the last round in which some agent's basis changed (0 if none).
        max_pivots: the most pivots one agent needed in one round.
    """

    rounds: int
    bases: tuple[tuple[Column, ...], ...]
    assignment: dict[int, int]
    halted_at: tuple[int, ...]
    last_change: int
    max_pivots: int


def run_synchronous(
    problem: AssignmentProblem,
    owner: Sequence[int],
    edges: Iterable[tuple[int, int]],
    diameter_bound: int | None = None,
    *,
    max_rounds: int = 10_000,
) -> SyncResult:
    """Run the distributed simplex in lock step until every agent has halted.

    In round t every agent that has not halted receives its neighbours' bases of round
    t - 1 (halted agents keep sending theirs) and solves. Each agent sends its
    :meth:`SimplexAgent.shared_basis`, one object until its basis changes, as a sender's
    wire basis is decoded once on the network.

    Args:
        problem: the LP.
        owner: ``owner[i]`` is the agent index owning robot i; agents are 0..max(owner).
        edges: undirected links between agent indices.
        diameter_bound: the agents' diameter bound; default the graph's diameter.
        max_rounds: a guard against a bug: exceeding it raises.

    Raises:
        ModelError: ``assignment.owner`` (wrong length or negative), ``network.edges``
            (unknown agent, self-loop, disconnected graph), ``assignment.diameter_bound``
            (below the diameter).
        RuntimeError: not all agents halted within ``max_rounds``.
    """
    if len(owner) != len(problem.robots) or min(owner, default=0) < 0:
        raise ModelError("assignment.owner", list(owner), "one agent index >= 0 per robot")
    n_agents = max(owner) + 1
    adjacent = _adjacency(n_agents, edges)
    hops = graph_diameter(adjacent)
    bound = hops if diameter_bound is None else diameter_bound
    if bound < hops:
        raise ModelError("assignment.diameter_bound", bound, f">= the diameter {hops}")
    agents = [
        agent_for(problem, [i for i, o in enumerate(owner) if o == a], bound)
        for a in range(n_agents)
    ]
    halted_at = [0] * n_agents
    last_change = 0
    max_pivots = 0
    rounds = 0
    while not all(a.converged for a in agents):
        if rounds >= max_rounds:
            raise RuntimeError(f"distributed simplex did not halt in {max_rounds} rounds")
        rounds += 1
        sent = [a.shared_basis() for a in agents]
        for k, agent in enumerate(agents):
            if agent.converged:
                continue
            if agent.merge_and_solve([sent[j] for j in adjacent[k]]):
                last_change = rounds
            max_pivots = max(max_pivots, agent.pivots)
            if agent.converged:
                halted_at[k] = rounds
    return SyncResult(
        rounds=rounds,
        bases=tuple(tuple(a.basis) for a in agents),
        assignment=agents[0].assignment(),
        halted_at=tuple(halted_at),
        last_change=last_change,
        max_pivots=max_pivots,
    )


def graph_diameter(adjacent: Sequence[Sequence[int]]) -> int:
    """The largest hop count between two agents (BFS from each).

    Raises:
        ModelError: ``network.edges`` when the graph is not connected.
    """
    longest = 0
    for start in range(len(adjacent)):
        hops = hops_from(start, adjacent.__getitem__)
        if len(hops) < len(adjacent):
            raise ModelError("network.edges", "disconnected", "a connected graph of agents")
        longest = max(longest, max(hops.values()))
    return longest


def _adjacency(n_agents: int, edges: Iterable[tuple[int, int]]) -> list[list[int]]:
    """Sorted neighbour lists; each edge must join two different known agents."""
    adjacent: list[set[int]] = [set() for _ in range(n_agents)]
    for a, b in edges:
        if a == b or not (0 <= a < n_agents and 0 <= b < n_agents):
            raise ModelError("network.edges", (a, b), f"pairs of distinct agents 0..{n_agents - 1}")
        adjacent[a].add(b)
        adjacent[b].add(a)
    return [sorted(s) for s in adjacent]
