from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from models.assignment.problem import (
    AssignmentProblem,
    Column,
    ColumnKind,
    LpShape,
    hungarian,
    idle,
    objective,
    pair,
    unserved,
)
from models.assignment.simplex import (
    _layout,
    assignment_of,
    columns_of,
    lex_simplex,
    primal,
    ranked,
    ranked_rows,
    solve,
    solve_ranked,
    union,
)
from models.errors import ModelError


def _subset_basis(problem: AssignmentProblem, rng: np.random.Generator) -> list[Column]:
    """A lexicographically feasible basis other than the identity: optimal on a subset."""
    kept = [c for c in problem.columns() if rng.random() < 0.5]
    return solve(problem.shape, kept, problem.start_basis())


def test_solve_from_different_start_bases_ends_in_the_same_basis(make_lp):
    for seed in range(200):
        problem = make_lp(seed)
        rng = np.random.default_rng(seed)
        columns = problem.columns()
        reference = solve(problem.shape, columns, problem.start_basis())
        for _ in range(3):
            start = _subset_basis(problem, rng)
            shuffled = [columns[k] for k in rng.permutation(len(columns))]
            assert solve(problem.shape, shuffled, start) == reference, f"seed {seed}"
        again = lex_simplex(problem.shape, columns, reference)
        assert again.basis == reference and again.pivots == 0, f"seed {seed}"


def test_the_lexicographic_optimum_has_the_hungarian_objective_exactly(make_lp):
    for seed in range(200, 400):
        problem = make_lp(seed)
        basis = solve(problem.shape, problem.columns(), problem.start_basis())
        found = objective(problem, assignment_of(problem.shape, basis))
        assert found == hungarian(problem)[1], f"seed {seed}"


def test_the_returned_inverse_is_the_inverse_of_the_returned_basis(make_lp):
    for seed in range(20):
        problem = make_lp(seed)
        solution = lex_simplex(problem.shape, problem.columns(), problem.start_basis())
        m, r = problem.shape.rows, problem.shape.n_robots
        matrix = np.zeros((m, m))
        for k, column in enumerate(solution.basis):
            matrix[list(column.rows(r)), k] = 1.0
        assert np.array_equal(solution.inverse @ matrix, np.eye(m))
        assert set(np.unique(solution.inverse)) <= {-1.0, 0.0, 1.0}


def test_basic_values_are_zero_or_one_and_the_assignment_is_a_matching(make_lp):
    for seed in range(50):
        problem = make_lp(seed)
        basis = solve(problem.shape, problem.columns(), problem.start_basis())
        assert set(primal(problem.shape, basis).tolist()) <= {0.0, 1.0}
        assignment = assignment_of(problem.shape, basis)
        assert len(set(assignment.values())) == len(assignment)


@pytest.mark.parametrize("value", [0.0, 1.0, 0.1])
def test_fully_degenerate_instances_end_without_hitting_the_pivot_cap(value):
    # all costs equal, every pair eligible: every matching ties, most pivots are degenerate
    for n_robots, n_tasks in [(15, 15), (15, 7), (7, 15)]:
        cost = np.full((n_robots, n_tasks), value)
        problem = AssignmentProblem(
            tuple(f"r{i}" for i in range(n_robots)), tuple(range(n_tasks)), cost
        )
        m, n = problem.shape.rows, len(problem.columns())
        solution = lex_simplex(problem.shape, problem.columns(), problem.start_basis())
        assert solution.pivots <= 20 * (m + n) + 100
        assert len(assignment_of(problem.shape, solution.basis)) == min(n_robots, n_tasks)


def test_the_pivot_cap_raises_when_it_is_hit():
    problem = AssignmentProblem(("a",), (1,), np.array([[1.0]]))
    with pytest.raises(RuntimeError, match="cap"):
        lex_simplex(problem.shape, problem.columns(), problem.start_basis(), max_pivots=0)


SHAPE = LpShape(2, 2)


def test_a_singular_start_basis_is_rejected():
    cycle = [pair(0, 0, 1.0), pair(0, 1, 1.0), pair(1, 0, 1.0), pair(1, 1, 1.0)]
    with pytest.raises(ModelError, match="independent"):
        solve(SHAPE, [], cycle)


