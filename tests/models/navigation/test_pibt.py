"""One PIBT step: claims, making way, following, and what no step may do."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from models.navigation.pibt import Pibt


def _grid(width: int, height: int, blocked: frozenset[int] = frozenset()) -> np.ndarray:
    """4-neighbours of a width x height grid of nodes (node = y * width + x)."""
    neighbours = np.full((width * height, 4), -1, dtype=np.int64)
    for y in range(height):
        for x in range(width):
            u = y * width + x
            if u in blocked:
                continue
            for k, (dx, dy) in enumerate(((1, 0), (-1, 0), (0, 1), (0, -1))):
                v = (y + dy) * width + (x + dx)
                if 0 <= x + dx < width and 0 <= y + dy < height and v not in blocked:
                    neighbours[u, k] = v
    return neighbours


def _towards(goals: dict[int, int], width: int):
    """Rank by Manhattan distance to each robot's goal node."""

    def rank(robot: int, u: int) -> tuple[float, ...]:
        g = goals[robot]
        return (abs(u % width - g % width) + abs(u // width - g // width), u)

    return rank


def _step(at, neighbours, rank, held=frozenset(), order=None):
    step = Pibt(at, neighbours, rank, dict.fromkeys(held, -1))
    for robot in order if order is not None else sorted(at):
        if robot not in step.nxt:
            step.move(robot)
    return step.nxt


def test_a_robot_steps_to_the_free_neighbour_nearest_its_goal():
    nxt = _step({0: 5}, _grid(5, 3), _towards({0: 9}, 5))
    assert nxt == {0: 6}


def test_a_robot_asks_one_standing_in_its_way_to_make_way_and_follows_it():
    corridor = _grid(5, 1)  # 0 - 1 - 2 - 3 - 4
    nxt = _step({0: 0, 1: 1}, corridor, _towards({0: 4, 1: 1}, 5))
    assert nxt == {0: 1, 1: 2}  # robot 1 wanted to stay; it moves on, robot 0 follows


def test_a_robot_that_cannot_make_way_stays_and_so_does_the_one_that_asked():
    corridor = _grid(2, 1)  # 0 - 1: robot 1 at the dead end
    nxt = _step({0: 0, 1: 1}, corridor, _towards({0: 1, 1: 1}, 2))
    assert nxt == {0: 0, 1: 1}


def test_a_held_node_is_never_entered():
    nxt = _step({0: 0}, _grid(3, 1), _towards({0: 2}, 3), held={1})
    assert nxt == {0: 0}


def test_a_held_node_is_entered_only_by_the_one_robot_that_holds_it():
    # robot 0 on node 1, asked to make way by robot 1 on node 2, can only go back to node 0:
    # its own body still covers it, so it may; held by robot 5, or by several, it may not
    corridor = _grid(3, 1)
    rank = _towards({0: 2, 1: 0}, 3)
    for holder, moved in ((0, {0: 0, 1: 1}), (5, {0: 1, 1: 2}), (-1, {0: 1, 1: 2})):
        step = Pibt({0: 1, 1: 2}, corridor, rank, {0: holder})
        step.move(1)
        assert step.nxt == moved


def test_a_robot_does_not_move_onto_the_node_of_a_robot_planned_before_it():
    # robot 0 goes first and moves off node 1 of its own accord; robot 1 waits a step
    nxt = _step({0: 1, 1: 0}, _grid(3, 1), _towards({0: 2, 1: 2}, 3), order=[0, 1])
    assert nxt == {0: 2, 1: 0}


def test_a_robot_lets_through_one_whose_only_way_on_leads_over_its_node():
    # a one-way street 0 -> 1 -> 2 with a side node 3 off node 1: robot 0 stands on node 1
    # (its goal) and claimed to stay; robot 1 on node 0 can only go on through node 1
    neighbours = np.array([[1, -1, -1, -1], [2, -1, 3, -1], [-1, -1, -1, -1], [-1, -1, -1, 1]])
    rank = _towards({0: 1, 1: 2}, 10)
    step = Pibt({0: 1, 1: 0}, neighbours, rank, {})
    step.move(0)
    step.move(1)
    assert step.nxt == {0: 1, 1: 0}  # stuck: robot 0 stays, robot 1 cannot move
    step.let_through(0, 1)
    assert step.nxt[1] == 1  # robot 1 goes on
    assert step.nxt[0] == 2  # robot 0 makes way, nearest its goal and never onto node 0
    assert step.claimed == {1: 1, 2: 0}


def test_only_robots_planned_to_stay_can_let_each_other_through():
    step = Pibt({0: 0, 1: 2}, _grid(3, 1), _towards({0: 1, 1: 2}, 3), {})
    step.move(0)  # moves on to node 1
    step.move(1)
    with pytest.raises(ValueError, match="stay"):
        step.let_through(1, 0)


@settings(max_examples=300, deadline=None)
@given(
    width=st.integers(2, 6),
    height=st.integers(1, 5),
    data=st.data(),
)
def test_no_step_shares_a_node_swaps_jumps_enters_a_held_node_or_follows_round_a_cycle(
    width, height, data
):
    """Also when, after the step, one robot staying lets another staying through."""
    nodes = width * height
    blocked = frozenset(data.draw(st.sets(st.integers(0, nodes - 1), max_size=nodes // 3)))
    free = [u for u in range(nodes) if u not in blocked]
    if not free:
        return
    places = data.draw(st.lists(st.sampled_from(free), unique=True, min_size=1))
    held_nodes = set(data.draw(st.sets(st.sampled_from(free)))) - set(places)
    # each held by one of the robots (its body still covers it), or by others (-1)
    held = {u: data.draw(st.integers(-1, len(places) - 1)) for u in sorted(held_nodes)}
    goals = {r: data.draw(st.sampled_from(free)) for r in range(len(places))}
    order = data.draw(st.permutations(range(len(places))))
    neighbours = _grid(width, height, blocked)
    at = dict(enumerate(places))
    leaving = data.draw(st.sets(st.sampled_from(sorted(held_nodes)))) if held_nodes else set()
    step = Pibt(at, neighbours, _towards(goals, width), held, leaving)
    for robot in order:
        if robot not in step.nxt:
            step.move(robot)
    staying = [r for r in range(len(places)) if step.nxt[r] == at[r]]
    if len(staying) >= 2 and data.draw(st.booleans()):
        robot, other = data.draw(st.permutations(staying))[:2]
        step.let_through(robot, other)
    nxt = step.nxt

    assert set(nxt) == set(at)
    assert len(set(nxt.values())) == len(nxt)  # one robot per node
    standing = {v: r for r, v in at.items()}
    for r, v in nxt.items():
        assert v == at[r] or v in neighbours[at[r]]  # stays or steps to a neighbour
        assert held.get(v, r) == r  # a held node only by its holder
        other = standing.get(v)
        if other is not None and other != r:
            assert nxt[other] != at[other]  # follows a robot that leaves...
            assert nxt[other] != at[r]  # ...without swapping with it
    # following never closes a cycle: each chain of followers ends at a robot moving
    # onto a node nobody stood on
    for r in nxt:
        seen = set()
        while nxt[r] != at[r] and nxt[r] in standing:
            assert r not in seen
            seen.add(r)
            r = standing[nxt[r]]


def _queue_with_a_side_loop() -> tuple[np.ndarray, dict[int, int]]:
    """Nodes 0 - 1 - 2 - 3 in a line, and node 4 off node 1: from 4, 20 steps to node 3."""
    neighbours = np.full((5, 4), -1, dtype=np.int64)
    for u, vs in {0: [1], 1: [0, 2, 4], 2: [1, 3], 3: [2], 4: [1]}.items():
        neighbours[u, : len(vs)] = vs
    return neighbours, {0: 3, 1: 2, 2: 1, 3: 0, 4: 20}


@pytest.mark.parametrize(("leaving", "expected"), [({2}, {0: 0, 1: 1}), (set(), {0: 1, 1: 4})])
def test_a_robot_asked_to_make_way_follows_the_robot_ahead_leaving_rather_than_go_round(
    leaving, expected
):
    neighbours, steps = _queue_with_a_side_loop()
    # robot 0 (first) behind robot 1, both for node 3; a robot driving on still holds node 2
    step = Pibt({0: 0, 1: 1}, neighbours, lambda _r, u: (steps[u], u), {2: 9}, leaving)
    step.move(0)
    if 1 not in step.nxt:
        step.move(1)
    assert step.nxt == expected
