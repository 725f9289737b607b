"""The ``[network]`` section: defaults, profiles, bounds and the partitions' checks."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import cosim
from adapters.network.settings import PROFILES, NetworkConfig, PartitionConfig
from cosim.core.errors import ConfigError
from models.network.loss import GilbertElliottLoss
from tests.conftest import SMALL


def _load(**keys: object) -> NetworkConfig:
    scenario = cosim.load_scenario("warehouse-random", {**SMALL, **keys})
    return scenario.section(NetworkConfig)


def test_the_default_network_is_ideal_and_built_by_the_links_backend():
    cfg = _load()
    assert (cfg.profile, cfg.backend, cfg.topology) == ("ideal", "links", "complete")
    assert (cfg.latency_model, cfg.latency_ms, cfg.loss_model) == ("constant", 0.0, "none")
    assert (cfg.bandwidth_mbps, cfg.range_m, cfg.partitions) == (0.0, 0.0, ())


def test_a_profile_fills_the_link_keys_with_its_figures():
    cfg = _load(**{"network.profile": "wifi_nominal"})
    assert (cfg.latency_model, cfg.latency_ms, cfg.jitter_ms) == ("normal", 3.0, 1.0)
    assert (cfg.loss_model, cfg.loss_prob, cfg.bandwidth_mbps) == ("bernoulli", 0.01, 50.0)


def test_a_key_given_with_a_profile_overrides_the_profile():
    cfg = _load(**{"network.profile": "wifi_nominal", "network.latency_ms": 7.5})
    assert cfg.latency_ms == 7.5
    assert (cfg.jitter_ms, cfg.loss_prob) == (1.0, 0.01)  # the rest from the profile


@pytest.mark.parametrize(
    ("profile", "loss", "burst"), [("wifi_degraded", 0.05, 3.0), ("wifi_stress", 0.25, 5.0)]
)
def test_the_wifi_profiles_lose_their_documented_rate_in_bursts_of_their_length(
    profile, loss, burst
):
    cfg = _load(**{"network.profile": profile})
    assert cfg.loss_model == "gilbert_elliott" and cfg.latency_model == "lognormal"
    process = GilbertElliottLoss(
        cfg.ge_p, cfg.ge_r, loss_good=cfg.ge_loss_good, loss_bad=cfg.ge_loss_bad
    )
    assert process.stationary_loss() == pytest.approx(loss, abs=1e-4)
    assert process.mean_burst_length() == pytest.approx(burst, abs=1e-3)


def test_every_profile_sets_the_same_link_keys_and_only_keys_of_the_section():
    keys = set(PROFILES["ideal"])
    names = {f for f in NetworkConfig.__dataclass_fields__}
    for profile, values in PROFILES.items():
        assert set(values) == keys, profile
        assert keys <= names


@pytest.mark.parametrize(
    ("key", "value", "expected"),
    [
        ("loss_prob", 1.5, "<= 1"),
        ("ge_p", -0.1, ">= 0"),
        ("edge_prob", 0.0, "> 0"),
        ("queue_packets", 0, ">= 1"),
        ("topology_update_hz", 0.0, ">= 0.001 and <= 1000"),
        ("latency_ms", -1.0, ">= 0"),
        ("profile", "lte", "ideal"),
    ],
)
def test_a_value_out_of_bounds_is_refused_naming_the_key_the_value_and_the_bound(
    key, value, expected
):
    with pytest.raises(ConfigError) as refused:
        _load(**{f"network.{key}": value})
    message = str(refused.value)
    assert f"network.{key}" in message or f"[network] {key}" in message
    assert repr(value) in message or str(value) in message
    assert expected in message and "\n" not in message


def test_an_unknown_backend_is_refused_with_the_registered_ones():
    with pytest.raises(ConfigError) as refused:
        _load(**{"network.backend": "omnet"})
    message = str(refused.value)
    assert "backend = 'omnet': expected a registered network backend" in message
    assert "(registered: links" in message


def test_an_unknown_loss_model_is_refused_with_the_nearest_name():
    with pytest.raises(ConfigError, match=r"did you mean 'bernoulli'\?"):
        _load(**{"network.loss_model": "bernouli"})


def test_a_partition_must_end_after_it_starts():
    window = {"from_s": 1.0, "to_s": 0.5, "hosts": ["robot_1"]}
    with pytest.raises(ConfigError) as refused:
        _load(**{"network.partitions": [window]})
    assert "[network.partitions[0]] to_s = 0.5: expected a time after from_s (1 s)" in str(
        refused.value
    )


@pytest.mark.parametrize(
    "window",
    [
        {"from_s": 0.0, "to_s": 1.0},
        {"from_s": 0.0, "to_s": 1.0, "hosts": ["robot_1"], "links": [["robot_2", "robot_3"]]},
    ],
)
def test_a_partition_names_either_hosts_or_links(window):
    with pytest.raises(ConfigError, match=r"hosts = .*: expected either hosts or links"):
        _load(**{"network.partitions": [window]})


def test_partitions_of_hosts_and_of_links_are_read_as_tuples():
    cfg = _load(
        **{
            "network.partitions": [
                {"from_s": 0.5, "to_s": 1.0, "hosts": ["robot_1"]},
                {"from_s": 1.0, "to_s": 2.0, "links": [["robot_2", "robot_3"]]},
            ]
        }
    )
    assert cfg.partitions == (
        PartitionConfig(0.5, 1.0, hosts=("robot_1",)),
        PartitionConfig(1.0, 2.0, links=(("robot_2", "robot_3"),)),
    )


def test_the_section_comes_after_the_fleets_and_before_the_navigations():
    from adapters.navigation.settings import NavigationConfig

    assert NetworkConfig.ORDER < NavigationConfig.ORDER


KEYS = st.sampled_from(
    [
        "latency_ms",
        "jitter_ms",
        "loss_prob",
        "ge_p",
        "ge_r",
        "bandwidth_mbps",
        "queue_packets",
        "range_m",
        "edge_prob",
        "topology",
        "latency_model",
        "loss_model",
        "profile",
        "reorder",
    ]
)
VALUES = st.one_of(
    st.integers(-5, 2_000_000),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=8),
    st.booleans(),
    st.lists(st.floats(-1, 5), max_size=2),
)


@settings(max_examples=80, deadline=None)
@given(key=KEYS, value=VALUES)
def test_any_network_value_is_accepted_or_refused_in_one_line_naming_the_key(key, value):
    try:
        cfg = _load(**{f"network.{key}": value})
    except ConfigError as error:
        message = str(error)
        assert key in message and "\n" not in message
        return
    assert getattr(cfg, key) is not None
