import math

import numpy as np
import pytest
from scipy.optimize import linear_sum_assignment

from models.assignment.greedy import (
    check_cost,
    greedy_global,
    greedy_sequential,
    nearest_free,
    total_cost,
)

INF = math.inf
GREEDY = (greedy_sequential, greedy_global)


def random_costs(count: int = 200):
    for seed in range(count):
        rng = np.random.default_rng(seed)
        n_robots, n_tasks = (int(v) for v in rng.integers(0, 13, size=2))
        if seed % 4 == 3:  # many ties
            cost = rng.integers(1, 4, size=(n_robots, n_tasks)).astype(float)
        else:
            cost = rng.uniform(0.0, 30.0, size=(n_robots, n_tasks))
        cost[rng.random((n_robots, n_tasks)) < rng.uniform(0.0, 0.7)] = INF
        yield seed, cost


@pytest.mark.parametrize("solve", GREEDY)
def test_greedy_assignments_are_conflict_free_and_never_use_ineligible_pairs(solve):
    for seed, cost in random_costs():
        assignment = solve(cost)
        assert len(set(assignment.values())) == len(assignment), seed
        assert all(0 <= i < cost.shape[0] for i in assignment), seed
        assert all(math.isfinite(cost[i, j]) for i, j in assignment.items()), seed


@pytest.mark.parametrize("solve", GREEDY)
def test_greedy_leaves_no_robot_idle_next_to_an_eligible_free_task(solve):
    for seed, cost in random_costs():
        assignment = solve(cost)
        free = set(range(cost.shape[1])) - set(assignment.values())
        for robot in set(range(cost.shape[0])) - set(assignment):
            assert all(math.isinf(cost[robot, j]) for j in free), seed


@pytest.mark.parametrize("solve", GREEDY)
def test_greedy_never_beats_the_hungarian_optimum(solve):
    for seed, cost in random_costs():
        if not cost.size or np.isinf(cost).any():
            continue
        rows, cols = linear_sum_assignment(cost)
        assignment = solve(cost)
        assert len(assignment) == min(cost.shape), seed
        assert total_cost(cost, assignment) >= cost[rows, cols].sum() - 1e-9, seed


def test_more_tasks_than_robots_gives_every_robot_a_task():
    cost = np.array([[5.0, 1.0, 3.0, 9.0], [2.0, 1.5, 8.0, 0.5]])
    assert greedy_sequential(cost) == {0: 1, 1: 3}
    assert greedy_global(cost) == {0: 1, 1: 3}


def test_more_robots_than_tasks_leaves_the_later_or_farther_robots_idle():
    cost = np.array([[4.0, 6.0], [1.0, 7.0], [3.0, 2.0]])
    assert greedy_sequential(cost) == {0: 0, 1: 1}  # robot 0 chooses first
    assert greedy_global(cost) == {1: 0, 2: 1}  # the cheapest pairs first


def test_sequential_and_global_greedy_differ_in_order_of_choice():
    cost = np.array([[2.0, 3.0], [1.0, 9.0]])
    assert greedy_sequential(cost) == {0: 0, 1: 1}
    assert greedy_global(cost) == {1: 0, 0: 1}


def test_equal_costs_go_to_the_lower_robot_and_the_lower_task():
    ones = np.ones((3, 4))
    assert greedy_sequential(ones) == {0: 0, 1: 1, 2: 2}
    assert greedy_global(ones) == {0: 0, 1: 1, 2: 2}
    cost = np.array([[2.0, 1.0, 1.0], [1.0, 1.0, 3.0]])
    assert greedy_global(cost) == {0: 1, 1: 0}  # the three cost-1 pairs: robot 0 first
    assert greedy_sequential(cost) == {0: 1, 1: 0}


def test_greedy_is_a_pure_function_of_the_matrix():
    for _, cost in random_costs(30):
        assert greedy_global(cost) == greedy_global(cost.copy())
        assert list(greedy_global(cost)) == sorted(greedy_global(cost))


def test_the_nearest_free_task_is_the_cheapest_eligible_one_ties_to_the_lower_index():
    cost = np.array([[4.0, 2.0, INF, 2.0, 1.0]])
    assert nearest_free(cost, [0, 1, 2, 3, 4], 0) == 4
    assert nearest_free(cost, [3, 1, 0], 0) == 1
    assert nearest_free(cost, {2, 0}, 0) == 0
    assert nearest_free(cost, [2], 0) is None
    assert nearest_free(cost, [], 0) is None


def test_nearest_free_rejects_unknown_robots_and_tasks():
    cost = np.ones((2, 3))
    with pytest.raises(ValueError, match="robot = 2"):
        nearest_free(cost, [0], 2)
    with pytest.raises(ValueError, match="free_tasks"):
        nearest_free(cost, [0, 3], 1)
    with pytest.raises(ValueError, match="free_tasks"):
        nearest_free(cost, [-1], 1)


def test_a_fleet_without_eligible_pairs_gets_no_assignment():
    cost = np.full((3, 2), INF)
    assert greedy_sequential(cost) == {} and greedy_global(cost) == {}
    assert greedy_global(np.zeros((0, 4))) == {} and greedy_sequential(np.zeros((4, 0))) == {}


def test_malformed_cost_matrices_are_rejected():
    with pytest.raises(ValueError, match="shape"):
        check_cost([1.0, 2.0])
    with pytest.raises(ValueError, match="NaN"):
        greedy_global([[1.0, np.nan]])
    with pytest.raises(ValueError, match="-inf"):
        greedy_sequential([[-INF]])


def test_the_total_cost_sums_the_assigned_pairs():
    cost = np.array([[1.0, 2.0], [3.0, INF]])
    assert total_cost(cost, {0: 1, 1: 0}) == 5.0
    assert total_cost(cost, {1: 1}) == INF
    assert total_cost(cost, {}) == 0.0
