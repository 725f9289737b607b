"""Lexicographic primal simplex for the assignment LP: one answer from any start.

:func:`solve` ends in *the* lexicographically optimal basis of a column set, so two agents
that start from different bases with the same columns end with the same basis, bit for
bit. This is what the distributed simplex of Bürger, Notarstefano, Bullo and Allgöwer
("A distributed simplex algorithm for degenerate linear programs and multi-agent
assignments", Automatica 48(9):2298-2304, 2012, Sec. 3) needs of its local solver.

Why the basis is unique. Take the doubly perturbed LP

    min (c + eps)^T x   s.t.   A x = b + delta,   x >= 0,
    eps_j = e^rank(j)   (rank in the global column order),
    delta_r = d^(r+1)   (r in the global row order).

For all small enough e, d > 0 (finitely many bases, so finitely many nonzero polynomials
to keep away from zero): every basis is primal nondegenerate, since the basic values
``B^-1 b + B^-1 delta`` are nonzero polynomials in d (no row of ``B^-1`` is zero); and every
basis is dual nondegenerate, since a nonbasic reduced cost holds the monomial e^rank(j)
once, with coefficient 1. A dual nondegenerate optimal basis gives the only optimal
point, and a primal nondegenerate point has only one basis: the perturbed LP has one
optimal basis. The lexicographic ratio test (rows of ``[x_B | B^-1]``) is the ratio test of
the perturbed LP, and the sign test below is the sign of its reduced costs, so this is the
simplex on it: the perturbed objective falls at every pivot (no basis repeats, no
cycling) and the end is that basis, whatever the start and the entering rule.

Entering rule: the most negative reduced cost, ties to the smallest key (Dantzig); when no
float reduced cost is surely negative, the smallest key among the columns whose reduced
cost is exactly negative, or exactly zero with a negative perturbation term. That term is
decided by the smallest rank among the entering column (coefficient +1) and the basic
columns ``B_k`` with ``w_k = (B^-1 a_j)_k != 0`` (coefficient ``-w_k``).

Exact arithmetic, tolerance 0. The constraint matrix is totally unimodular, so every basis
has determinant +-1 and ``B^-1``, ``x_B`` and ``w`` are integral with entries in
{-1, 0, 1} (Cramer's rule). A pivot element is then exactly 1 and the product-form update
adds and subtracts small integers: float64 holds them exactly, no refactorization is ever
needed, and the ratio test compares exact integers. Only reduced costs see rounding. They
are computed in float with a rigorous bound on the error, ``(2m + 8) 2^-52 (max|c| +
2 sum|c_B|)``; the sign of a reduced cost inside the bound is recomputed exactly from the
signed sum ``c_j - sum_k w_k c_Bk`` (Shewchuk's exact expansion sum, the algorithm of
``math.fsum``). When all costs are integers summing below 2^52 the float value is exact
and the bound is 0. Every decision is thus exact on the given binary64 costs (tolerance
0), which is what makes agents on different pivot paths agree bit for bit; a tolerance
such as 1e-9 would not: two bases whose objectives differ by less than it could both
pass as optimal. The pivot loop is compiled (:mod:`models.assignment.pivoting`).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import Any, NamedTuple

import numpy as np
import numpy.typing as npt

from models.arrays import FloatArray, IntArray
from models.assignment.pivoting import CAP_HIT, UNBOUNDED, pivot_loop
from models.assignment.problem import KINDS, Column, ColumnKind, LpShape
from models.errors import ModelError

_EXACT_INTEGER_SUM = 2.0**52
"""Integer costs whose magnitudes sum below this add up exactly in float64."""


class Solution(NamedTuple):
    """The result of :func:`lex_simplex`.

    Attributes:
        basis: the lexicographically optimal basis, m columns in key order.
        pivots: the pivots it took.
        inverse: ``B^-1`` (m x m, integral) of ``basis`` in that order; hand it back as
            ``start_inverse`` when the next solve starts from this basis.
    """

    basis: list[Column]
    pivots: int
    inverse: FloatArray


class RankedColumns(NamedTuple):
    """Columns as two arrays: what a solve works on, without a Python object per column.

    Attributes:
        rank: each column's rank in the global key order (int64; see :func:`_layout`).
        cost: each column's cost (float64), in the same order.
    """

    rank: IntArray
    cost: FloatArray


class RankedSolution(NamedTuple):
    """The result of :func:`solve_ranked`.

    Attributes:
        basis: the lexicographically optimal basis, its m columns in key order.
        pivots: the pivots it took.
        table: ``[x_B | B^-1 | 0]`` (m x (m + 2), integral), rows in the order of
            ``basis``; hand it back as ``start_table`` when the next solve starts from it.
    """

    basis: RankedColumns
    pivots: int
    table: FloatArray


def solve(shape: LpShape, columns: Iterable[Column], start_basis: Sequence[Column]) -> list[Column]:
    """The lexicographically optimal basis of ``columns`` (plus the start basis), in key order.

    Args:
        shape: the LP's rows.
        columns: the candidate columns; repeats (same key, same cost) are merged.
        start_basis: m columns forming a lexicographically feasible basis (the identity basis
            or any basis this function returned); they join the candidates.

    Raises:
        ModelError: see :func:`lex_simplex`.
    """
    return lex_simplex(shape, columns, start_basis).basis


def lex_simplex(
    shape: LpShape,
    columns: Iterable[Column],
    start_basis: Sequence[Column],
    *,
    start_inverse: FloatArray | None = None,
    max_pivots: int | None = None,
) -> Solution:
    """:func:`solve`, with the pivot count.

    Args:
        shape: the LP's rows.
        columns: the candidate columns.
        start_basis: a lexicographically feasible basis.
        start_inverse: ``B^-1`` of ``start_basis`` in its order, if known (checked, not
            trusted); otherwise it is computed.
        max_pivots: the cap on pivots (default ``20 (m + n) + 100`` for n candidates);
            the cap is a guard against bugs, the lexicographic rules cannot cycle.

    Raises:
        ModelError: ``columns`` for one key with two costs, an index out of range or a
            cost that is not finite, ``start_basis`` for a basis that is not m independent,
            lexicographically feasible columns, ``start_inverse`` for a matrix that is not
            its inverse.
        RuntimeError: the pivot cap was hit (a bug, never expected).
    """
    start = ranked(shape, start_basis, "start_basis")
    candidates = union(shape, [ranked(shape, list(columns), "columns"), start])
    table = _start_table(shape, start, start_inverse, start_basis)
    solution = _solve(shape, candidates, start.rank, table, max_pivots)
    inverse = solution.table[:, 1:-1]
    return Solution(columns_of(shape, solution.basis), solution.pivots, inverse)


def solve_ranked(
    shape: LpShape,
    candidates: RankedColumns,
    start: RankedColumns,
    start_table: FloatArray | None = None,
    *,
    max_pivots: int | None = None,
) -> RankedSolution:
    """:func:`lex_simplex` on columns already ranked: the distributed simplex's inner call.

    Args:
        shape: the LP's rows.
        candidates: the candidate columns in key order, each once (as :func:`union` gives
            them), the start basis among them.
        start: a lexicographically feasible basis, m columns.
        start_table: the table of ``start`` as a previous :class:`RankedSolution` returned
            it (trusted: not checked); otherwise it is computed and checked.
        max_pivots: as in :func:`lex_simplex`.

    Raises:
        ModelError: ``start_basis`` as in :func:`lex_simplex`, or when it is not among the
            candidates.
        RuntimeError: the pivot cap was hit (a bug, never expected).
    """
    if start_table is None:
        table = _start_table(shape, start, None, columns_of(shape, start))
    else:
        table = np.array(start_table, dtype=np.float64)
    return _solve(shape, candidates, start.rank, table, max_pivots)


def ranked(shape: LpShape, columns: Sequence[Column], key: str) -> RankedColumns:
    """``columns`` as ranks and costs, in their order.

    Raises:
        ModelError: ``key`` for an index out of range for its kind, or a cost that is not
            finite.
    """
    n = len(columns)
    if n == 0:
        return RankedColumns(np.zeros(0, dtype=np.int64), np.zeros(0))
    rank = _layout(shape, columns, key)[0]
    cost = np.fromiter((c[3] for c in columns), np.float64, n)
    if not bool(np.all(np.isfinite(cost))):
        bad = columns[int(np.flatnonzero(~np.isfinite(cost))[0])]
        raise ModelError(key, bad, "a finite cost")
    return RankedColumns(rank, cost)


def ranked_rows(shape: LpShape, rows: FloatArray) -> RankedColumns | None:
    """:func:`ranked` of columns given as rows ``(kind, robot, task, cost)`` of one array.

    A basis in its wire form becomes one array in a single call instead of reading its
    :class:`Column` objects one by one (``bench/assignment_bench.py`` measures both).

    Returns:
        None unless every kind is a :class:`ColumnKind` value, every index a whole number
        within range for its kind and every cost finite (then :func:`ranked` on the
        columns names what is wrong).
    """
    if rows.ndim != 2 or rows.shape[1] != 4 or not bool(np.all(np.isfinite(rows))):
        return None
    kind, robot, task, cost = rows.T
    kind_ok = (kind >= ColumnKind.PAIR) & (kind <= ColumnKind.UNSERVED) & (kind == np.rint(kind))
    whole = (robot == np.rint(robot)) & (task == np.rint(task))
    rank = _ranks_within(shape, kind, robot, task) if bool(np.all(kind_ok & whole)) else None
    return None if rank is None else RankedColumns(rank, np.ascontiguousarray(cost))


def union(shape: LpShape, parts: Sequence[RankedColumns]) -> RankedColumns:
    """The distinct columns of ``parts`` (a key with the same cost is one column), key order.

    Raises:
        ModelError: ``columns`` for one key with two costs (the first such key in key order,
            its two lowest costs).
    """
    rank = np.concatenate([p.rank for p in parts])
    cost = np.concatenate([p.cost for p in parts])
    r, t = shape
    size = 3 * (r + 1) * (t + 1)  # every rank is below this
    if size <= 8 * rank.size + 4096:
        # marks over all ranks: linear in the columns, no sort
        present = np.zeros(size, dtype=bool)
        present[rank] = True
        value = np.empty(size)
        value[rank] = cost
        if bool(np.all(value[rank] == cost)):
            distinct = np.flatnonzero(present)
            return RankedColumns(distinct, value[distinct])
    order = np.lexsort((cost, rank))
    rank, cost = rank[order], cost[order]
    keep = np.ones(rank.size, dtype=bool)
    keep[1:] = (rank[1:] != rank[:-1]) | (cost[1:] != cost[:-1])
    rank, cost = rank[keep], cost[keep]
    repeated = np.flatnonzero(rank[1:] == rank[:-1])
    if repeated.size:
        k = int(repeated[0])
        pair = columns_of(shape, RankedColumns(rank[k : k + 2], cost[k : k + 2]))
        raise ModelError("columns", tuple(pair), "one cost per column key")
    return RankedColumns(rank, cost)


def columns_of(shape: LpShape, columns: RankedColumns) -> list[Column]:
    """The :class:`Column` of each rank and cost, in their order."""
    return [Column(KINDS[k], i, j, c) for k, i, j, c in rows_of(shape, columns)]


def rows_of(shape: LpShape, columns: RankedColumns) -> list[tuple[int, int, int, float]]:
    """Each rank and cost as a row ``(kind value, robot, task, cost)`` (the wire form)."""
    kind, robot, task = _unrank(shape, columns.rank)
    return list(
        zip(kind.tolist(), robot.tolist(), task.tolist(), columns.cost.tolist(), strict=True)
    )


def _unrank(shape: LpShape, rank: IntArray) -> tuple[IntArray, IntArray, IntArray]:
    """Kind, robot and task index (-1 for none) of each rank: :func:`_layout` inverted."""
    r, t = shape
    rest, task = np.divmod(rank, t + 1)
    kind, robot = np.divmod(rest, r + 1)
    return kind, robot - 1, task - 1


def _start_table(
    shape: LpShape,
    start: RankedColumns,
    start_inverse: FloatArray | None,
    start_basis: Sequence[Column],
) -> FloatArray:
    """``[x_B | B^-1 | 0]`` of ``start`` in its order, checked.

    Raises:
        ModelError: ``start_basis`` / ``start_inverse`` as in :func:`lex_simplex`.
    """
    m = shape.rows
    if start.rank.size != m or np.unique(start.rank).size != m:
        raise ModelError("start_basis", start.rank.size, f"{m} distinct columns")
    first, second = _rows_of(shape, *_unrank(shape, start.rank))
    inverse = _inverse(m, first, second, start_inverse)
    # One table [x_B | B^-1 | 0]: one product-form update per pivot, and candidate column
    # j's w = B^-1 a_j is table[:, 1 + first[j]] + table[:, 1 + second[j]] (second = m -> 0).
    table = np.hstack([inverse.sum(axis=1, keepdims=True), inverse])
    _check_lex_feasible(table, start_basis)
    return table


def _solve(
    shape: LpShape,
    candidates: RankedColumns,
    start_rank: IntArray,
    table: FloatArray,
    max_pivots: int | None,
) -> RankedSolution:
    """Pivot from ``start_rank`` (rows of ``table``, which is updated) to the optimum."""
    m, n = shape.rows, candidates.rank.size
    basis = np.searchsorted(candidates.rank, start_rank)
    if n == 0 or bool(np.any(candidates.rank[np.minimum(basis, n - 1)] != start_rank)):
        raise ModelError("start_basis", "not among the candidates", "a basis of candidates")
    first, second = _rows_of(shape, *_unrank(shape, candidates.rank))
    cost = candidates.cost
    exact = bool(np.all(cost == np.rint(cost))) and float(np.abs(cost).sum()) < _EXACT_INTEGER_SUM
    cap = 20 * (m + n) + 100 if max_pivots is None else max_pivots
    pivots = pivot_loop(cost, first + 1, second + 1, basis, table, exact, cap)
    if pivots == CAP_HIT:
        raise RuntimeError(f"lexicographic simplex hit its cap of {cap} pivots")
    if pivots == UNBOUNDED:
        raise RuntimeError("unbounded direction in a bounded LP: the basis inverse is corrupt")
    order = np.argsort(basis)
    basis = basis[order]
    return RankedSolution(RankedColumns(candidates.rank[basis], cost[basis]), pivots, table[order])


def primal(shape: LpShape, basis: Sequence[Column]) -> FloatArray:
    """The basic values ``x_B = B^-1 1``, in the order of ``basis`` (integers 0 or 1)."""
    _, first, second = _layout(shape, basis, "basis")
    values: FloatArray = _inverse(shape.rows, first, second).sum(axis=1)
    return values


def assignment_of(shape: LpShape, basis: Sequence[Column]) -> dict[int, int]:
    """Robot index -> task index for the pair columns at value 1 in ``basis``."""
    values = primal(shape, basis)
    return {
        c.robot: c.task
        for c, v in zip(basis, values.tolist(), strict=True)
        if c.kind is ColumnKind.PAIR and v > 0.5
    }


def _layout(
    shape: LpShape, columns: Sequence[Column], key: str
) -> tuple[IntArray, IntArray, IntArray]:
    """Each column's rank, first row and second row (m for a one-entry column).

    Ranks are integers increasing with the key ``(kind, robot, task)`` (indices from -1).

    Raises:
        ModelError: ``key`` for an index out of range for its kind.
    """
    r, t = shape
    m = r + t
    whole = _layout_arrays(r, t, columns)
    if whole is not None:
        return whole
    rank, first, second = [], [], []
    for c in columns:
        kind, robot, task = c.kind, c.robot, c.task
        robot_ok = robot == -1 if kind is ColumnKind.UNSERVED else 0 <= robot < r
        task_ok = task == -1 if kind is ColumnKind.IDLE else 0 <= task < t
        if not (robot_ok and task_ok and isinstance(kind, ColumnKind)):
            raise ModelError(key, c, f"indices within {r} robots and {t} tasks")
        rank.append((kind * (r + 1) + robot + 1) * (t + 1) + task + 1)
        first.append(r + task if kind is ColumnKind.UNSERVED else robot)
        second.append(r + task if kind is ColumnKind.PAIR else m)
    return (
        np.array(rank, dtype=np.int64),
        np.array(first, dtype=np.int64),
        np.array(second, dtype=np.int64),
    )


def _layout_arrays(
    r: int, t: int, columns: Sequence[Column]
) -> tuple[IntArray, IntArray, IntArray] | None:
    """:func:`_layout` by whole arrays instead of column by column.

    None unless every kind is a :class:`ColumnKind`, every index an integer and every
    column within range: the loop then names the first column out of range.
    """
    if not columns:
        return None
    kinds, robots, tasks, *_ = zip(*columns, strict=True)
    if not set(map(type, kinds)) <= {ColumnKind}:
        return None
    kind = np.fromiter(kinds, np.int64, len(kinds))
    robot = np.array(robots)
    task = np.array(tasks)
    if robot.dtype.kind != "i" or task.dtype.kind != "i":
        return None
    shape = LpShape(r, t)
    rank = _ranks_within(shape, kind, robot, task)
    return None if rank is None else (rank, *_rows_of(shape, kind, robot, task))


def _ranks_within(
    shape: LpShape, kind: npt.NDArray[Any], robot: npt.NDArray[Any], task: npt.NDArray[Any]
) -> IntArray | None:
    """The ranks of columns given by kind, robot and task arrays (int64).

    None unless every robot and task index is within range for its kind (-1 where the kind
    has none). Kinds must be :class:`ColumnKind` values.
    """
    r, t = shape
    unserved = kind == ColumnKind.UNSERVED
    robot_ok = np.where(unserved, robot == -1, (robot >= 0) & (robot < r))
    task_ok = np.where(kind == ColumnKind.IDLE, task == -1, (task >= 0) & (task < t))
    if not bool(np.all(robot_ok & task_ok)):
        return None
    rank: IntArray = ((kind * (r + 1) + robot + 1) * (t + 1) + task + 1).astype(np.int64)
    return rank


def _rows_of(
    shape: LpShape, kind: npt.NDArray[Any], robot: npt.NDArray[Any], task: npt.NDArray[Any]
) -> tuple[IntArray, IntArray]:
    """Each column's first and second row of ones (m for a one-entry column)."""
    r, t = shape
    first = np.where(kind == ColumnKind.UNSERVED, r + task, robot).astype(np.int64)
    second = np.where(kind == ColumnKind.PAIR, r + task, r + t).astype(np.int64)
    return first, second