def test_a_start_basis_that_is_not_lexicographically_feasible_is_rejected():
    infeasible = [pair(0, 0, 1.0), pair(1, 0, 1.0), unserved(0, 9.0)]
    with pytest.raises(ModelError, match="lexicographically feasible"):
        solve(LpShape(2, 1), [], infeasible)


def test_a_start_basis_of_the_wrong_size_is_rejected():
    with pytest.raises(ModelError, match="distinct columns"):
        solve(SHAPE, [], [idle(0), idle(1), unserved(0, 9.0)])


def test_one_column_key_with_two_costs_is_rejected():
    start = [idle(0), idle(1), unserved(0, 9.0), unserved(1, 9.0)]
    with pytest.raises(ModelError, match="one cost per column key"):
        solve(SHAPE, [pair(0, 0, 1.0), pair(0, 0, 2.0)], start)


def test_a_column_outside_the_shape_is_rejected():
    start = [idle(0), idle(1), unserved(0, 9.0), unserved(1, 9.0)]
    with pytest.raises(ModelError, match="indices within"):
        solve(SHAPE, [pair(2, 0, 1.0)], start)


def test_a_wrong_start_inverse_is_rejected():
    start = [idle(0), idle(1), unserved(0, 9.0), unserved(1, 9.0)]
    with pytest.raises(ModelError) as raised:
        lex_simplex(SHAPE, [], start, start_inverse=2.0 * np.eye(4))
    assert raised.value.key == "start_inverse"


@pytest.mark.parametrize("flip", [False, True])
def test_matchings_that_differ_below_the_rounding_error_are_still_ranked_exactly(flip):
    # 0.1 + 0.2 exceeds 0.3 + 0.0 by 2.8e-17 in exact binary arithmetic, far inside the
    # float error bound (big-M costs are in the basis): only the exact sign can tell.
    cost = np.array([[0.1, 0.3], [0.0, 0.2]])
    cost = cost[::-1] if flip else cost
    problem = AssignmentProblem(("a", "b"), (1, 2), cost)
    basis = solve(problem.shape, problem.columns(), problem.start_basis())
    better = {0: 0, 1: 1} if flip else {0: 1, 1: 0}
    assert assignment_of(problem.shape, basis) == better
    assert objective(problem, better) == 0.3 < objective(problem, {0: 1 - better[0], 1: better[0]})


def _layout_by_loop(shape, columns):
    """Rank, first and second row of each column, one column at a time (the reference)."""
    r, t = shape
    rank, first, second = [], [], []
    for c in columns:
        rank.append((c.kind * (r + 1) + c.robot + 1) * (t + 1) + c.task + 1)
        first.append(r + c.task if c.kind is ColumnKind.UNSERVED else c.robot)
        second.append(r + c.task if c.kind is ColumnKind.PAIR else r + t)
    return tuple(np.array(v, dtype=np.int64) for v in (rank, first, second))


@pytest.mark.parametrize("seed", range(4))
def test_columns_laid_out_as_whole_arrays_equal_the_layout_column_by_column(seed):
    rng = np.random.default_rng(seed)
    shape = LpShape(int(rng.integers(1, 9)), int(rng.integers(1, 9)))
    r, t = shape
    columns = [
        pair(int(rng.integers(r)), int(rng.integers(t)), float(rng.random())) for _ in range(30)
    ]
    columns += [idle(i) for i in range(r)] + [unserved(j, 99.0) for j in range(t)]
    rng.shuffle(columns)
    got = _layout(shape, columns, "columns")
    assert all(g.dtype == np.int64 for g in got)
    assert all(
        np.array_equal(g, w) for g, w in zip(got, _layout_by_loop(shape, columns), strict=True)
    )


@pytest.mark.parametrize(
    "bad",
    [
        Column(ColumnKind.IDLE, 0, 0, 0.0),  # an idle column with a task
        Column(ColumnKind.UNSERVED, 1, 0, 9.0),  # an unserved column with a robot
        Column(ColumnKind.PAIR, 0, 2, 1.0),  # a task out of range
        Column(0, 0, 0, 1.0),  # a kind that is no ColumnKind
    ],
)
def test_the_first_column_out_of_range_is_named_whatever_the_layout(bad):
    columns = [pair(0, 0, 1.0), idle(1), bad, pair(1, 1, 2.0)]
    with pytest.raises(ModelError, match="indices within") as raised:
        _layout(SHAPE, columns, "columns")
    assert raised.value.key == "columns" and raised.value.value == bad


