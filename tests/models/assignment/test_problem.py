from __future__ import annotations

import itertools
import math
from fractions import Fraction

import numpy as np
import pytest

from models.assignment.problem import (
    DEFAULT_UNSERVED_COST,
    AssignmentProblem,
    ColumnKind,
    LpShape,
    hungarian,
    idle,
    named,
    objective,
    pair,
    unserved,
)
from models.errors import ModelError

INF = math.inf


def _problem(cost: list[list[float]], unserved_cost: float = DEFAULT_UNSERVED_COST):
    array = np.array(cost, dtype=float).reshape(len(cost), -1 if cost and cost[0] else 0)
    robots = tuple(f"r{i}" for i in range(array.shape[0]))
    return AssignmentProblem(robots, tuple(range(10, 10 + array.shape[1])), array, unserved_cost)


def _brute_force(problem: AssignmentProblem) -> float:
    n_robots, n_tasks = problem.cost.shape
    best = math.inf
    for served in range(min(n_robots, n_tasks) + 1):
        for robots in itertools.combinations(range(n_robots), served):
            for tasks in itertools.permutations(range(n_tasks), served):
                if all(
                    math.isfinite(problem.cost[i, j]) for i, j in zip(robots, tasks, strict=True)
                ):
                    best = min(best, objective(problem, dict(zip(robots, tasks, strict=True))))
    return best


def test_columns_are_eligible_pairs_then_idle_then_unserved_in_key_order():
    problem = _problem([[1.0, INF], [2.0, 3.0]], unserved_cost=100.0)
    assert problem.columns() == [
        pair(0, 0, 1.0),
        pair(1, 0, 2.0),
        pair(1, 1, 3.0),
        idle(0),
        idle(1),
        unserved(0, 100.0),
        unserved(1, 100.0),
    ]
    assert problem.columns_of(0) == [pair(0, 0, 1.0), idle(0)]
    assert problem.start_basis() == [idle(0), idle(1), unserved(0, 100.0), unserved(1, 100.0)]
    assert problem.shape == LpShape(2, 2) and problem.shape.rows == 4


def test_a_column_has_ones_in_its_robot_row_and_its_task_row():
    assert pair(1, 2, 5.0).rows(3) == (1, 5)
    assert idle(2).rows(3) == (2,)
    assert unserved(0, 9.0).rows(3) == (3,)
    assert pair(1, 2, 5.0).key == (int(ColumnKind.PAIR), 1, 2)
    assert sorted([unserved(0, 9.0), idle(0), pair(0, 0, 1.0)])[0].kind is ColumnKind.PAIR


@pytest.mark.parametrize(
    ("cost", "unserved_cost", "key"),
    [
        ([[math.nan]], 1e6, "assignment.cost"),
        ([[-1.0]], 1e6, "assignment.cost"),
        ([[-INF]], 1e6, "assignment.cost"),
        ([[10.0, 10.0], [10.0, 10.0]], 20.0, "assignment.unserved_cost"),
        ([[1.0]], INF, "assignment.unserved_cost"),
    ],
)
def test_problem_rejects_bad_costs_and_a_big_m_that_does_not_dominate(cost, unserved_cost, key):
    with pytest.raises(ModelError) as raised:
        _problem(cost, unserved_cost)
    assert raised.value.key == key


def test_problem_rejects_a_wrong_shape_and_repeated_names_or_ids():
    with pytest.raises(ModelError, match="shape"):
        AssignmentProblem(("a", "b"), (1,), np.zeros((1, 1)))
    with pytest.raises(ModelError) as raised:
        AssignmentProblem(("a", "a"), (1,), np.zeros((2, 1)))
    assert raised.value.key == "assignment.robots"
    with pytest.raises(ModelError) as raised:
        AssignmentProblem(("a",), (1, 1), np.zeros((1, 2)))
    assert raised.value.key == "assignment.tasks"


def test_problem_keeps_a_read_only_copy_of_the_costs():
    cost = np.array([[1.0, 2.0]])
    problem = AssignmentProblem(("a",), (1, 2), cost)
    cost[0, 0] = 99.0
    assert problem.cost[0, 0] == 1.0
    with pytest.raises(ValueError, match="read-only"):
        problem.cost[0, 0] = 5.0


def test_objective_is_the_correctly_rounded_exact_sum_whatever_the_insertion_order():
    rng = np.random.default_rng(3)
    cost = rng.random((6, 6)) * 1e3
    problem = AssignmentProblem(tuple("abcdef"), tuple(range(6)), cost)
    items = [(i, (i * 5 + 1) % 6) for i in range(5)]
    forward, backward = dict(items), dict(reversed(items))
    exact = sum(Fraction(cost[i, j]) for i, j in items) + Fraction(problem.unserved_cost)
    assert objective(problem, forward) == objective(problem, backward) == float(exact)


def test_objective_rejects_ineligible_pairs_unknown_indices_and_double_service():
    problem = _problem([[1.0, INF], [2.0, 3.0]])
    for bad in ({0: 1}, {2: 0}, {0: 0, 1: 0}):
        with pytest.raises(ModelError):
            objective(problem, bad)


def test_hungarian_equals_brute_force_on_small_instances_with_ineligible_pairs():
    rng = np.random.default_rng(11)
    for _ in range(150):
        n_robots, n_tasks = int(rng.integers(1, 5)), int(rng.integers(0, 5))
        cost = rng.integers(0, 4, (n_robots, n_tasks)).astype(float)
        cost[rng.random(cost.shape) < 0.4] = INF
        problem = AssignmentProblem(
            tuple(f"r{i}" for i in range(n_robots)), tuple(range(n_tasks)), cost, 50.0
        )
        assignment, value = hungarian(problem)
        assert value == _brute_force(problem) == objective(problem, assignment)


def test_hungarian_serves_every_task_someone_may_serve_when_robots_suffice():
    problem = _problem([[5.0, INF, 1.0], [2.0, INF, INF], [9.0, INF, 9.0]])
    assignment, value = hungarian(problem)
    assert sorted(assignment.values()) == [0, 2]  # task 1: eligible for nobody
    assert value == 1.0 + 2.0 + DEFAULT_UNSERVED_COST
    assert named(problem, assignment) == {"r0": 12, "r1": 10}


def test_hungarian_leaves_robots_idle_when_tasks_are_fewer():
    problem = _problem([[3.0], [1.0], [2.0]])
    assert hungarian(problem) == ({1: 0}, 1.0)
