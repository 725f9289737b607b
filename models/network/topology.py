"""Undirected communication graphs over host names.

A graph is a ``frozenset`` of edges, each edge a sorted pair of distinct host names
``(a, b)`` with ``a < b``. Set iteration order depends on string hashing, which changes
from one Python process to the next: iterate over ``sorted(edges)`` whenever the order
can reach a result. Functions that return several names return them sorted.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable, Hashable, Iterable, Sequence
from typing import TypeVar

import numpy as np
import numpy.typing as npt

from models.errors import ModelError
from models.network.loss import check_probability

N = TypeVar("N", bound=Hashable)

Edge = tuple[str, str]
Edges = frozenset[Edge]


def edge(a: str, b: str) -> Edge:
    """The undirected edge between ``a`` and ``b``, as a sorted pair."""
    return (a, b) if a < b else (b, a)


def complete(names: Sequence[str]) -> Edges:
    """Every pair of distinct hosts linked."""
    return frozenset(edge(a, b) for i, a in enumerate(names) for b in names[i + 1 :])


def ring(names: Sequence[str]) -> Edges:
    """A cycle through the hosts in the given order (one edge for two hosts, none for one)."""
    n = len(names)
    if n < 2:
        return frozenset()
    return frozenset(edge(names[i], names[(i + 1) % n]) for i in range(n) if n > 2 or i == 0)


def binomial_connected(
    names: Sequence[str], p: float, rng: np.random.Generator, *, max_tries: int = 1000
) -> Edges:
    """An Erdos-Renyi G(n, p) graph, drawn again until it is connected.

    Each try draws ``rng.random(n * (n - 1) // 2)`` and keeps pair (i, j), i < j in the
    order of ``names`` (row by row), when its uniform is < p. This is the scheme of
    ChoiRbot's ``binomial_random_graph`` (redraw until connected) with one draw per
    unordered pair; ChoiRbot draws a full n x n matrix and ORs it with its transpose, so
    its effective edge probability is ``1 - (1 - p)^2`` (pass that to reproduce it).

    Raises:
        ModelError: ``network.edge_prob`` when p is not a probability, or no connected
            graph came up in ``max_tries`` draws.
    """
    check_probability("network.edge_prob", p)
    n = len(names)
    if n < 2:
        return frozenset()
    rows, cols = np.triu_indices(n, k=1)
    for _ in range(max_tries):
        edges = _pairs(names, rows, cols, rng.random(rows.size) < p)
        if is_connected(names, edges):
            return edges
    raise ModelError(
        "network.edge_prob",
        p,
        f"an edge probability for which G({n}, p) is connected within {max_tries} draws",
    )


def explicit(names: Sequence[str], edges: Iterable[Sequence[str]]) -> Edges:
    """The given edges, checked: each a pair of two different known hosts.

    Raises:
        ModelError: ``network.edges`` = the offending edge.
    """
    known = set(names)
    expected = f"pairs of two different known hosts: {', '.join(sorted(known))}"
    result: set[Edge] = set()
    for pair in edges:
        if isinstance(pair, str) or len(pair) != 2:
            raise ModelError("network.edges", pair, expected)
        a, b = pair
        if a not in known or b not in known or a == b:
            raise ModelError("network.edges", list(pair), expected)
        result.add(edge(a, b))
    return frozenset(result)


def within_range(names: Sequence[str], positions: npt.ArrayLike, range_m: float) -> Edges:
    """Hosts linked when their distance is at most ``range_m``.

    Args:
        names: the hosts.
        positions: (n, 2) positions (m) in one common frame, row i for ``names[i]``.
        range_m: the largest linked distance (m, >= 0).

    Raises:
        ModelError: ``network.range_m`` for a negative or NaN range.
        ValueError: if ``positions`` is not (n, 2).
    """
    if not range_m >= 0.0:
        raise ModelError("network.range_m", range_m, "a distance in m >= 0")
    xy = np.asarray(positions, dtype=np.float64)
    n = len(names)
    if xy.shape != (n, 2):
        raise ValueError(f"positions must be ({n}, 2), got {xy.shape}")
    rows, cols = np.triu_indices(n, k=1)
    d = np.hypot(xy[rows, 0] - xy[cols, 0], xy[rows, 1] - xy[cols, 1])
    return _pairs(names, rows, cols, d <= range_m)


def _pairs(
    names: Sequence[str],
    rows: npt.NDArray[np.intp],
    cols: npt.NDArray[np.intp],
    keep: npt.NDArray[np.bool_],
) -> Edges:
    """The edges ``(names[rows[k]], names[cols[k]])`` where ``keep[k]``."""
    kept = zip(rows[keep].tolist(), cols[keep].tolist(), strict=True)
    return frozenset(edge(names[i], names[j]) for i, j in kept)


def _adjacency(names: Sequence[str], edges: Edges) -> dict[str, list[str]]:
    adjacent: dict[str, list[str]] = {name: [] for name in names}
    for a, b in edges:
        if a in adjacent and b in adjacent:
            adjacent[a].append(b)
            adjacent[b].append(a)
    return adjacent


def hops_from(start: N, neighbours: Callable[[N], Iterable[N]]) -> dict[N, int]:
    """Hop counts from ``start`` to every node it reaches (breadth-first search).

    Args:
        start: the first node.
        neighbours: a node's neighbours, e.g. ``adjacency.__getitem__``.
    """
    hops = {start: 0}
    frontier = deque([start])
    while frontier:
        here = frontier.popleft()
        for there in neighbours(here):
            if there not in hops:
                hops[there] = hops[here] + 1
                frontier.append(there)
    return hops


def is_connected(names: Sequence[str], edges: Edges) -> bool:
    """Whether every host reaches every other (true for zero or one host).

    Edges that name hosts outside ``names`` are ignored.
    """
    if len(names) < 2:
        return True
    return len(hops_from(names[0], _adjacency(names, edges).__getitem__)) == len(set(names))


def diameter(names: Sequence[str], edges: Edges) -> float:
    """The largest hop count between two hosts (BFS); ``inf`` if disconnected, 0 for <= 1 host."""
    adjacent = _adjacency(names, edges)
    longest = 0
    for name in adjacent:
        hops = hops_from(name, adjacent.__getitem__)
        if len(hops) < len(adjacent):
            return math.inf
        longest = max(longest, max(hops.values()))
    return float(longest)


def neighbors(edges: Edges, name: str) -> tuple[str, ...]:
    """The hosts linked to ``name``, sorted."""
    return tuple(sorted({b if a == name else a for a, b in edges if name in (a, b)}))
