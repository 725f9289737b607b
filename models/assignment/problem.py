"""The robot-task assignment problem as a standard-form linear program.

``min c^T x  s.t.  A x = b, x >= 0`` with ``m = R + T`` equality rows and ``b = 1``:
row ``i`` says robot ``i`` does at most one task, row ``R + j`` says task ``j`` is served at
most once. The columns, each a :class:`Column`:

* ``("x", i, j)`` (:attr:`ColumnKind.PAIR`) for every eligible pair: cost ``c_ij``, ones in
  rows ``i`` and ``R + j``; owned by robot ``i``;
* ``("idle", i)`` (:attr:`ColumnKind.IDLE`): cost 0, a one in row ``i`` (robot ``i`` stays
  idle); owned by robot ``i``;
* ``("unserved", j)`` (:attr:`ColumnKind.UNSERVED`): the big-M cost ``unserved_cost``, a one
  in row ``R + j``; known to every agent.

Idle and unserved columns form the identity basis every agent starts from, so the LP is
feasible for any eligibility mask and any ``R``, ``T``. The constraint matrix is the
incidence matrix of a bipartite graph next to an identity: it is totally unimodular, so
every basis has determinant +-1 and an integral inverse.

Columns are totally ordered by their key ``(kind, robot, task)``; robot and task indices
follow the global order of ``AssignmentProblem.robots`` and ``.tasks``, known to every
agent. This order is what makes the lexicographic simplex end in one basis everywhere.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from enum import IntEnum
from typing import NamedTuple

import numpy as np
import numpy.typing as npt
from scipy.optimize import linear_sum_assignment

from models.errors import ModelError

DEFAULT_UNSERVED_COST = 1e6
"""Default big-M cost of leaving a task unserved (cost units, e.g. metres of travel)."""

NO_INDEX = -1
"""The robot of an unserved column and the task of an idle column."""


class ColumnKind(IntEnum):
    """The kinds of LP columns, in the rank order of the global column order."""

    PAIR = 0
    """``("x", i, j)``: robot ``i`` serves task ``j``."""
    IDLE = 1
    """``("idle", i)``: robot ``i`` serves nothing."""
    UNSERVED = 2
    """``("unserved", j)``: nobody serves task ``j`` (big-M)."""


KINDS = {int(kind): kind for kind in ColumnKind}
"""Column kinds by value (wire form, rank digit): a dict lookup is ~10x cheaper than calling
the enum."""


class Column(NamedTuple):
    """One LP column. Tuples compare by key first; the key identifies the column.

    Attributes:
        kind: what the column stands for.
        robot: robot index (``NO_INDEX`` for an unserved column).
        task: task index into ``AssignmentProblem.tasks`` (``NO_INDEX`` for an idle column).
        cost: the objective coefficient.
    """

    kind: ColumnKind
    robot: int
    task: int
    cost: float

    @property
    def key(self) -> tuple[int, int, int]:
        """``(kind rank, robot, task)``: the column's place in the global total order."""
        return (int(self.kind), self.robot, self.task)

    def rows(self, n_robots: int) -> tuple[int, ...]:
        """The rows holding a one (the column's sparse form; every other entry is 0)."""
        if self.kind is ColumnKind.PAIR:
            return (self.robot, n_robots + self.task)
        if self.kind is ColumnKind.IDLE:
            return (self.robot,)
        return (n_robots + self.task,)


class LpShape(NamedTuple):
    """What every agent knows of the LP's rows: the numbers of robots and tasks."""

    n_robots: int
    n_tasks: int

    @property
    def rows(self) -> int:
        """``m = R + T``, the number of equality rows."""
        return self.n_robots + self.n_tasks


def pair(robot: int, task: int, cost: float) -> Column:
    """The column ``("x", robot, task)``."""
    return Column(ColumnKind.PAIR, robot, task, cost)


def idle(robot: int) -> Column:
    """The column ``("idle", robot)``, cost 0."""
    return Column(ColumnKind.IDLE, robot, NO_INDEX, 0.0)


def unserved(task: int, unserved_cost: float) -> Column:
    """The column ``("unserved", task)`` with the big-M cost."""
    return Column(ColumnKind.UNSERVED, NO_INDEX, task, unserved_cost)


def identity_basis(shape: LpShape, unserved_cost: float) -> list[Column]:
    """The start basis of every agent: all idle and all unserved columns, in key order."""
    return [idle(i) for i in range(shape.n_robots)] + unserved_columns(shape, unserved_cost)


def unserved_columns(shape: LpShape, unserved_cost: float) -> list[Column]:
    """The big-M columns, one per task, in key order."""
    return [unserved(j, unserved_cost) for j in range(shape.n_tasks)]


