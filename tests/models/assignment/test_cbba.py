import itertools
import math
from dataclasses import dataclass

import numpy as np
import pytest
from scipy.optimize import linear_sum_assignment

from models.assignment.cbba import (
    CbbaAgent,
    CbbaResult,
    convergence_bound,
    graph_diameter,
    run_synchronous,
    scores_from_cost,
    sequential_greedy_auction,
)
from models.assignment.greedy import greedy_global, total_cost

INF = math.inf
SEEDS = range(330)
GRAPHS = ("complete", "ring", "random")


@dataclass(frozen=True)
class Instance:
    seed: int
    cost: np.ndarray
    graph: str
    edges: tuple[tuple[int, int], ...]


def random_edges(n: int, rng: np.random.Generator) -> set[tuple[int, int]]:
    """A random spanning tree plus each other pair with probability 0.2: connected."""
    order = rng.permutation(n).tolist()
    edges = {tuple(sorted((order[k], order[int(rng.integers(k))]))) for k in range(1, n)}
    extra = rng.random(n * (n - 1) // 2) < 0.2
    pairs = itertools.combinations(range(n), 2)
    edges |= {pair for pair, keep in zip(pairs, extra, strict=True) if keep}
    return edges


def make_instance(seed: int) -> Instance:
    """Up to 15 x 15; a third each complete / ring / random; eligibility masks; some ties."""
    rng = np.random.default_rng(seed)
    n_robots, n_tasks = (int(v) for v in rng.integers(1, 16, size=2))
    if seed % 5 == 4:  # small integer costs: many ties
        cost = rng.integers(1, 4, size=(n_robots, n_tasks)).astype(float)
    else:
        cost = rng.uniform(0.5, 40.0, size=(n_robots, n_tasks))
    if seed % 3 != 0:
        cost[rng.random((n_robots, n_tasks)) > rng.uniform(0.2, 1.0)] = INF
    graph = GRAPHS[seed % 3 if seed % 2 else (seed // 2) % 3]
    if graph == "complete":
        edges = set(itertools.combinations(range(n_robots), 2))
    elif graph == "ring":
        edges = {tuple(sorted((i, (i + 1) % n_robots))) for i in range(n_robots) if n_robots > 1}
    else:
        edges = random_edges(n_robots, rng)
    return Instance(seed, cost, graph, tuple(sorted(edges)))


@pytest.fixture(scope="module")
def runs() -> list[tuple[Instance, CbbaResult]]:
    instances = [make_instance(seed) for seed in SEEDS]
    return [(inst, run_synchronous(inst.cost, inst.edges)) for inst in instances]


def test_the_random_instances_cover_every_graph_eligibility_masks_and_ties(runs):
    assert len(runs) >= 300
    assert {inst.graph for inst, _ in runs} == set(GRAPHS)
    assert max(inst.cost.shape[0] for inst, _ in runs) == 15
    assert any(np.isinf(inst.cost).any() for inst, _ in runs)
    assert any(inst.cost.shape[0] > inst.cost.shape[1] for inst, _ in runs)
    assert any(inst.cost.shape[0] < inst.cost.shape[1] for inst, _ in runs)
    assert max(res.diameter for _, res in runs) >= 7


def test_every_final_assignment_is_conflict_free_and_eligible(runs):
    for inst, res in runs:
        tasks = list(res.assignment.values())
        assert len(set(tasks)) == len(tasks), inst.seed
        assert all(math.isfinite(inst.cost[i, j]) for i, j in res.assignment.items()), inst.seed


def test_every_agent_agrees_on_the_winners(runs):
    for inst, res in runs:
        for agent in res.agents:
            assert agent.assignment() == res.assignment, inst.seed
            assert np.array_equal(agent.z, res.agents[0].z), inst.seed
            assert np.array_equal(agent.y, res.agents[0].y), inst.seed


def test_no_robot_is_left_idle_while_an_eligible_task_is_free(runs):
    for inst, res in runs:
        free = set(range(inst.cost.shape[1])) - set(res.assignment.values())
        for robot in set(range(inst.cost.shape[0])) - set(res.assignment):
            assert not any(math.isfinite(inst.cost[robot, j]) for j in free), inst.seed


def test_convergence_takes_at_most_n_min_times_diameter_rounds(runs):
    for inst, res in runs:
        n_robots, n_tasks = inst.cost.shape
        assert res.bound == min(n_robots, n_tasks) * max(res.diameter, 1)
        assert res.rounds <= res.bound, inst.seed
        assert res.rounds_run == res.rounds + res.diameter + 1, inst.seed


def test_the_fixed_point_is_the_sequential_greedy_auction(runs):
    for inst, res in runs:
        assert res.assignment == sequential_greedy_auction(scores_from_cost(inst.cost)), inst.seed
        # scores are reward - cost: the best score is the cheapest pair, with the same ties
        assert res.assignment == greedy_global(inst.cost), inst.seed


def test_the_total_score_is_at_least_half_of_the_optimum(runs):
    for inst, res in runs:
        scores = scores_from_cost(inst.cost)
        weights = np.where(np.isfinite(scores), scores, 0.0)  # an ineligible pair adds nothing
        rows, cols = linear_sum_assignment(weights, maximize=True)
        optimum = weights[rows, cols].sum()
        achieved = sum(scores[i, j] for i, j in res.assignment.items())
        assert achieved >= 0.5 * optimum - 1e-9, inst.seed


def test_cbba_is_not_always_optimal_in_total_cost():
    # robot 0 grabs its cheapest task, leaving robot 1 the far one: 1 + 100 against 2 + 2
    cost = np.array([[1.0, 2.0], [2.0, 100.0]])
    result = run_synchronous(cost, [(0, 1)])
    rows, cols = linear_sum_assignment(cost)
    assert result.assignment == {0: 0, 1: 1}
    assert total_cost(cost, result.assignment) == 101.0
    assert cost[rows, cols].sum() == 4.0


def test_cbba_costs_more_than_the_hungarian_optimum_on_many_random_fleets(runs):
    worse = 0
    for inst, res in runs:
        if np.isinf(inst.cost).any():
            continue
        rows, cols = linear_sum_assignment(inst.cost)
        optimum = inst.cost[rows, cols].sum()
        achieved = total_cost(inst.cost, res.assignment)
        assert len(res.assignment) == len(rows), inst.seed
        assert achieved >= optimum - 1e-9, inst.seed
        worse += achieved > optimum + 1e-9
    assert worse >= 10


def test_equal_costs_go_to_the_lower_robot_and_then_the_lower_task():
    result = run_synchronous(np.ones((3, 3)), [(0, 1), (1, 2)])
    assert result.assignment == {0: 0, 1: 1, 2: 2}
    # robot 2 and robot 1 tie on task 0, robot 1 wins it; robot 2 takes what is left
    cost = np.array([[INF, INF], [1.0, 5.0], [1.0, 2.0]])
    assert run_synchronous(cost, [(0, 1), (0, 2)]).assignment == {1: 0, 2: 1}


def test_runs_repeat_exactly_and_do_not_depend_on_the_edge_order():
    inst = make_instance(7)
    first = run_synchronous(inst.cost, inst.edges)
    again = run_synchronous(inst.cost, [(b, a) for a, b in reversed(inst.edges)])
    assert (first.assignment, first.rounds, first.rounds_run) == (
        again.assignment,
        again.rounds,
        again.rounds_run,
    )


def test_a_single_robot_takes_its_best_task_in_one_round():
    result = run_synchronous(np.array([[3.0, 1.0, INF]]), [])
    assert result.assignment == {0: 1}
    assert (result.rounds, result.diameter, result.bound) == (1, 0, 1)


def test_a_robot_without_eligible_tasks_never_bids_and_stays_unassigned():
    cost = np.array([[INF, INF], [4.0, 3.0]])
    result = run_synchronous(cost, [(0, 1)])
    assert result.assignment == {1: 1}
    assert result.agents[0].x is None


def test_a_line_of_robots_needs_the_news_to_travel_its_diameter():
    # all robots prefer task 0, robot 0 (one end) wins it; the other end hears at round 4
    cost = np.tile([1.0, 2.0, 3.0, 4.0, 5.0], (5, 1))
    result = run_synchronous(cost, [(i, i + 1) for i in range(4)])
    assert result.diameter == 4
    assert result.assignment == {i: i for i in range(5)}
    assert result.rounds <= result.bound == 20


def test_an_agent_bids_on_its_best_task_it_can_win():
    agent = CbbaAgent(1, [5.0, 9.0, 7.0], n_robots=3)
    agent.y[:] = [0.0, 9.5, 0.0]
    agent.z[:] = [-1, 0, -1]
    assert agent.bid()
    assert agent.x == 2
    assert agent.y.tolist() == [0.0, 9.5, 7.0] and agent.z.tolist() == [-1, 0, 1]
    assert not agent.bid()  # already holds a task


def test_an_agent_wins_a_tie_only_against_a_higher_robot_index():
    agent = CbbaAgent(1, [4.0, 4.0], n_robots=3)
    agent.y[:] = [4.0, 4.0]
    agent.z[:] = [0, 2]
    assert agent.bid()
    assert agent.x == 1 and agent.z.tolist() == [0, 1]


def test_an_agent_never_bids_on_an_ineligible_task():
    agent = CbbaAgent(0, [np.nan, -np.inf, 2.0], n_robots=1)
    assert agent.bid() and agent.x == 2
    lonely = CbbaAgent(0, [np.nan, -np.inf], n_robots=1)
    assert not lonely.bid() and lonely.x is None


def test_an_outbid_agent_releases_its_task_and_bids_again():
    agent = CbbaAgent(1, [6.0, 3.0], n_robots=2)
    agent.bid()
    assert agent.x == 0
    assert agent.consensus([(np.array([6.0, 0.0]), np.array([0, -1]))])  # tie, robot 0 wins
    assert agent.x is None and agent.z.tolist() == [0, -1]
    assert agent.bid() and agent.x == 1


def test_a_better_bid_from_a_neighbour_on_another_task_leaves_the_own_task_held():
    agent = CbbaAgent(0, [6.0, 3.0], n_robots=2)
    agent.bid()
    assert agent.consensus([(np.array([0.0, 8.0]), np.array([-1, 1]))])
    assert agent.x == 0 and agent.y.tolist() == [6.0, 8.0] and agent.z.tolist() == [0, 1]


def test_consensus_ignores_message_order_and_duplicates():
    rng = np.random.default_rng(3)
    messages = [
        (rng.integers(0, 3, 6).astype(float), rng.integers(0, 4, 6).astype(np.int64))
        for _ in range(5)
    ]
    messages = [(y, np.where(y == 0, -1, z)) for y, z in messages]
    merged = []
    for order in ([0, 1, 2, 3, 4], [4, 2, 0, 3, 1], [1, 1, 4, 0, 2, 3, 3]):
        agent = CbbaAgent(0, np.ones(6), n_robots=4)
        agent.consensus([messages[k] for k in order])
        merged.append((agent.y.tolist(), agent.z.tolist()))
    assert merged[0] == merged[1] == merged[2]
    one_by_one = CbbaAgent(0, np.ones(6), n_robots=4)
    for k in [3, 0, 4, 1, 2, 0]:  # late and repeated messages one at a time
        one_by_one.consensus([messages[k]])
    assert (one_by_one.y.tolist(), one_by_one.z.tolist()) == merged[0]


def test_an_agent_counts_quiet_rounds_until_converged():
    agent = CbbaAgent(0, [1.0], n_robots=1)
    agent.bid()
    agent.consensus([])
    assert agent.unchanged_rounds == 0 and not agent.converged(1)
    for _ in range(2):
        assert not agent.bid()
        assert not agent.consensus([])
    assert agent.unchanged_rounds == 2 and agent.rounds == 3
    assert agent.converged(1) and not agent.converged(2)


def test_messages_are_copies():
    agent = CbbaAgent(0, [1.0, 2.0], n_robots=1)
    message = agent.message()
    message.y[0] = 99.0
    message.z[0] = 5
    assert agent.y.tolist() == [0.0, 0.0] and agent.z.tolist() == [-1, -1]


def test_malformed_agents_and_messages_are_rejected():
    with pytest.raises(ValueError, match="robot = 3"):
        CbbaAgent(3, [1.0], n_robots=3)
    with pytest.raises(ValueError, match="> 0"):
        CbbaAgent(0, [0.0, 1.0], n_robots=1)
    with pytest.raises(ValueError, match="> 0"):
        CbbaAgent(0, [np.inf], n_robots=1)
    agent = CbbaAgent(0, [1.0, 2.0], n_robots=2)
    with pytest.raises(ValueError, match="shapes"):
        agent.consensus([(np.zeros(3), np.full(3, -1))])
    with pytest.raises(ValueError, match="winners"):
        agent.consensus([(np.ones(2), np.array([0, 2]))])


def test_a_disconnected_graph_or_a_bad_edge_is_rejected():
    with pytest.raises(ValueError, match="not connected"):
        run_synchronous(np.ones((3, 3)), [(0, 1)])
    with pytest.raises(ValueError, match=r"edge \(0, 0\)"):
        graph_diameter(2, [(0, 0)])
    with pytest.raises(ValueError, match=r"edge \(0, 5\)"):
        graph_diameter(2, [(0, 5)])


def test_the_reward_must_exceed_every_finite_cost():
    assert scores_from_cost(np.array([[1.0, INF]]), reward=3.0).tolist() == [[2.0, -INF]]
    with pytest.raises(ValueError, match=r"reward = 2\.0"):
        scores_from_cost(np.array([[1.0, 2.0]]), reward=2.0)
    assert run_synchronous(np.array([[1.0, 2.0]]), [], reward=50.0).assignment == {0: 0}


def test_the_bound_is_n_min_times_diameter():
    assert convergence_bound(4, 7, 3) == 12
    assert convergence_bound(9, 2, 4) == 8
    assert convergence_bound(1, 5, 0) == 1


def test_an_empty_fleet_or_task_list_assigns_nothing():
    assert run_synchronous(np.zeros((0, 3)), []).assignment == {}
    result = run_synchronous(np.zeros((2, 0)), [(0, 1)])
    assert result.assignment == {} and result.rounds == 0
