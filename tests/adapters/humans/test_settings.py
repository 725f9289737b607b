import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cosim import load_scenario
from cosim.core.errors import ConfigError


def test_people_are_off_by_default_and_the_preset_has_ten_workers():
    assert not load_scenario("warehouse-rows").humans.enabled
    humans = load_scenario("warehouse-humans").humans
    assert (humans.workers, humans.near_miss_m, humans.enabled) == (10, 0.5, True)


def test_standing_workers_alone_turn_sumo_on():
    assert load_scenario("warehouse-rows", {"humans.standing": [[5.0, 5.0]]}).humans.enabled


@pytest.mark.parametrize(
    ("key", "value", "expected"),
    [
        ("humans.workers", -1, ">= 0"),
        ("humans.near_miss_m", 0, "> 0"),
        ("humans.step_length_s", 2.0, "<= 1"),
        ("humans.pick_s", [30, 10], "min <= max"),
        ("humans.standing", [[1.0]], "2"),
        ("humans.forklift_size_m", [2.0, -1.0], "> 0"),
        ("humans.worker", 3, "workers"),
    ],
)
def test_a_bad_humans_key_names_the_key_the_value_and_what_was_expected(key, value, expected):
    with pytest.raises(ConfigError) as error:
        load_scenario("warehouse-humans", {key: value})
    message = str(error.value)
    assert key in message
    assert expected in message
    assert "\n" not in message


VALUES = st.one_of(
    st.integers(-5, 3000),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=5),
    st.lists(st.floats(-5, 50), max_size=3),
    st.lists(st.lists(st.floats(-5, 50), max_size=3), max_size=3),
    st.booleans(),
)
KEYS = st.sampled_from(
    [
        "workers",
        "forklifts",
        "standing",
        "near_miss_m",
        "step_length_s",
        "worker_radius_m",
        "worker_speed_mps",
        "pick_s",
        "stations",
        "forklift_size_m",
        "forklift_speed_mps",
        "aisle_spacing_m",
        "stop_radius_m",
        "record_hz",
    ]
)


@settings(max_examples=200, deadline=None)
@given(key=KEYS, value=VALUES)
def test_any_humans_value_is_either_accepted_or_refused_naming_the_section_and_key(key, value):
    try:
        scenario = load_scenario("warehouse-humans", {f"humans.{key}": value})
    except ConfigError as error:
        assert f"humans.{key}" in str(error)
        return
    assert getattr(scenario.humans, key) is not None
