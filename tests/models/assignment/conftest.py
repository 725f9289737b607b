"""Seeded assignment LPs for the simplex tests, degenerate ones on purpose.

``lp_instance(seed)`` draws R in 1..15 robots, T in 0..15 tasks and one of these cost
styles: floats in [0, 40) m, small integers {1, 2, 3}, all equal (1 or 0), duplicated
robots and tasks (copied rows and columns, float or integer), dyadic fractions {0.25, 0.5,
0.75, 1.5} (exact ties in non-integers) or decimals {0.1, 0.2, 0.3, 0.4} (near-ties at the
rounding level), then an eligibility mask
(none, 30 % or 60 % ineligible pairs, sometimes a task nobody may serve). ``graph(kind,
n, rng)`` gives agent edges: complete, ring, or G(n, 0.3) redrawn until connected.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from models.assignment.dsimplex import _adjacency, graph_diameter
from models.assignment.problem import AssignmentProblem
from models.errors import ModelError

STYLES = ("float", "small_int", "equal", "dup_float", "dup_int", "dyadic", "decimal")
GRAPHS = ("complete", "ring", "random")


def _costs(style: str, n_robots: int, n_tasks: int, rng: np.random.Generator) -> np.ndarray:
    if style == "float":
        return rng.random((n_robots, n_tasks)) * 40.0
    if style == "small_int":
        return rng.integers(1, 4, (n_robots, n_tasks)).astype(float)
    if style == "dyadic":  # not integers, yet exact ties: the exact-sign path decides
        return rng.choice([0.25, 0.5, 0.75, 1.5], (n_robots, n_tasks))
    if style == "decimal":  # 0.1 + 0.2 != 0.3 in binary64: near-ties at rounding level
        return rng.choice([0.1, 0.2, 0.3, 0.4], (n_robots, n_tasks))
    if style == "equal":
        return np.full((n_robots, n_tasks), float(rng.integers(0, 2)))
    base = rng.random((n_robots, n_tasks)) * 40.0
    if style == "dup_int":
        base = rng.integers(1, 4, (n_robots, n_tasks)).astype(float)
    if n_robots > 1:
        base[rng.integers(0, n_robots, n_robots // 2)] = base[rng.integers(0, n_robots)]
    if n_tasks > 1:
        base[:, rng.integers(0, n_tasks, n_tasks // 2)] = base[:, [rng.integers(0, n_tasks)]]
    return base


def lp_instance(seed: int) -> AssignmentProblem:
    rng = np.random.default_rng(seed)
    n_robots, n_tasks = int(rng.integers(1, 16)), int(rng.integers(0, 16))
    cost = _costs(STYLES[seed % len(STYLES)], n_robots, n_tasks, rng)
    cost[rng.random(cost.shape) < rng.choice([0.0, 0.3, 0.6])] = np.inf
    if n_tasks and rng.random() < 0.3:
        cost[:, rng.integers(0, n_tasks)] = np.inf
    robots = tuple(f"robot_{i}" for i in range(n_robots))
    return AssignmentProblem(robots, tuple(range(100, 100 + n_tasks)), cost)


def graph(kind: str, n: int, rng: np.random.Generator) -> list[tuple[int, int]]:
    if kind == "complete":
        return [(a, b) for a in range(n) for b in range(a + 1, n)]
    if kind == "ring":
        return [(a, (a + 1) % n) for a in range(n)] if n > 1 else []
    while True:
        edges = [(a, b) for a in range(n) for b in range(a + 1, n) if rng.random() < 0.3]
        try:
            graph_diameter(_adjacency(n, edges))
        except ModelError:
            continue
        return edges


@pytest.fixture
def make_lp() -> Callable[[int], AssignmentProblem]:
    return lp_instance


@pytest.fixture
def make_graph() -> Callable[[str, int, np.random.Generator], list[tuple[int, int]]]:
    return graph
