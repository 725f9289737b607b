"""The ``[navigation]`` section: Nav2's defaults, bounds, and the registered choices."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import cosim
from adapters.navigation.settings import NavigationConfig
from cosim.core.errors import ConfigError


def _navigation(**keys: object) -> NavigationConfig:
    overrides = {f"navigation.{key}": value for key, value in keys.items()}
    return cosim.load_scenario("warehouse-random", overrides).section(NavigationConfig)


def test_the_defaults_are_nav2s_where_it_has_one():
    cfg = _navigation()
    assert (cfg.planner, cfg.controller, cfg.traffic) == ("astar", "dwa", "none")
    assert (cfg.replan_hz, cfg.control_hz, cfg.goal_tolerance_m) == (1.0, 10.0, 0.25)
    assert (cfg.inflation_radius_m, cfg.cost_scaling, cfg.resolution_m) == (1.0, 3.0, 0.1)
    assert (cfg.stuck_timeout_s, cfg.progress_hz, cfg.obstacle_memory_s) == (30.0, 1.0, 3.0)
    assert cfg.robots_layer == "auto" and cfg.goals == ()


@pytest.mark.parametrize(
    ("value", "mapping", "on"),
    [("auto", False, False), ("auto", True, True), (True, False, True), (False, True, False)],
)
def test_the_robots_layer_is_on_with_mapping_unless_set_either_way(value, mapping, on):
    assert _navigation(robots_layer=value).robots_layer_on(mapping) is on


def test_a_robots_layer_neither_true_false_nor_auto_is_refused_naming_what_is_expected():
    with pytest.raises(ConfigError, match=r"robots_layer = 'sometimes'.*true or false or.*'auto'"):
        _navigation(robots_layer="sometimes")


def test_goals_are_read_as_pairs_in_map():
    cfg = _navigation(goals=[[1.0, 2.0], [3.5, 4.0]])
    assert cfg.goals == ((1.0, 2.0), (3.5, 4.0))


@pytest.mark.parametrize(
    ("key", "value", "expected"),
    [
        ("replan_hz", 0.0, ">= 0.001 and <= 50"),
        ("control_hz", 200.0, ">= 0.001 and <= 100"),
        ("resolution_m", 2.0, "<= 1"),
        ("inflation_radius_m", 0.0, "> 0"),
        ("goal_tolerance_m", -0.1, "> 0"),
        ("obstacle_memory_s", -1.0, ">= 0"),
        ("goals", [[1.0]], "expected a list of 2 numbers"),
    ],
)
def test_a_value_out_of_bounds_is_refused_naming_the_key(key, value, expected):
    with pytest.raises(ConfigError) as refused:
        _navigation(**{key: value})
    message = str(refused.value)
    assert f"navigation.{key}" in message and expected in message and "\n" not in message


@pytest.mark.parametrize(
    ("key", "value", "words", "near"),
    [
        ("planner", "a_star", "global planner", "astar"),
        ("controller", "dwb", "local controller", "dwa"),
        ("traffic", "lane", "traffic policy", "lanes"),
    ],
)
def test_an_unregistered_choice_is_refused_with_the_nearest_registered_name(
    key, value, words, near
):
    with pytest.raises(ConfigError) as refused:
        _navigation(**{key: value})
    message = str(refused.value)
    assert f"{key} = {value!r}: expected a registered {words}" in message
    assert f"did you mean {near!r}" in message


def test_the_section_comes_after_the_networks():
    from adapters.network.settings import NetworkConfig

    assert NavigationConfig.ORDER > NetworkConfig.ORDER


@settings(max_examples=60, deadline=None)
@given(
    st.sampled_from(
        ["replan_hz", "control_hz", "lookahead_m", "stuck_timeout_s", "robots_layer_hz", "traffic"]
    ),
    st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.text(max_size=5), st.booleans()),
)
def test_any_navigation_value_is_accepted_or_refused_naming_the_key(key, value):
    try:
        cfg = _navigation(**{key: value})
    except ConfigError as error:
        assert f"navigation.{key}" in str(error) and "\n" not in str(error)
        return
    assert getattr(cfg, key) is not None
