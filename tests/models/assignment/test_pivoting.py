"""The compiled pivot loop of the lexicographic simplex, on assignment LPs laid out by hand."""

import itertools
from fractions import Fraction

import numpy as np
import pytest

from models.assignment.pivoting import CAP_HIT, UNBOUNDED, _exact_sign_py, pivot_loop


class Lp:
    """An assignment LP of ``r`` robots and ``t`` tasks as the pivot loop takes it.

    Rows: robots, then tasks (each covered exactly once). Candidates: every robot idle
    (cost ``idle``), every task unserved (cost ``unserved``), then every pair.
    """

    def __init__(self, cost: np.ndarray, idle: float, unserved: float) -> None:
        self.r, self.t = cost.shape
        self.m = self.r + self.t
        none = self.m + 1  # the zero column of the table
        units = [(row + 1, none) for row in range(self.m)]
        pairs = [(i + 1, self.r + j + 1) for i in range(self.r) for j in range(self.t)]
        self.first = np.array([f for f, _ in units + pairs], dtype=np.int64)
        self.second = np.array([s for _, s in units + pairs], dtype=np.int64)
        self.cost = np.array([idle] * self.r + [unserved] * self.t + list(cost.ravel()))
        self.matrix = cost

    def start(self) -> tuple[np.ndarray, np.ndarray]:
        """The identity basis: everyone idle, everything unserved; ``[1 | I | 0]``."""
        table = np.zeros((self.m, self.m + 2))
        table[:, 0] = 1.0
        table[:, 1 : self.m + 1] = np.eye(self.m)
        return np.arange(self.m, dtype=np.int64), table

    def column(self, j: int) -> np.ndarray:
        a = np.zeros(self.m + 2)
        a[self.first[j]] = a[self.second[j]] = 1.0
        return a[1 : self.m + 1]

    def best(self, idle: float, unserved: float) -> float:
        """The least cost of any matching, by enumeration."""
        best = np.inf
        for k in range(min(self.r, self.t) + 1):
            for robots in itertools.combinations(range(self.r), k):
                for tasks in itertools.permutations(range(self.t), k):
                    total = sum(self.matrix[i, j] for i, j in zip(robots, tasks, strict=True))
                    best = min(best, total + (self.r - k) * idle + (self.t - k) * unserved)
        return float(best)


def _solve(lp: Lp, exact: bool, cap: int = 10_000):
    basis, table = lp.start()
    pivots = pivot_loop(lp.cost, lp.first, lp.second, basis, table, exact, cap)
    return pivots, basis, table


def _random_lp(seed: int, integer: bool) -> tuple[Lp, float, float]:
    rng = np.random.default_rng(seed)
    r, t = int(rng.integers(1, 4)), int(rng.integers(1, 4))
    if integer:
        cost = rng.integers(0, 20, (r, t)).astype(float)
        return Lp(cost, 0.0, 50.0), 0.0, 50.0
    cost = rng.choice([0.1, 0.2, 0.3, 1.7, 2.0], (r, t)) * rng.random((r, t)).round(1)
    return Lp(cost, 0.0, 10.0), 0.0, 10.0


@pytest.mark.parametrize("integer", [True, False], ids=["integer costs", "float costs"])
def test_the_loop_ends_in_an_optimal_basis_whose_inverse_and_values_it_kept(integer):
    for seed in range(60):
        lp, idle, unserved = _random_lp(seed, integer)
        pivots, basis, table = _solve(lp, exact=integer)
        assert pivots >= 0, seed
        matrix = np.column_stack([lp.column(j) for j in basis])
        inverse = table[:, 1 : lp.m + 1]
        assert np.array_equal(inverse @ matrix, np.eye(lp.m)), seed
        assert set(np.unique(inverse)) <= {-1.0, 0.0, 1.0}, seed
        x = table[:, 0]
        assert np.array_equal(x, inverse @ np.ones(lp.m)) and set(x.tolist()) <= {0.0, 1.0}
        objective = float(np.dot(lp.cost[basis], x))
        assert objective == pytest.approx(lp.best(idle, unserved), abs=1e-12), seed


def test_restarting_from_the_optimum_takes_no_pivot_and_keeps_the_basis():
    lp, _, _ = _random_lp(7, integer=False)
    _, basis, table = _solve(lp, exact=False)
    again_basis, again_table = basis.copy(), table.copy()
    assert pivot_loop(lp.cost, lp.first, lp.second, again_basis, again_table, False, 10) == 0
    assert np.array_equal(again_basis, basis) and np.array_equal(again_table, table)


def test_one_pair_cheaper_than_idle_and_unserved_is_one_pivot_leaving_the_lexicographic_row():
    lp = Lp(np.array([[3.0]]), idle=5.0, unserved=5.0)
    pivots, basis, table = _solve(lp, exact=True)
    # the pair enters; rows [1, 1, 0, 0] and [1, 0, 1, 0] tie on x_B, the task's is smaller
    assert pivots == 1 and basis.tolist() == [0, 2]
    assert table.tolist() == [[0.0, 1.0, -1.0, 0.0], [1.0, 0.0, 1.0, 0.0]]


def test_the_cap_is_reported_when_an_entering_column_remains():
    lp = Lp(np.array([[3.0]]), idle=5.0, unserved=5.0)
    basis, table = lp.start()
    assert pivot_loop(lp.cost, lp.first, lp.second, basis, table, True, 0) == CAP_HIT
    assert basis.tolist() == [0, 1]


def test_a_column_of_negative_cost_with_no_positive_entry_is_unbounded():
    # one row; candidate 1 is the zero column: x_1 grows for ever at cost -1
    cost = np.array([0.0, -1.0])
    first = np.array([1, 2], dtype=np.int64)
    second = np.array([2, 2], dtype=np.int64)
    basis = np.array([0], dtype=np.int64)
    table = np.array([[1.0, 1.0, 0.0]])
    assert pivot_loop(cost, first, second, basis, table, False, 10) == UNBOUNDED


def test_a_zero_reduced_cost_enters_only_with_a_negative_perturbation_term():
    # a pair as dear as idle plus unserved: a tie the perturbation breaks by rank. The
    # pair's rank (2) is above both basic columns' (0, 1) with w = 1: the term is negative
    lp = Lp(np.array([[2.0]]), idle=1.0, unserved=1.0)
    pivots, basis, _ = _solve(lp, exact=True)
    assert pivots == 1 and 2 in basis.tolist()


def test_exact_sign_matches_rational_arithmetic_on_cancelling_float_sums():
    rng = np.random.default_rng(5)
    for _ in range(500):
        m = int(rng.integers(1, 12))
        w = rng.integers(-1, 2, m).astype(float)
        basic = rng.choice([0.1, 0.2, 0.3, 1e6, 1e-9, 3.0, 2.0**-60], m) * rng.choice([1, 3], m)
        cost_j = float(np.dot(w, basic)) if rng.random() < 0.5 else float(rng.choice(basic))
        table = np.zeros((m, 2))
        table[:, 0] = w
        exact = Fraction(cost_j) - sum(Fraction(b) * int(x) for b, x in zip(basic, w, strict=True))
        expected = (exact > 0) - (exact < 0)
        assert _exact_sign_py(table, 0, 1, cost_j, basic) == expected