@dataclass(frozen=True, eq=False)
class AssignmentProblem:
    """Robots, tasks and travel costs of one assignment epoch.

    Attributes:
        robots: robot names in the global order (index i is row i).
        tasks: task ids in the global order (index j is row R + j).
        cost: (R, T) costs >= 0; ``math.inf`` where robot i is not eligible for task j.
            Stored as a read-only float64 copy.
        unserved_cost: the big-M cost of an unserved task; it must exceed
            ``min(R, T) * max finite cost`` so that serving one more task always pays.

    Raises:
        ModelError: ``assignment.robots`` / ``assignment.tasks`` for repeated names or ids
            (or no robot), ``assignment.cost`` for a wrong shape, NaN, negative or -inf
            entries, ``assignment.unserved_cost`` for a big-M that is too small or not finite.
    """

    robots: tuple[str, ...]
    tasks: tuple[int, ...]
    cost: npt.NDArray[np.float64]
    unserved_cost: float = DEFAULT_UNSERVED_COST

    def __post_init__(self) -> None:
        if not self.robots or len(set(self.robots)) != len(self.robots):
            raise ModelError("assignment.robots", self.robots, "one or more distinct names")
        if len(set(self.tasks)) != len(self.tasks):
            raise ModelError("assignment.tasks", self.tasks, "distinct task ids")
        cost = np.array(self.cost, dtype=np.float64)
        shape = (len(self.robots), len(self.tasks))
        if cost.shape != shape:
            raise ModelError("assignment.cost", cost.shape, f"an array of shape {shape}")
        if np.isnan(cost).any() or (cost < 0.0).any():
            raise ModelError("assignment.cost", cost.tolist(), "costs >= 0 or inf (no NaN)")
        cost.setflags(write=False)
        object.__setattr__(self, "cost", cost)
        finite = cost[np.isfinite(cost)]
        bound = min(shape) * float(finite.max()) if finite.size else 0.0
        big_m = float(self.unserved_cost)
        if not (math.isfinite(big_m) and big_m > bound):
            raise ModelError(
                "assignment.unserved_cost",
                self.unserved_cost,
                f"a finite cost > min(R, T) * max finite cost = {bound!r}",
            )
        object.__setattr__(self, "unserved_cost", big_m)

    @property
    def shape(self) -> LpShape:
        """The LP's row structure."""
        return LpShape(len(self.robots), len(self.tasks))

    def columns_of(self, robot: int) -> list[Column]:
        """The columns robot ``robot`` owns: its eligible pairs and its idle column."""
        row = self.cost[robot]
        owned = [pair(robot, j, float(row[j])) for j in np.flatnonzero(np.isfinite(row)).tolist()]
        return [*owned, idle(robot)]

    def columns(self) -> list[Column]:
        """Every column of the LP, in key order."""
        owned = [c for i in range(len(self.robots)) for c in self.columns_of(i)]
        return sorted(owned + unserved_columns(self.shape, self.unserved_cost))

    def start_basis(self) -> list[Column]:
        """The identity basis (idle + unserved columns)."""
        return identity_basis(self.shape, self.unserved_cost)


def objective(problem: AssignmentProblem, assignment: Mapping[int, int]) -> float:
    """The LP objective of an assignment, summed exactly.

    ``math.fsum`` returns the correctly rounded value of the exact sum, so two assignments
    with the same exact cost (the same one, or different optima of a tie) give bit-identical
    floats whatever order they were built in.

    Raises:
        ModelError: ``assignment`` when a pair is not eligible, an index is out of range or
            a task is assigned twice.
    """
    n_robots, n_tasks = problem.cost.shape
    terms: list[float] = []
    for robot, task in sorted(assignment.items()):
        ok = 0 <= robot < n_robots and 0 <= task < n_tasks
        if not ok or not math.isfinite(problem.cost[robot, task]):
            raise ModelError("assignment", (robot, task), "an eligible (robot, task) pair")
        terms.append(float(problem.cost[robot, task]))
    served = len(set(assignment.values()))
    if served != len(assignment):
        raise ModelError("assignment", dict(assignment), "each task assigned at most once")
    terms.extend([problem.unserved_cost] * (n_tasks - served))
    return math.fsum(terms)


def hungarian(problem: AssignmentProblem) -> tuple[dict[int, int], float]:
    """The centralized optimum of the same LP, by ``scipy.optimize.linear_sum_assignment``.

    The square (R + T) x (T + R) matrix has robots and "unserved" slots as rows, tasks and
    "idle" slots as columns: robot i -> task j costs c_ij, robot i -> its own idle slot 0,
    task j's unserved slot -> task j costs the big-M, unserved slot -> idle slot 0, and
    every other entry (ineligible pairs included) is ``inf``. Every perfect matching of it
    is a feasible point of the LP with the same cost, and all robots idle is one, so the
    matrix is always feasible.

    Returns:
        The assignment (robot index -> task index) and its :func:`objective`.
    """
    n_robots, n_tasks = problem.cost.shape
    size = n_robots + n_tasks
    square = np.full((size, size), math.inf)
    square[:n_robots, :n_tasks] = problem.cost
    square[np.arange(n_robots), n_tasks + np.arange(n_robots)] = 0.0
    square[n_robots + np.arange(n_tasks), np.arange(n_tasks)] = problem.unserved_cost
    square[n_robots:, n_tasks:] = 0.0
    rows, cols = linear_sum_assignment(square)
    assignment = {
        int(r): int(c) for r, c in zip(rows, cols, strict=True) if r < n_robots and c < n_tasks
    }
    return assignment, objective(problem, assignment)


def named(problem: AssignmentProblem, assignment: Mapping[int, int]) -> dict[str, int]:
    """The assignment with robot names and task ids instead of indices."""
    return {problem.robots[i]: problem.tasks[j] for i, j in sorted(assignment.items())}
