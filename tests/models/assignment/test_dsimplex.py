"""The distributed simplex: agreement, optimality, halting.

What Bürger et al. (2012) prove: every agent's basis converges in finite time to the
lexicographically optimal basis, and an agent whose basis has not changed for
2 * diameter + 1 rounds may halt because every agent holds it. They give no bound on the
rounds before the last change in terms of the diameter (only finiteness: the
lexicographic objective falls with each change and there are finitely many bases). The
bound asserted here, rounds <= 8 (2 diam + 1), is empirical: over 4,000 seeds of these
instance families the largest ratio measured was 5.33 (16 rounds, diameter 1).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from models.assignment.dsimplex import SharedBasis, SimplexAgent, agent_for, run_synchronous
from models.assignment.problem import (
    AssignmentProblem,
    LpShape,
    hungarian,
    idle,
    objective,
    pair,
    unserved,
)
from models.assignment.simplex import assignment_of, columns_of, primal, ranked, solve
from models.errors import ModelError

GRAPHS = ("complete", "ring", "random")
ROUNDS_PER_STOPPING_WINDOW = 8


def _diameter(n: int, edges: list[tuple[int, int]]) -> int:
    from models.assignment.dsimplex import _adjacency, graph_diameter

    return graph_diameter(_adjacency(n, edges))


def _network(seed, make_lp, make_graph):
    """Seed's problem, each robot's neighbours in a graph of GRAPHS, and the diameter."""
    problem = make_lp(seed)
    n = len(problem.robots)
    edges = make_graph(GRAPHS[seed % 3], n, np.random.default_rng(seed + 10**6))
    neighbours = {
        i: [j for a, b in edges for i2, j in ((a, b), (b, a)) if i2 == i] for i in range(n)
    }
    return problem, neighbours, _diameter(n, edges)


@pytest.mark.parametrize("chunk", range(5))
def test_every_agent_ends_with_the_central_optimum_on_random_instances(chunk, make_lp, make_graph):
    for seed in range(100 * chunk, 100 * chunk + 100):
        problem = make_lp(seed)
        n = len(problem.robots)
        kind = GRAPHS[seed % 3]
        edges = make_graph(kind, n, np.random.default_rng(seed + 10**6))
        diameter = _diameter(n, edges)
        result = run_synchronous(problem, list(range(n)), edges)
        central = tuple(solve(problem.shape, problem.columns(), problem.start_basis()))
        where = f"seed {seed}, {kind} graph, diameter {diameter}"
        assert all(basis == central for basis in result.bases), where
        assert objective(problem, result.assignment) == hungarian(problem)[1], where
        window = 2 * diameter + 1
        assert result.rounds == max(result.halted_at) <= result.last_change + window, where
        assert min(result.halted_at) >= window, where
        assert result.rounds <= ROUNDS_PER_STOPPING_WINDOW * window, where


def test_an_agent_halts_after_two_diameter_bounds_plus_one_unchanged_rounds():
    problem = AssignmentProblem(("a", "b"), (7, 8), np.array([[1.0, 2.0], [2.0, 1.0]]))
    agent = agent_for(problem, [0, 1], diameter_bound=2)
    assert agent.merge_and_solve([]) is True
    for round_ in range(2, 7):
        assert not agent.converged
        assert agent.merge_and_solve([]) is False
        assert agent.unchanged == round_ - 1
    assert agent.converged and agent.rounds == 6
    assert agent.assignment() == {0: 0, 1: 1}


def test_each_agents_objective_never_increases_from_round_to_round(make_lp, make_graph):
    for seed in range(30):
        problem = make_lp(seed)
        n = len(problem.robots)
        edges = make_graph("ring", n, np.random.default_rng(seed))
        neighbours = [[b if a == k else a for a, b in edges if k in (a, b)] for k in range(n)]
        agents = [agent_for(problem, [k], _diameter(n, edges)) for k in range(n)]
        last = [math.inf] * n
        while not all(a.converged for a in agents):
            sent = [a.basis for a in agents]
            for k, agent in enumerate(agents):
                agent.merge_and_solve([sent[j] for j in neighbours[k]])
                values = primal(problem.shape, agent.basis)
                value = math.fsum(c.cost * v for c, v in zip(agent.basis, values, strict=True))
                assert value <= last[k], f"seed {seed}, agent {k}"
                last[k] = value


def test_agents_owning_several_robots_or_none_agree_on_the_optimum():
    rng = np.random.default_rng(4)
    problem = AssignmentProblem(
        tuple(f"r{i}" for i in range(6)), tuple(range(5)), rng.integers(1, 4, (6, 5)) * 1.0
    )
    owner = [0, 0, 2, 2, 3, 3]  # agent 1 owns no robot and only relays
    result = run_synchronous(problem, owner, [(0, 1), (1, 2), (2, 3)])
    assert len(set(result.bases)) == 1
    assert objective(problem, result.assignment) == hungarian(problem)[1]


def test_a_loose_diameter_bound_halts_later_with_the_same_answer(make_lp, make_graph):
    problem = make_lp(8)
    n = len(problem.robots)
    edges = make_graph("ring", n, np.random.default_rng(0))
    tight = run_synchronous(problem, list(range(n)), edges)
    loose = run_synchronous(problem, list(range(n)), edges, _diameter(n, edges) + 3)
    assert loose.bases == tight.bases
    assert loose.rounds == tight.rounds + 6


def test_overlapping_received_bases_are_merged_by_key():
    rng = np.random.default_rng(2)
    problem = AssignmentProblem(("a", "b", "c"), (1, 2, 3), rng.random((3, 3)))
    other = agent_for(problem, [1, 2], 1)
    other.merge_and_solve([])
    once, thrice = agent_for(problem, [0], 1), agent_for(problem, [0], 1)
    once.merge_and_solve([other.basis])
    thrice.merge_and_solve([other.basis, list(other.basis), other.basis])
    assert once.basis == thrice.basis


def test_a_round_without_new_columns_skips_the_solve_and_keeps_the_basis():
    problem = AssignmentProblem(("a", "b"), (1,), np.array([[2.0], [1.0]]))
    agent = agent_for(problem, [0, 1], 1)
    agent.merge_and_solve([])
    assert agent.solved
    basis = agent.basis
    assert agent.merge_and_solve([basis]) is False
    assert not agent.solved and agent.basis == basis and agent.unchanged == 1


def test_fifty_robots_in_a_hall_reach_the_hungarian_optimum_on_a_sparse_graph(make_graph):
    rng = np.random.default_rng(50)
    robots, tasks = rng.random((50, 2)) * 30.0, rng.random((40, 2)) * 30.0
    cost = np.linalg.norm(robots[:, None, :] - tasks[None, :, :], axis=2)
    problem = AssignmentProblem(tuple(f"r{i}" for i in range(50)), tuple(range(40)), cost)
    result = run_synchronous(problem, list(range(50)), make_graph("random", 50, rng))
    assert len(set(result.bases)) == 1
    assert objective(problem, result.assignment) == hungarian(problem)[1]


def test_a_received_basis_of_the_wrong_size_is_rejected():
    problem = AssignmentProblem(("a",), (1,), np.array([[1.0]]))
    agent = agent_for(problem, [0], 0)
    with pytest.raises(ModelError) as raised:
        agent.merge_and_solve([agent.basis[:1]])
    assert raised.value.key == "received"


@pytest.mark.parametrize(
    ("owner", "edges", "bound", "key"),
    [
        ([0, 1, 2], [(0, 1)], None, "network.edges"),
        ([0, 1, 2], [(0, 1), (1, 1)], None, "network.edges"),
        ([0, 1, 2], [(0, 1), (1, 2)], 1, "assignment.diameter_bound"),
        ([0, 1], [(0, 1)], None, "assignment.owner"),
    ],
)
def test_synchronous_runs_reject_bad_graphs_bounds_and_owners(owner, edges, bound, key):
    problem = AssignmentProblem(("a", "b", "c"), (1,), np.ones((3, 1)))
    with pytest.raises(ModelError) as raised:
        run_synchronous(problem, owner, edges, bound)
    assert raised.value.key == key


def test_a_negative_diameter_bound_is_rejected():
    problem = AssignmentProblem(("a",), (1,), np.ones((1, 1)))
    with pytest.raises(ModelError):
        SimplexAgent(problem.shape, [], -1, 0, unserved_cost=problem.unserved_cost)


def test_the_agent_reads_its_assignment_from_values_not_from_degenerate_columns():
    # all costs equal: the optimal basis holds pair columns at 0 next to ones at 1
    problem = AssignmentProblem(tuple("abcd"), (1, 2, 3), np.ones((4, 3)))
    result = run_synchronous(problem, [0, 1, 2, 3], [(0, 1), (1, 2), (2, 3)])
    pairs = [c for c in result.bases[0] if c.kind.name == "PAIR"]
    assignment = assignment_of(problem.shape, list(result.bases[0]))
    assert len(assignment) == 3 and len(set(assignment.values())) == 3
    assert len(pairs) >= len(assignment)


def test_the_agent_objective_counts_only_columns_at_one():
    problem = AssignmentProblem(tuple("abcd"), (1, 2, 3), np.ones((4, 3)))
    agent = agent_for(problem, range(4), 0)
    agent.merge_and_solve([])
    assert agent.objective() == objective(problem, agent.assignment()) == 3.0


@pytest.mark.parametrize("seed", range(12))
def test_bases_resent_as_the_same_objects_give_the_rounds_fresh_copies_give(
    seed, make_lp, make_graph
):
    problem, neighbours, bound = _network(seed, make_lp, make_graph)
    n = len(problem.robots)
    shared = [agent_for(problem, [i], bound) for i in range(n)]
    fresh = [agent_for(problem, [i], bound) for i in range(n)]
    sent: list[list] = [[] for _ in range(n)]  # what each shared agent sends, kept until it changes
    for _round in range(ROUNDS_PER_STOPPING_WINDOW * (2 * bound + 1)):
        inbox_shared = [[sent[j] for j in neighbours[i] if sent[j]] for i in range(n)]
        inbox_fresh = [[list(fresh[j].basis) for j in neighbours[i] if sent[j]] for i in range(n)]
        for i in range(n):
            a = shared[i].merge_and_solve(inbox_shared[i])
            b = fresh[i].merge_and_solve(inbox_fresh[i])
            assert (a, shared[i].basis, shared[i].unchanged) == (
                b,
                fresh[i].basis,
                fresh[i].unchanged,
            )
        sent = [s if s and s == shared[i].basis else shared[i].basis for i, s in enumerate(sent)]


@pytest.mark.parametrize("seed", range(3))
def test_bases_received_laid_out_once_give_the_rounds_plain_lists_give(seed, make_lp, make_graph):
    problem, neighbours, bound = _network(seed, make_lp, make_graph)
    n = len(problem.robots)
    keyed = [agent_for(problem, [i], bound) for i in range(n)]
    plain = [agent_for(problem, [i], bound) for i in range(n)]
    sent: list[SharedBasis | None] = [None] * n  # kept until the basis changes
    solves = 0
    for _round in range(ROUNDS_PER_STOPPING_WINDOW * (2 * bound + 1)):
        inbox_keyed = [[sent[j] for j in neighbours[i] if sent[j] is not None] for i in range(n)]
        inbox_plain = [[list(b) for b in inbox] for inbox in inbox_keyed]
        for i in range(n):
            a = keyed[i].merge_and_solve(inbox_keyed[i])
            b = plain[i].merge_and_solve(inbox_plain[i])
            assert (a, keyed[i].solved, keyed[i].basis, keyed[i].unchanged) == (
                b,
                plain[i].solved,
                plain[i].basis,
                plain[i].unchanged,
            )
            solves += keyed[i].solved
        sent = [
            s if s is not None and list(s) == keyed[i].basis else SharedBasis(keyed[i].basis)
            for i, s in enumerate(sent)
        ]
    assert solves > n  # the sets were merged into solves, not only skipped
    assert all(agent.converged for agent in keyed)


def test_a_basis_from_rows_keeps_its_columns_and_lays_them_out_as_they_would_be():
    shape = LpShape(2, 3)
    rows = ((0, 1, 2, 3.5), (1, 0, -1, 0.0), (2, -1, 0, 1e6))
    basis = SharedBasis.from_rows(rows)
    assert list(basis) == [pair(1, 2, 3.5), idle(0), unserved(0, 1e6)]
    ranks = basis.ranked_in(shape)
    assert columns_of(shape, ranks) == list(basis)


@pytest.mark.parametrize("rows", [((3, 0, 0, 1.0),), ((0, 0, 0),), (("x", 0, 0, 1.0),)])
def test_a_basis_from_rows_that_are_not_columns_is_rejected_when_read_or_laid_out(rows):
    with pytest.raises(ModelError) as raised:
        list(SharedBasis.from_rows(rows))
    assert raised.value.key == "columns"
    with pytest.raises(ModelError) as raised:
        SharedBasis.from_rows(rows).ranked_in(LpShape(2, 2))
    assert raised.value.key == "columns"


def test_an_agent_merging_a_basis_from_rows_never_builds_its_columns():
    problem = AssignmentProblem(("a", "b"), (1, 2), np.array([[1.0, 2.0], [2.0, 1.0]]))
    sender, receiver = agent_for(problem, [1], 0), agent_for(problem, [0], 0)
    sender.merge_and_solve([])
    wire = SharedBasis.from_rows(sender.basis_rows())
    receiver.merge_and_solve([wire])
    assert wire._columns is None  # laid out from its rows only
    assert wire == sender.basis
    assert receiver.assignment() == {0: 0, 1: 1}  # robot 1's column came through the rows


def test_a_basis_from_rows_out_of_range_is_named_when_it_is_laid_out():
    basis = SharedBasis.from_rows(((0, 5, 0, 1.0),))
    with pytest.raises(ModelError, match="indices within") as raised:
        basis.ranked_in(LpShape(2, 2))
    assert raised.value.value == pair(5, 0, 1.0)


def test_an_agent_sends_one_shared_basis_until_its_basis_changes():
    problem = AssignmentProblem(("a", "b"), (1, 2), np.array([[1.0, 2.0], [2.0, 1.0]]))
    agent = agent_for(problem, [0, 1], 0)
    first = agent.shared_basis()
    assert agent.shared_basis() is first and first == agent.basis
    assert agent.merge_and_solve([]) is True
    second = agent.shared_basis()
    assert second is not first and second == agent.basis
    laid_out = ranked(problem.shape, agent.basis, "columns")
    assert np.array_equal(second.ranked_in(problem.shape).rank, laid_out.rank)
    assert agent.merge_and_solve([second]) is False and agent.shared_basis() is second
