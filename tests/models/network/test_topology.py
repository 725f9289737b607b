import math

import numpy as np
import pytest

from models.errors import ModelError
from models.network.topology import (
    binomial_connected,
    complete,
    diameter,
    edge,
    explicit,
    is_connected,
    neighbors,
    ring,
    within_range,
)

HOSTS = ["base", "robot_0", "robot_1", "robot_2", "robot_3"]


def test_a_complete_graph_links_every_pair_once_as_sorted_pairs():
    edges = complete(HOSTS)
    assert len(edges) == 10
    assert all(a < b for a, b in edges)
    assert diameter(HOSTS, edges) == 1.0


def test_a_ring_links_each_host_to_the_next_and_closes():
    edges = ring(HOSTS)
    assert edges == {
        ("base", "robot_0"),
        ("robot_0", "robot_1"),
        ("robot_1", "robot_2"),
        ("robot_2", "robot_3"),
        ("base", "robot_3"),
    }
    assert diameter(HOSTS, edges) == 2.0
    assert ring(["a", "b"]) == {("a", "b")}
    assert ring(["a"]) == frozenset()


def test_a_binomial_graph_is_connected_and_repeats_with_the_same_seed():
    names = [f"r{i}" for i in range(12)]
    first = binomial_connected(names, 0.3, np.random.default_rng(5))
    assert is_connected(names, first)
    assert first == binomial_connected(names, 0.3, np.random.default_rng(5))
    assert binomial_connected(names, 1.0, np.random.default_rng(5)) == complete(names)


def test_a_binomial_graph_keeps_about_p_of_the_pairs():
    names = [f"r{i}" for i in range(60)]
    edges = binomial_connected(names, 0.2, np.random.default_rng(6))
    pairs = 60 * 59 // 2
    # binomial standard deviation of the fraction: sqrt(0.2 * 0.8 / 1770) = 0.0095
    assert len(edges) / pairs == pytest.approx(0.2, abs=0.04)


def test_a_binomial_graph_that_never_connects_is_refused():
    with pytest.raises(ModelError, match="connected within 20 draws") as error:
        binomial_connected(HOSTS, 0.0, np.random.default_rng(0), max_tries=20)
    assert error.value.key == "network.edge_prob"
    with pytest.raises(ModelError) as error:
        binomial_connected(HOSTS, 1.2, np.random.default_rng(0))
    assert error.value.key == "network.edge_prob"


def test_explicit_edges_are_normalized_to_sorted_pairs():
    assert explicit(HOSTS, [["robot_1", "base"], ("robot_2", "robot_1")]) == {
        ("base", "robot_1"),
        ("robot_1", "robot_2"),
    }


@pytest.mark.parametrize(
    "bad", [["base", "robot_9"], ["robot_1", "robot_1"], ["base"], "ab", ["a", "b", "c"]]
)
def test_an_edge_to_an_unknown_host_or_itself_is_refused(bad):
    with pytest.raises(ModelError, match="pairs of two different known hosts: base, ") as error:
        explicit(HOSTS, [["base", "robot_0"], bad])
    assert error.value.key == "network.edges"


def test_hosts_within_range_are_linked_including_at_exactly_the_range():
    names = ["a", "b", "c", "d"]
    positions = np.array([[0.0, 0.0], [3.0, 4.0], [6.0, 8.0], [100.0, 0.0]])
    edges = within_range(names, positions, 5.0)
    assert edges == {("a", "b"), ("b", "c")}
    assert not is_connected(names, edges)
    assert diameter(names, edges) == math.inf
    with pytest.raises(ModelError):
        within_range(names, positions, -1.0)


def test_diameter_of_a_path_is_its_length_and_neighbors_are_sorted():
    names = ["a", "b", "c", "d"]
    path = frozenset({edge("a", "b"), edge("c", "b"), edge("d", "c")})
    assert is_connected(names, path)
    assert diameter(names, path) == 3.0
    assert neighbors(path, "b") == ("a", "c")
    assert neighbors(path, "z") == ()
    assert diameter(["a"], frozenset()) == 0.0
    assert is_connected([], frozenset())
