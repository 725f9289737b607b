"""The built-in topologies of the links backend: which robots may talk directly."""

from __future__ import annotations

import pytest

import cosim
from adapters.network.topologies import Binomial, Complete, Explicit, InRange, Ring
from cosim.core.errors import ConfigError, ScenarioError
from cosim.core.rng import RngStreams
from models.errors import ModelError
from models.network.topology import binomial_connected, is_connected
from tests.conftest import SMALL

from .conftest import ROBOTS


def _load(**network: object) -> cosim.Scenario:
    return cosim.load_scenario("warehouse-random", {**SMALL, **network})


def test_complete_links_every_pair_of_robots_and_nothing_else(context):
    edges = Complete(context()).edges()
    assert len(edges) == 6
    assert all(a < b and a in ROBOTS and b in ROBOTS for a, b in edges)
    assert Complete(context(["robot_1"])).edges() == frozenset()


def test_in_range_starts_from_every_pair_the_range_cuts_later(context):
    assert InRange(context(range_m=5.0)).edges() == Complete(context()).edges()


def test_a_range_topology_without_a_range_is_refused_naming_range_m():
    with pytest.raises(ConfigError, match=r"range_m = 0.0: expected a range > 0 with topology"):
        _load(**{"network.topology": "range"})
    assert _load(**{"network.topology": "range", "network.range_m": 8.0}).network.range_m == 8.0


def test_a_ring_links_each_robot_to_the_ones_before_and_after_it_in_fleet_order(context):
    assert Ring(context()).edges() == {
        ("robot_1", "robot_2"),
        ("robot_2", "robot_3"),
        ("robot_3", "robot_4"),
        ("robot_1", "robot_4"),
    }
    assert Ring(context(["robot_1", "robot_2"])).edges() == {("robot_1", "robot_2")}


def test_a_binomial_graph_is_connected_and_drawn_from_the_runs_topology_stream(context):
    robots = [f"robot_{i}" for i in range(1, 9)]
    edges = Binomial(context(robots, seed=7, edge_prob=0.3)).edges()
    assert is_connected(robots, edges)
    expected = binomial_connected(robots, 0.3, RngStreams(7).stream("network/topology"))
    assert edges == expected
    assert Binomial(context(robots, seed=7, edge_prob=0.3)).edges() == edges  # the same seed


def test_a_binomial_graph_with_edge_prob_1_is_complete(context):
    assert Binomial(context(edge_prob=1.0)).edges() == Complete(context()).edges()


def test_explicit_links_exactly_the_pairs_listed_in_either_order(context):
    listed = (("robot_2", "robot_1"), ("robot_3", "robot_4"))
    assert Explicit(context(topology="explicit", edges=listed)).edges() == {
        ("robot_1", "robot_2"),
        ("robot_3", "robot_4"),
    }


@pytest.mark.parametrize("pair", [("robot_1", "robot_9"), ("robot_2", "robot_2")])
def test_an_explicit_edge_of_an_unknown_or_the_same_robot_is_refused_naming_it(context, pair):
    with pytest.raises(ModelError) as refused:
        Explicit(context(topology="explicit", edges=(pair,)))
    assert "network.edges" in str(refused.value) and pair[1] in str(refused.value)


def test_an_explicit_topology_needs_edges_and_edges_need_an_explicit_topology():
    with pytest.raises(ConfigError, match=r"edges = \[\]: expected at least one \[a, b\] pair"):
        _load(**{"network.topology": "explicit"})
    pairs = [["robot_1", "robot_2"]]
    with pytest.raises(ConfigError, match="expected no edges unless topology is 'explicit'"):
        _load(**{"network.edges": pairs})
    loaded = _load(**{"network.topology": "explicit", "network.edges": pairs})
    assert loaded.network.edges == (("robot_1", "robot_2"),)


def test_an_explicit_edge_naming_an_unknown_robot_is_refused_when_the_run_is_assembled():
    from cosim.runner.assembly import assemble

    scenario = _load(**{"network.topology": "explicit", "network.edges": [["robot_1", "robot_7"]]})
    with pytest.raises(ScenarioError) as refused:
        assemble(scenario, names=["world", "fleet", "network"])
    assert str(refused.value) == (
        "preset warehouse-random: network.edges = ['robot_1', 'robot_7']: expected pairs of two "
        "different known hosts: robot_1, robot_2, robot_3"
    )
