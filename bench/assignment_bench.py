"""Distributed simplex cost: solve time per agent per round and rounds to converge.

Cases: N = 4, 16, 50 robots (one agent each) with N and N/2 tasks, robots and tasks at
uniform random positions in a 30 m x 30 m hall, Euclidean costs (m), every pair eligible;
graphs complete and G(N, 0.3) redrawn until connected (``binomial_connected``). Agents run
in lock step as in ``models.assignment.dsimplex.run_synchronous``; every
``merge_and_solve`` call is timed. Reported per case, over ``repeat`` seeds:
``solve_ms_median`` / ``solve_ms_p95`` / ``solve_ms_max`` (one agent, one round: merge
and solve, or merge and skip when no new column arrived), ``solving_rounds_ms_*`` (only
the rounds that ran the simplex),
``rounds_median`` / ``rounds_max`` (until every agent halted, stopping rule included),
``last_change_max`` (the last round a basis changed), ``pivots_max`` and whether every
run agreed with the Hungarian optimum. Run: ``.venv/bin/python bench/assignment_bench.py [repeat]``.
"""

from __future__ import annotations

import json
import statistics
import sys
import time
from typing import Any

import numpy as np

from models.assignment.dsimplex import agent_for, graph_diameter
from models.assignment.problem import AssignmentProblem, hungarian, objective
from models.network.topology import binomial_connected, complete

Result = dict[str, Any]

HALL_M = 30.0
EDGE_PROB = 0.3


def _problem(n_robots: int, n_tasks: int, rng: np.random.Generator) -> AssignmentProblem:
    robots = rng.random((n_robots, 2)) * HALL_M
    tasks = rng.random((n_tasks, 2)) * HALL_M
    cost = np.hypot(*(robots[:, None, :] - tasks[None, :, :]).transpose(2, 0, 1))
    return AssignmentProblem(
        tuple(f"robot_{i}" for i in range(n_robots)), tuple(range(n_tasks)), cost
    )


def _graph(n: int, kind: str, rng: np.random.Generator) -> list[list[int]]:
    names = [f"robot_{i:03d}" for i in range(n)]
    edges = complete(names) if kind == "complete" else binomial_connected(names, EDGE_PROB, rng)
    index = {name: i for i, name in enumerate(names)}
    adjacent: list[list[int]] = [[] for _ in range(n)]
    for a, b in sorted(edges):
        adjacent[index[a]].append(index[b])
        adjacent[index[b]].append(index[a])
    return [sorted(s) for s in adjacent]


def _run(problem: AssignmentProblem, adjacent: list[list[int]]) -> Result:
    bound = graph_diameter(adjacent)
    agents = [agent_for(problem, [i], bound) for i in range(len(problem.robots))]
    times_ms: list[float] = []
    solved_ms: list[float] = []
    rounds = last_change = pivots = 0
    while not all(a.converged for a in agents):
        rounds += 1
        sent = [a.shared_basis() for a in agents]
        for k, agent in enumerate(agents):
            if agent.converged:
                continue
            received = [sent[j] for j in adjacent[k]]
            start = time.perf_counter()
            changed = agent.merge_and_solve(received)
            times_ms.append((time.perf_counter() - start) * 1e3)
            if agent.solved:
                solved_ms.append(times_ms[-1])
            pivots = max(pivots, agent.pivots)
            last_change = rounds if changed else last_change
    agreed = all(a.basis == agents[0].basis for a in agents)
    optimal = objective(problem, agents[0].assignment()) == hungarian(problem)[1]
    return {
        "times_ms": times_ms,
        "solved_ms": solved_ms,
        "rounds": rounds,
        "last_change": last_change,
        "pivots": pivots,
        "diameter": bound,
        "ok": agreed and optimal,
    }


def assignment_solve_stats(repeat: int) -> Result:
    """Median solve time per agent per round (ms) and rounds to converge, per case."""
    _run(_problem(3, 3, np.random.default_rng(0)), [[1, 2], [0, 2], [0, 1]])  # JIT warm-up
    cases: dict[str, Result] = {}
    for n in (4, 16, 50):
        for n_tasks in (n, n // 2):
            for kind in ("complete", "random"):
                runs = []
                for seed in range(1, repeat + 1):
                    rng = np.random.default_rng([seed, n, n_tasks])
                    problem = _problem(n, n_tasks, rng)
                    runs.append(_run(problem, _graph(n, kind, rng)))
                times = sorted(t for r in runs for t in r["times_ms"])
                solved = sorted(t for r in runs for t in r["solved_ms"])
                rounds = [r["rounds"] for r in runs]
                cases[f"n{n}_t{n_tasks}_{kind}"] = {
                    "solve_ms_median": round(statistics.median(times), 3),
                    "solve_ms_p95": round(times[int(0.95 * (len(times) - 1))], 3),
                    "solve_ms_max": round(times[-1], 3),
                    "solving_rounds_ms_median": round(statistics.median(solved), 3),
                    "solving_rounds_ms_p95": round(solved[int(0.95 * (len(solved) - 1))], 3),
                    "rounds_median": statistics.median(rounds),
                    "rounds_max": max(rounds),
                    "last_change_max": max(r["last_change"] for r in runs),
                    "diameter_max": max(r["diameter"] for r in runs),
                    "pivots_max": max(r["pivots"] for r in runs),
                    "all_agree_and_optimal": all(r["ok"] for r in runs),
                }
    return {"cases": cases, "repeat": repeat, "hall_m": HALL_M, "edge_prob": EDGE_PROB}


if __name__ == "__main__":
    print(
        json.dumps(assignment_solve_stats(int(sys.argv[1]) if len(sys.argv) > 1 else 3), indent=2)
    )
