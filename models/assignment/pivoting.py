"""The pivot loop of the lexicographic simplex, compiled with numba.

:mod:`models.assignment.simplex` checks the input and explains the method; this module
is its inner loop over plain arrays, written so that every decision is exact:

* ``table`` is ``[x_B | B^-1 | 0]`` (m x (m + 2)) with entries in {-1, 0, 1}; a candidate
  column j has ones in table columns ``first[j]`` and ``second[j]`` (already shifted by one
  for x_B; a one-entry column's ``second[j]`` is the zero column m + 1), so
  ``w = B^-1 a_j = table[:, first[j]] + table[:, second[j]]``;
* candidates are indexed in the global key order, so an index is a rank.

Each function is written in plain Python (suffix ``_py``) and compiled once; set
``NUMBA_DISABLE_JIT=1`` to step through it in a debugger.
"""

from __future__ import annotations

from typing import Any

import numba
import numpy as np
import numpy.typing as npt

from models.arrays import FloatArray, IntArray

UNIT_ROUNDOFF = 2.0**-52
"""Twice the unit roundoff of float64: the error bound keeps a factor 2 of margin."""

CAP_HIT = -1
"""Returned by the pivot loop when it hit its pivot cap."""

UNBOUNDED = -2
"""Returned by the pivot loop when an entering column had no positive entry."""


def _exact_sign_py(
    table: FloatArray, j0: int, j1: int, cost_j: float, basic_cost: FloatArray
) -> int:
    """The exact sign of ``cost_j - sum_k w_k basic_cost_k``, ``w = table[:, j0] + table[:, j1]``.

    Shewchuk's grow-expansion (the algorithm of ``math.fsum``): the partial sums stay
    exact and non-overlapping, ordered by magnitude, so the largest nonzero one carries
    the sign of the exact sum. Every term ``w_k c_k`` is exact because ``w_k`` is in
    {-1, 0, 1}.
    """
    m = table.shape[0]
    partials = np.zeros(m + 1)
    count = 0
    for k in range(-1, m):
        if k < 0:
            x = cost_j
        else:
            w = table[k, j0] + table[k, j1]
            if w == 0.0:
                continue
            x = -w * basic_cost[k]
        kept = 0
        for i in range(count):
            p = partials[i]
            if abs(x) < abs(p):
                x, p = p, x
            high = x + p
            low = p - (high - x)
            if low != 0.0:
                partials[kept] = low
                kept += 1
            x = high
        partials[kept] = x
        count = kept + 1
    for i in range(count - 1, -1, -1):
        if partials[i] > 0.0:
            return 1
        if partials[i] < 0.0:
            return -1
    return 0


def _perturbation_negative_py(table: FloatArray, j0: int, j1: int, j: int, basis: IntArray) -> bool:
    """For a zero reduced cost: whether the perturbation term of column j is negative.

    The term is ``e^rank(j) - sum_k w_k e^rank(B_k)``; the lowest rank among j and the basic
    columns with ``w_k != 0`` decides it, and it is negative only when that is a basic
    column with ``w_k > 0``.
    """
    lowest = j
    weight = 0.0
    for k in range(table.shape[0]):
        w = table[k, j0] + table[k, j1]
        if w != 0.0 and basis[k] < lowest:
            lowest = basis[k]
            weight = w
    return weight > 0.0


def _entering_py(
    cost: FloatArray,
    first: IntArray,
    second: IntArray,
    basis: IntArray,
    in_basis: npt.NDArray[np.bool_],
    table: FloatArray,
    exact: bool,
) -> int:
    """The entering column, or -1 when the basis is lexicographically optimal.

    The most negative reduced cost that is surely negative (ties to the smallest rank);
    else the smallest rank whose reduced cost is, exactly, negative, or zero with a
    negative perturbation term. Float reduced costs are trusted outside the bound
    ``(2m + 8) u (max|c| + 2 sum|c_B|)`` on their rounding error (0 when ``exact``).
    """
    m, width = table.shape
    basic_cost = np.empty(m)
    dual = np.zeros(width)
    basic_sum = 0.0
    for k in range(m):
        basic_cost[k] = cost[basis[k]]
        basic_sum += abs(basic_cost[k])
        if basic_cost[k] != 0.0:
            for c in range(width):
                dual[c] += basic_cost[k] * table[k, c]
    largest = 0.0
    for j in range(cost.size):
        largest = max(largest, abs(cost[j]))
    bound = 0.0 if exact else (2 * m + 8) * UNIT_ROUNDOFF * (largest + 2.0 * basic_sum)
    reduced = np.empty(cost.size)
    best = -1
    best_value = -bound
    for j in range(cost.size):
        if in_basis[j]:
            reduced[j] = np.inf
            continue
        reduced[j] = cost[j] - dual[first[j]] - dual[second[j]]
        if reduced[j] < best_value:
            best_value = reduced[j]
            best = j
    if best >= 0:
        return best
    for j in range(cost.size):
        if abs(reduced[j]) > bound:
            continue
        sign = 0 if exact else _exact_sign(table, first[j], second[j], cost[j], basic_cost)
        if sign < 0:
            return j
        if sign == 0 and _perturbation_negative(table, first[j], second[j], j, basis):
            return j
    return -1