_ROWS = st.tuples(
    st.integers(-2, 4),
    st.integers(-2, 4),
    st.integers(-2, 4),
    st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.integers(-3, 3)),
)


@settings(max_examples=300, deadline=None)
@given(st.lists(_ROWS, min_size=1, max_size=12), st.integers(1, 3), st.integers(1, 3))
def test_rows_read_as_one_array_rank_as_their_columns_do_or_are_left_to_the_columns(
    rows, n_robots, n_tasks
):
    shape = LpShape(n_robots, n_tasks)
    fast = ranked_rows(shape, np.array(rows, dtype=np.float64))
    kinds = {int(k): k for k in ColumnKind}
    if any(k not in kinds for k, *_ in rows):
        assert fast is None  # not a kind: the caller refuses the rows
        return
    columns = [Column(kinds[k], r, t, float(c)) for k, r, t, c in rows]
    try:
        slow = ranked(shape, columns, "columns")
    except ModelError:
        assert fast is None  # the column-by-column reading names what is wrong
        return
    assert fast is not None
    assert np.array_equal(fast.rank, slow.rank) and np.array_equal(fast.cost, slow.cost)


@pytest.mark.parametrize("seed", range(40))
def test_a_union_holds_each_column_once_in_key_order(seed, make_lp):
    problem = make_lp(seed)
    rng = np.random.default_rng(seed)
    columns = problem.columns()
    parts = [[columns[k] for k in rng.integers(0, len(columns), 30)] for _ in range(4)]
    merged = union(problem.shape, [ranked(problem.shape, p, "columns") for p in parts])
    assert columns_of(problem.shape, merged) == sorted({c for p in parts for c in p})


def test_a_union_names_the_first_key_with_two_costs_and_both_costs():
    a = ranked(SHAPE, [pair(1, 1, 3.0), pair(0, 1, 2.0), idle(0)], "columns")
    b = ranked(SHAPE, [pair(0, 1, 1.0), pair(1, 1, 0.5), idle(0)], "columns")
    with pytest.raises(ModelError, match="one cost per column key") as raised:
        union(SHAPE, [a, b])
    assert raised.value.value == (pair(0, 1, 1.0), pair(0, 1, 2.0))


@pytest.mark.parametrize("cost", [math.inf, -math.inf, math.nan])
def test_a_column_whose_cost_is_not_finite_is_rejected(cost):
    with pytest.raises(ModelError, match="a finite cost") as raised:
        ranked(SHAPE, [idle(0), pair(0, 1, cost)], "columns")
    assert raised.value.key == "columns"


@pytest.mark.parametrize("seed", range(60))
def test_solves_chained_on_ranked_columns_and_their_tables_equal_solves_on_columns(seed, make_lp):
    problem = make_lp(seed)
    rng = np.random.default_rng(seed)
    shape, columns = problem.shape, problem.columns()
    basis = problem.start_basis()
    start = ranked(shape, basis, "start_basis")
    table = None
    for _ in range(4):
        subset = [c for c in columns if rng.random() < 0.5]
        expected = lex_simplex(shape, subset, basis)
        candidates = union(shape, [ranked(shape, subset, "columns"), start])
        got = solve_ranked(shape, candidates, start, table)
        assert columns_of(shape, got.basis) == expected.basis
        assert got.pivots == expected.pivots
        assert np.array_equal(got.table[:, 1:-1], expected.inverse)
        assert np.array_equal(got.table[:, 0], expected.inverse.sum(axis=1))
        basis, start, table = expected.basis, got.basis, got.table


def test_a_union_in_a_large_lp_sorts_instead_of_marking_every_rank_and_agrees():
    shape = LpShape(1000, 1000)  # 3 million ranks: too many to mark for a few columns
    columns = [pair(999, 998, 1.0), idle(3), unserved(5, 9.0), pair(0, 0, 2.0)]
    parts = [ranked(shape, columns, "columns"), ranked(shape, columns[::-1], "columns")]
    assert columns_of(shape, union(shape, parts)) == sorted(columns)
    clash = ranked(shape, [pair(0, 0, 0.5)], "columns")
    with pytest.raises(ModelError, match="one cost per column key"):
        union(shape, [*parts, clash])
