"""Keys that choose a registered implementation: its own checks, and keys left doing nothing."""

from __future__ import annotations

import dataclasses

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import cosim
from adapters.mocap.settings import MocapConfig
from adapters.network.settings import NetworkConfig
from cosim.core.errors import ConfigError
from cosim.core.registry import group_named
from cosim.scenario.choices import choice_problems
from cosim.scenario.fields import Problem


def test_the_chosen_entry_s_own_problems_are_yielded():
    lognormal = NetworkConfig(latency_model="lognormal", latency_ms=0.0)
    assert list(choice_problems(lognormal, "latency_model")) == [
        Problem("latency_ms", 0.0, "a value > 0 with latency_model 'lognormal'")
    ]
    assert list(choice_problems(NetworkConfig(topology="range"), "topology")) == [
        Problem("range_m", 0.0, "a range > 0 with topology 'range'")
    ]
    assert list(choice_problems(NetworkConfig(topology="explicit"), "topology")) == [
        Problem("edges", [], "at least one [a, b] pair with topology 'explicit'")
    ]


def test_a_key_only_another_entry_reads_set_while_it_is_not_chosen_is_refused_naming_it():
    lossless = NetworkConfig(loss_model="none", loss_prob=0.2)
    assert list(choice_problems(lossless, "loss_model")) == [
        Problem("loss_prob", 0.2, "0 with loss_model 'none' (only 'bernoulli' read loss_prob)")
    ]


def test_a_key_several_entries_read_names_every_reader():
    constant = NetworkConfig(latency_model="constant", jitter_ms=2.0)
    (problem,) = choice_problems(constant, "latency_model")
    assert problem == Problem(
        "jitter_ms",
        2.0,
        "0 with latency_model 'constant' (only 'lognormal' or 'normal' read jitter_ms)",
    )


def test_an_empty_default_is_refused_as_no_key_unless_a_reader_is_chosen():
    complete = NetworkConfig(topology="complete", edges=(("robot_1", "robot_2"),))
    assert list(choice_problems(complete, "topology")) == [
        Problem("edges", (("robot_1", "robot_2"),), "no edges unless topology is 'explicit'")
    ]
    csv = NetworkConfig(latency_model="normal", latency_csv="delays.csv")
    assert list(choice_problems(csv, "latency_model")) == [
        Problem("latency_csv", "delays.csv", "no latency_csv unless latency_model is 'empirical'")
    ]


def test_the_chosen_entry_s_own_keys_and_keys_left_at_their_default_are_fine():
    assert list(choice_problems(NetworkConfig(), "loss_model")) == []
    assert (
        list(choice_problems(NetworkConfig(loss_model="bernoulli", loss_prob=0.2), "loss_model"))
        == []
    )
    explicit = NetworkConfig(topology="explicit", edges=(("robot_1", "robot_2"),))
    assert list(choice_problems(explicit, "topology")) == []
    assert (
        list(choice_problems(MocapConfig(source="simulated", robots=("robot_1",)), "source")) == []
    )


def test_the_off_value_chooses_nothing_so_every_entry_s_own_keys_are_unused():
    assert list(choice_problems(MocapConfig(source="none"), "source")) == []
    tracked = MocapConfig(source="none", robots=("robot_1",))
    assert list(choice_problems(tracked, "source")) == [
        Problem("robots", ("robot_1",), "no robots unless source is 'simulated'")
    ]
    bodies = MocapConfig(source="none", bodies=(("robot_1", "jackal"),))
    (problem,) = choice_problems(bodies, "source")
    assert problem.key == "bodies"
    for reader in ("'bag'", "'motioncapture'", "'ros2'", "'unity'"):
        assert reader in problem.expected
    assert problem.expected.startswith("no bodies unless source is ")


def test_an_unregistered_name_yields_nothing_here():
    # the key's own check refuses it when loaded, with the registered names
    assert (
        list(choice_problems(NetworkConfig(loss_model="nope", loss_prob=0.5), "loss_model")) == []
    )
    assert list(choice_problems(MocapConfig(source="vicon", robots=("robot_1",)), "source")) == []


@settings(max_examples=40, deadline=None)
@given(
    model=st.sampled_from(group_named("cosim.loss_models").installed().names()),
    loss_prob=st.floats(0.0, 1.0),
)
def test_a_loss_probability_is_refused_exactly_when_a_model_that_ignores_it_is_chosen(
    model, loss_prob
):
    network = NetworkConfig(loss_model=model, loss_prob=loss_prob)
    refused = [p.key for p in choice_problems(network, "loss_model")]
    ignored = model != "bernoulli" and loss_prob != 0.0
    assert refused == (["loss_prob"] if ignored else [])


def test_a_section_s_problems_relay_them_in_one_line_naming_the_key_when_loaded():
    with pytest.raises(ConfigError) as refused:
        cosim.load_scenario("warehouse-random", {"network.loss_prob": 0.2})
    assert str(refused.value) == (
        "--set network.loss_prob: [network] loss_prob = 0.2: expected 0 with loss_model 'none' "
        "(only 'bernoulli' read loss_prob)"
    )
    chosen = {"network.loss_prob": 0.2, "network.loss_model": "bernoulli"}
    scenario = cosim.load_scenario("warehouse-random", chosen)
    assert dataclasses.asdict(scenario.network)["loss_prob"] == 0.2
