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
from typing import NamedTuple

import numpy as np

from models.arrays import FloatArray, IntArray
from models.assignment.pivoting import CAP_HIT, UNBOUNDED, pivot_loop
from models.assignment.problem import Column, ColumnKind, LpShape
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
        ModelError: ``columns`` for one key with two costs or an index out of range,
            ``start_basis`` for a basis that is not m independent, lexicographically
            feasible columns, ``start_inverse`` for a matrix that is not its inverse.
        RuntimeError: the pivot cap was hit (a bug, never expected).
    """
    cands = sorted(set(columns).union(start_basis))
    m, n = shape.rows, len(cands)
    rank, first, second = _layout(shape, cands, "columns")
    repeated = np.flatnonzero(rank[1:] == rank[:-1])
    if repeated.size:
        pair = (cands[repeated[0]], cands[repeated[0] + 1])
        raise ModelError("columns", pair, "one cost per column key")
    basis = np.searchsorted(rank, _layout(shape, start_basis, "start_basis")[0]).astype(np.int64)
    if len(start_basis) != m or np.unique(basis).size != m:
        raise ModelError("start_basis", len(start_basis), f"{m} distinct columns")
    cost = np.array([c.cost for c in cands], dtype=np.float64)
    inverse = _inverse(m, first[basis], second[basis], start_inverse)
    # One table [x_B | B^-1 | 0]: one product-form update per pivot, and candidate column
    # j's w = B^-1 a_j is table[:, 1 + first[j]] + table[:, 1 + second[j]] (second = m -> 0).
    table = np.hstack([inverse.sum(axis=1, keepdims=True), inverse])
    _check_lex_feasible(table, start_basis)
    exact = bool(np.all(cost == np.rint(cost))) and float(np.abs(cost).sum()) < _EXACT_INTEGER_SUM
    cap = 20 * (m + n) + 100 if max_pivots is None else max_pivots
    pivots = pivot_loop(cost, first + 1, second + 1, basis, table, exact, cap)
    if pivots == CAP_HIT:
        raise RuntimeError(f"lexicographic simplex hit its cap of {cap} pivots")
    if pivots == UNBOUNDED:
        raise RuntimeError("unbounded direction in a bounded LP: the basis inverse is corrupt")
    order = np.argsort(basis)
    return Solution([cands[k] for k in basis[order].tolist()], pivots, table[order, 1:-1])


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
    """:func:`_layout` by whole arrays, 5x faster on a few hundred columns.

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
    unserved = kind == ColumnKind.UNSERVED
    robot_ok = np.where(unserved, robot == -1, (robot >= 0) & (robot < r))
    task_ok = np.where(kind == ColumnKind.IDLE, task == -1, (task >= 0) & (task < t))
    if not bool(np.all(robot_ok & task_ok)):
        return None
    return (
        ((kind * (r + 1) + robot + 1) * (t + 1) + task + 1).astype(np.int64),
        np.where(unserved, r + task, robot).astype(np.int64),
        np.where(kind == ColumnKind.PAIR, r + task, r + t).astype(np.int64),
    )


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