def _inverse(
    m: int, first: IntArray, second: IntArray, given: FloatArray | None = None
) -> FloatArray:
    """``B^-1`` with a zero column m appended, exact by total unimodularity.

    The product with B is checked column by column (two ones per column, no BLAS), so a
    wrong ``given`` inverse or a singular basis is caught.

    Raises:
        ModelError: ``start_basis`` when the columns are not independent,
            ``start_inverse`` when ``given`` is not the inverse.
    """
    position = np.arange(m)
    if given is not None:
        inverse = np.array(given, dtype=np.float64)
        key, what = "start_inverse", "the inverse of the start basis"
    elif bool(np.all(second == m)):
        inverse = np.zeros((m, m))
        inverse[position, first] = 1.0  # a permutation matrix: its inverse is its transpose
        key, what = "start_basis", "m linearly independent columns"
    else:
        matrix = np.zeros((m + 1, m))
        matrix[first, position] = 1.0
        matrix[second, position] = 1.0
        key, what = "start_basis", "m linearly independent columns"
        try:
            inverse = np.rint(np.linalg.inv(matrix[:m]))
        except np.linalg.LinAlgError:
            inverse = np.zeros((m, m))
    if inverse.shape != (m, m):
        raise ModelError(key, inverse.shape, what)
    extended = np.hstack([inverse, np.zeros((m, 1))])
    if not np.array_equal(extended[:, first] + extended[:, second], np.eye(m)):
        raise ModelError(key, "not an inverse", what)
    return extended


def _check_lex_feasible(table: FloatArray, basis: Sequence[Column]) -> None:
    """Every row of ``[x_B | B^-1]`` must be lexicographically positive."""
    lead = table[np.arange(len(table)), np.argmax(table != 0.0, axis=1)]
    if not bool(np.all(lead > 0.0)):
        raise ModelError("start_basis", sorted(basis), "a lexicographically feasible basis")