def _leaving_py(w: FloatArray, table: FloatArray) -> int:
    """The lexicographic minimum of the rows ``k`` with ``w_k > 0`` (each ``w_k`` is 1).

    Rows of ``B^-1`` are independent, so the minimum is unique. -1: no such row.
    """
    leaving = -1
    for k in range(table.shape[0]):
        if w[k] <= 0.0:
            continue
        if leaving < 0:
            leaving = k
            continue
        for c in range(table.shape[1]):
            if table[k, c] != table[leaving, c]:
                if table[k, c] < table[leaving, c]:
                    leaving = k
                break
    return leaving


def _pivot_loop_py(
    cost: FloatArray,
    first: IntArray,
    second: IntArray,
    basis: IntArray,
    table: FloatArray,
    exact: bool,
    cap: int,
) -> int:
    """Pivot ``basis`` and ``table`` in place to the lexicographic optimum.

    Returns:
        The number of pivots, or ``CAP_HIT`` / ``UNBOUNDED``.
    """
    m, width = table.shape
    in_basis = np.zeros(cost.size, dtype=np.bool_)
    for k in range(m):
        in_basis[basis[k]] = True
    pivots = 0
    w = np.empty(m)
    pivot_row = np.empty(width)
    while True:
        entering = _entering(cost, first, second, basis, in_basis, table, exact)
        if entering < 0:
            return pivots
        if pivots >= cap:
            return CAP_HIT
        for k in range(m):
            w[k] = table[k, first[entering]] + table[k, second[entering]]
        leaving = _leaving(w, table)
        if leaving < 0:
            return UNBOUNDED
        pivot_row[:] = table[leaving]
        for k in range(m):
            if k != leaving and w[k] != 0.0:  # the pivot element w[leaving] is exactly 1
                for c in range(width):
                    table[k, c] -= w[k] * pivot_row[c]
        in_basis[basis[leaving]] = False
        in_basis[entering] = True
        basis[leaving] = entering
        pivots += 1


_exact_sign: Any = numba.njit(cache=True, nogil=True)(_exact_sign_py)
_perturbation_negative: Any = numba.njit(cache=True, nogil=True)(_perturbation_negative_py)
_entering: Any = numba.njit(cache=True, nogil=True)(_entering_py)
_leaving: Any = numba.njit(cache=True, nogil=True)(_leaving_py)
_pivot_loop: Any = numba.njit(cache=True, nogil=True)(_pivot_loop_py)


def pivot_loop(
    cost: FloatArray,
    first: IntArray,
    second: IntArray,
    basis: IntArray,
    table: FloatArray,
    exact: bool,
    cap: int,
) -> int:
    """Pivot ``basis`` and ``table`` in place to the lexicographic optimum (compiled).

    Args:
        cost: candidate costs, candidates in key order.
        first: each candidate's first table column (row index + 1).
        second: its second table column (row index + 1, or m + 1 for none).
        basis: candidate index of each basic position; updated in place.
        table: ``[x_B | B^-1 | 0]`` of ``basis``; updated in place.
        exact: whether float arithmetic on these costs is exact (integers, small sum).
        cap: the most pivots allowed.

    Returns:
        The number of pivots, or ``CAP_HIT`` / ``UNBOUNDED``.
    """
    return int(_pivot_loop(cost, first, second, basis, table, exact, cap))
