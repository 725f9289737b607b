"""Greedy assignment baselines over a travel-cost matrix.

``cost`` is an (R, T) array: ``cost[i, j]`` is robot i's travel cost (m) to task j, and
``math.inf`` where robot i is not eligible for task j. An ineligible pair is never
assigned. Every tie is broken the same way: the lower robot index first, then the lower
task index, so the result is a pure function of the matrix.

Two greedy orders are offered:

- :func:`greedy_sequential`: robots choose one after another in index order, each its
  nearest free task ("first come, first served"). Cheap, and what a fleet without
  coordination would do.
- :func:`greedy_global`: the globally cheapest (robot, task) pair is fixed first, then
  the cheapest among the remaining robots and tasks, and so on. This is the sequential
  greedy algorithm (SGA) that the consensus-based auction (``models.assignment.cbba``)
  reaches without a central node.

Neither is optimal in total cost (the Hungarian method is); see the tests for instances.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np
import numpy.typing as npt

Assignment = dict[int, int]
"""Robot index -> task index; each robot at most once, each task at most once."""


def check_cost(cost: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """The cost matrix as a float64 (R, T) array, checked.

    Raises:
        ValueError: if the array is not 2-D, or holds NaN or ``-inf`` (a pair is either
            a finite cost or ``+inf``, ineligible).
    """
    matrix = np.asarray(cost, dtype=np.float64)
    if matrix.ndim != 2:
        raise ValueError(f"cost must be an (R, T) array, got shape {matrix.shape}")
    if np.isnan(matrix).any() or np.isneginf(matrix).any():
        raise ValueError(
            "cost must hold finite costs (m) or +inf for ineligible pairs, got NaN/-inf"
        )
    return matrix


def nearest_free(cost: npt.ArrayLike, free_tasks: Iterable[int], robot: int) -> int | None:
    """The free task with the lowest finite cost for ``robot``.

    Args:
        cost: (R, T) travel costs (m), ``inf`` where ineligible.
        free_tasks: indices of the tasks still free, in any order; duplicates are harmless.
        robot: the robot's index.

    Returns:
        The nearest eligible free task (ties: the lowest task index), or ``None`` when no
        free task is eligible for the robot.

    Raises:
        ValueError: for a malformed cost matrix, a robot or task index out of range.
    """
    matrix = check_cost(cost)
    n_robots, n_tasks = matrix.shape
    if not 0 <= robot < n_robots:
        raise ValueError(f"robot = {robot}: expected an index in [0, {n_robots})")
    tasks = sorted(set(free_tasks))
    if tasks and not (tasks[0] >= 0 and tasks[-1] < n_tasks):
        raise ValueError(f"free_tasks = {tasks}: expected indices in [0, {n_tasks})")
    return _nearest(matrix[robot], tasks)


def _nearest(row: npt.NDArray[np.float64], sorted_tasks: list[int]) -> int | None:
    best: int | None = None
    best_cost = np.inf
    for task in sorted_tasks:  # ascending, and only a strictly lower cost replaces the best
        if row[task] < best_cost:
            best, best_cost = task, float(row[task])
    return best


def greedy_sequential(cost: npt.ArrayLike) -> Assignment:
    """Robots in index order each take their nearest free eligible task.

    A robot for which no free task is eligible stays unassigned; later robots still
    choose. With more robots than tasks, the last robots find nothing left.

    Args:
        cost: (R, T) travel costs (m), ``inf`` where ineligible.

    Returns:
        The assignment robot -> task, keys in ascending robot order.

    Raises:
        ValueError: for a malformed cost matrix.
    """
    matrix = check_cost(cost)
    free = list(range(matrix.shape[1]))
    assignment: Assignment = {}
    for robot in range(matrix.shape[0]):
        task = _nearest(matrix[robot], free)
        if task is not None:
            assignment[robot] = task
            free.remove(task)
    return assignment


def greedy_global(cost: npt.ArrayLike) -> Assignment:
    """The cheapest remaining (robot, task) pair first, repeated (sequential greedy).

    Pairs are taken in increasing cost; equal costs in increasing robot index, then task
    index. A pair is skipped when its robot or its task is already taken, and ``inf``
    pairs are never taken. The result is a maximal matching: no unassigned robot has an
    eligible free task left.

    Args:
        cost: (R, T) travel costs (m), ``inf`` where ineligible.

    Returns:
        The assignment robot -> task, keys in ascending robot order.

    Raises:
        ValueError: for a malformed cost matrix.
    """
    matrix = check_cost(cost)
    robots, tasks = np.nonzero(np.isfinite(matrix))  # row-major: robot, then task ascending
    # lexsort sorts by the last key first and is stable: cost, then robot, then task
    order = np.lexsort((tasks, robots, matrix[robots, tasks]))
    taken_robot = np.zeros(matrix.shape[0], dtype=bool)
    taken_task = np.zeros(matrix.shape[1], dtype=bool)
    assignment: Assignment = {}
    for robot, task in zip(robots[order].tolist(), tasks[order].tolist(), strict=True):
        if taken_robot[robot] or taken_task[task]:
            continue
        taken_robot[robot] = taken_task[task] = True
        assignment[robot] = task
        if len(assignment) == min(matrix.shape):
            break
    return dict(sorted(assignment.items()))


def total_cost(cost: npt.ArrayLike, assignment: Assignment) -> float:
    """The summed cost (m) of the assigned pairs (``inf`` if one is ineligible)."""
    matrix = check_cost(cost)
    return float(sum(matrix[robot, task] for robot, task in assignment.items()))
