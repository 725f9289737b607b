"""The ``[tasks]`` section: defaults, bounds, and a cap below the initial tasks refused."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import cosim
from adapters.tasks.settings import TasksConfig
from cosim.core.errors import ConfigError


def _tasks(**keys: object) -> TasksConfig:
    overrides = {f"tasks.{key}": value for key, value in keys.items()}
    return cosim.load_scenario("warehouse-random", overrides).section(TasksConfig)


def test_the_defaults_open_four_tasks_for_every_robot_without_a_cap():
    cfg = _tasks()
    assert (cfg.initial, cfg.max_total, cfg.eligibility_prob) == (4, 0, 1.0)
    assert (cfg.dwell_s, cfg.station_offset_m) == (2.0, 0.25)


def test_a_cap_of_at_least_the_initial_tasks_or_none_is_accepted():
    assert _tasks(initial=3, max_total=3).max_total == 3
    assert _tasks(initial=3, max_total=0).max_total == 0


def test_a_cap_below_the_initial_tasks_is_refused_naming_both():
    with pytest.raises(ConfigError) as refused:
        _tasks(initial=5, max_total=2)
    assert "[tasks] max_total = 2: expected 0 or at least initial (5)" in str(refused.value)


@pytest.mark.parametrize(
    ("key", "value", "expected"),
    [
        ("initial", 0, ">= 1"),
        ("max_total", -1, ">= 0"),
        ("eligibility_prob", 0.0, "> 0"),
        ("eligibility_prob", 1.5, "<= 1"),
        ("dwell_s", -1.0, ">= 0"),
        ("station_offset_m", 0.0, "> 0"),
        ("station_offset_m", 6.0, "<= 5"),
    ],
)
def test_a_value_out_of_bounds_is_refused_naming_the_key_and_the_bound(key, value, expected):
    with pytest.raises(ConfigError) as refused:
        _tasks(**{key: value})
    message = str(refused.value)
    assert f"tasks.{key}" in message and expected in message and "\n" not in message


@settings(max_examples=60, deadline=None)
@given(st.integers(-3, 200), st.integers(-3, 200))
def test_any_initial_and_cap_are_accepted_exactly_when_the_cap_can_be_reached(initial, cap):
    try:
        cfg = _tasks(initial=initial, max_total=cap)
    except ConfigError as error:
        assert initial < 1 or cap < 0 or 0 < cap < initial, str(error)
        return
    assert cfg.initial == initial >= 1 and (cap == 0 or cap >= initial)
