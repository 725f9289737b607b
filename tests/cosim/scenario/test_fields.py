"""Typed configuration fields: declared with ``param``, checked and built by ``build``."""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Literal

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cosim.core.errors import ConfigError, ScenarioError
from cosim.scenario.fields import (
    SHOWN_CHARS,
    Bounds,
    Problem,
    build,
    coerce,
    describe,
    docs,
    field_names,
    format_problem,
    implicit_bounds,
    key_bounds,
    key_unit,
    model_problem,
    param,
    show_name,
    show_value,
    suggest,
)
from models.errors import ModelError


@dataclass(frozen=True)
class Leg:
    """``[[gadget.legs]]``: one leg."""

    length_m: float = param(1.0, "leg length (m)", gt=0)


@dataclass(frozen=True)
class Gadget:
    """``[gadget]``: every kind of field a section may have."""

    count: int = param(2, "how many", ge=1, le=10)
    rate_hz: float = param(5.0, "ticks per second (Hz)", gt=0)
    wait_s: float = param(1.0, "a pause (s)", ge=0)
    size_m: tuple[float, float] = param((1.0, 2.0), "width and depth (m)", gt=0)
    offsets_m: tuple[float, ...] = param((), "offsets (m)", ge=-5, le=5)
    mode: Literal["fast", "slow"] = param("fast", "speed mode")
    enabled: bool = param(True, "switched on")
    driver: str = param("waypoints", "a registered driver", registry="cosim.drivers")
    source: str = param("none", "a pose source", registry="cosim.mocap_sources", off="none")
    data_file: str = param("", "a file", path=True)
    legs: tuple[Leg, ...] = param((), "the legs")

    def problems(self) -> Iterator[Problem]:
        if self.count > 5 and not self.enabled:
            yield Problem("enabled", self.enabled, f"true with count {self.count} (> 5)")


def _build(table: dict[str, object], origins: dict[str, str] | None = None) -> Gadget:
    return build(Gadget, table, section="gadget", origins=origins or {}, default_origin="g.toml")


def _refusal(table: dict[str, object], origins: dict[str, str] | None = None) -> str:
    with pytest.raises(ConfigError) as refused:
        _build(table, origins)
    return str(refused.value)


def test_a_table_builds_the_section_with_defaults_for_missing_keys():
    gadget = _build({"count": 3.0, "size_m": [0.5, 1], "offsets_m": [-1, 2.5], "mode": "slow"})
    assert gadget == Gadget(count=3, size_m=(0.5, 1.0), offsets_m=(-1.0, 2.5), mode="slow")
    assert isinstance(gadget.count, int) and isinstance(gadget.size_m[1], float)


def test_an_unknown_key_is_refused_with_the_nearest_key():
    assert _refusal({"cuont": 3}) == "g.toml: [gadget] unknown key 'cuont'; did you mean 'count'?"
    assert _refusal({"zzz": 1}).startswith("g.toml: [gadget] unknown key 'zzz'; valid: count, ")


@pytest.mark.parametrize(
    ("table", "message"),
    [
        ({"count": "3"}, "[gadget] count = '3': expected an integer >= 1 and <= 10"),
        ({"count": 2.5}, "[gadget] count = 2.5: expected an integer >= 1 and <= 10"),
        ({"count": True}, "[gadget] count = true: expected an integer >= 1 and <= 10"),
        ({"count": 11}, "[gadget] count = 11: expected an integer >= 1 and <= 10"),
        ({"enabled": 1}, "[gadget] enabled = 1: expected true or false"),
        ({"mode": "medium"}, "[gadget] mode = 'medium': expected one of 'fast', 'slow'"),
        ({"size_m": [1.0]}, "[gadget] size_m = [1.0]: expected a list of 2 numbers > 0"),
        (
            {"wait_s": float("inf")},
            "[gadget] wait_s = inf: expected a finite number >= 0 and <= 1e+09",
        ),
    ],
)
def test_a_wrong_value_is_refused_naming_origin_section_key_value_and_expectation(table, message):
    assert _refusal(table, {k: "s.toml" for k in table}) == f"s.toml: {message}"


def test_a_bound_applies_to_every_element_of_a_list():
    assert _refusal({"offsets_m": [1.0, 6.0]}) == (
        "g.toml: [gadget] offsets_m = [1.0, 6.0]: expected a list of numbers >= -5 and <= 5 "
        "(every element)"
    )


def test_a_name_of_a_registry_must_be_registered_unless_it_is_the_off_value():
    refused = _refusal({"driver": "wandr"})
    assert refused.startswith(
        "g.toml: [gadget] driver = 'wandr': expected a registered robot driver"
    )
    assert "did you mean 'wander'?" in refused and "(registered: " in refused
    assert _build({"source": "none", "driver": "wander"}).source == "none"
    assert "motion capture source" in _refusal({"source": "off"})


def test_a_cross_field_problem_names_where_the_key_came_from_or_the_default_origin():
    table = {"count": 6, "enabled": False}
    assert _refusal(table, {"enabled": "--set gadget.enabled"}) == (
        "--set gadget.enabled: [gadget] enabled = false: expected true with count 6 (> 5)"
    )
    assert _refusal(table).startswith("g.toml: [gadget] enabled = false")


def test_an_array_of_tables_builds_each_table_and_names_a_bad_one_by_its_index():
    gadget = _build({"legs": [{"length_m": 0.5}, {}]})
    assert gadget.legs == (Leg(0.5), Leg(1.0))
    assert _refusal({"legs": [{}, {"length_m": -1}]}) == (
        "g.toml: [gadget.legs[1]] length_m = -1: expected a number > 0"
    )
    assert _refusal({"legs": [1, 2]}) == (
        "g.toml: [gadget.legs] = [1, 2]: expected a list of tables (length_m)"
    )


def test_rates_and_times_keep_implicit_limits_besides_the_declared_ones():
    assert key_bounds(Gadget, "rate_hz") == Bounds(ge=1e-3, le=1e6)
    assert key_bounds(Gadget, "wait_s") == Bounds(ge=0, le=1e9)
    assert key_bounds(Gadget, "count") == Bounds(ge=1, le=10)  # not a rate or a time
    assert implicit_bounds("latency_ms", Bounds(gt=0)) == Bounds(ge=1e-3, le=1e12)
    assert implicit_bounds("duration_s", Bounds(gt=0, le=1e7)) == Bounds(ge=1e-6, le=1e7)
    assert implicit_bounds("period_s", Bounds(gt=1.0)) == Bounds(gt=1.0, le=1e9)
    assert "rate_hz = 1e-300: expected a number >= 0.001 and <= 1e+06" in _refusal(
        {"rate_hz": 1e-300}
    )


def test_bounds_say_which_one_a_value_breaks_and_describe_them_all():
    bounds = Bounds(ge=0, lt=1)
    assert bounds.violation(0.5) is None
    assert bounds.violation(-0.1) == ">= 0"
    assert bounds.violation(1.0) == "< 1"
    assert bounds.violation(float("nan")) == ">= 0"  # NaN breaks every bound
    assert bounds.describe() == ">= 0 and < 1"
    assert Bounds(gt=2, le=5).describe() == "> 2 and <= 5"
    assert Bounds().describe() == "" and Bounds().violation(1e300) is None


@pytest.mark.parametrize(
    ("hint", "words"),
    [
        (bool, "true or false"),
        (int, "an integer"),
        (float, "a number"),
        (str, "a string"),
        (Literal["a", "b"], "one of 'a', 'b'"),
        (tuple[float, float], "a list of 2 numbers"),
        (tuple[int, ...], "a list of integers"),
        (tuple[bool, ...], "a list of booleans"),
        (tuple[tuple[float, float, float], ...], "a list of lists of 3 numbers"),
        (tuple[Literal["x"], ...], "a list of values one of 'x'"),
        (int | str, "an integer or a string"),
    ],
)
def test_a_type_is_said_in_words(hint, words):
    assert describe(hint) == words


def test_coercion_turns_toml_values_into_the_annotated_type():
    assert coerce(3, float) == 3.0 and isinstance(coerce(3, float), float)
    assert coerce(4.0, int) == 4 and isinstance(coerce(4.0, int), int)
    assert coerce([[1, 2], [3, 4]], tuple[tuple[float, float], ...]) == ((1.0, 2.0), (3.0, 4.0))
    assert coerce("b", int | str) == "b"


def test_a_param_carries_its_doc_bounds_path_registry_and_off_value():
    found = {f.name: f for f in dataclasses.fields(Gadget)}
    assert found["count"].default == 2
    assert found["count"].metadata["bounds"] == Bounds(ge=1, le=10)
    assert found["data_file"].metadata["path"] is True
    assert found["source"].metadata["registry"] == "cosim.mocap_sources"
    assert found["source"].metadata["off"] == "none"
    assert docs(Gadget)["rate_hz"] == "ticks per second (Hz)"
    assert field_names(Gadget)[:3] == ["count", "rate_hz", "wait_s"]


@dataclass(frozen=True)
class Radio:
    tx_power_dbm: float = param(20.0, "transmit power (dBm)")
    shadowing_db: float = param(4.0, "shadowing deviation (dB)")
    cost_scaling: float = param(3.0, "inflation slope (1/m)", unit="1/m")
    beams: int = param(360, "beams per scan", unit="count")
    rate_hz: float = param(5.0, "ticks per second (Hz)", unit="ticks/s")
    name: str = param("a", "a name")


def test_a_key_s_unit_is_the_declared_one_else_the_one_its_name_carries():
    units = {f.name: key_unit(f) for f in dataclasses.fields(Radio)}
    assert units == {
        "tx_power_dbm": "dBm",
        "shadowing_db": "dB",
        "cost_scaling": "1/m",
        "beams": "count",
        "rate_hz": "ticks/s",  # declared wins over the name's
        "name": "",
    }
    assert dataclasses.fields(Radio)[0].metadata["unit"] is None


def test_a_problem_message_is_one_line_with_the_value_shown_as_toml():
    assert format_problem("s.toml", "robots", "count", 0, "an integer > 0") == (
        "s.toml: [robots] count = 0: expected an integer > 0"
    )
    assert (
        show_value([1, True, {"a b": 2.5, "k": "x\ny"}]) == "[1, true, {'a b' = 2.5, k = 'x\\ny'}]"
    )
    long = show_value("x" * 200)
    assert len(long) == SHOWN_CHARS and long.endswith("...")


def test_a_name_is_shown_as_written_or_quoted_when_spaces_around_or_control_characters():
    assert show_name("robots") == "robots"
    assert show_name(" robots") == "' robots'"
    assert show_name("ro\tbots") == "'ro\\tbots'"
    assert show_name("") == "''"
    assert len(show_name("s" * 500)) == SHOWN_CHARS


def test_a_suggestion_is_the_nearest_option_or_the_list_of_valid_ones():
    assert suggest("lidr", ["lidar", "robots"]) == "; did you mean 'lidar'?"
    assert suggest("zzz", ["lidar", "robots"]) == "; valid: lidar, robots"


def test_a_model_s_refusal_becomes_a_scenario_error_naming_the_source_and_key():
    error = model_problem("s.toml", ModelError("robots.radius_m", 0.5, "a radius < 0.4 (m)"))
    assert isinstance(error, ScenarioError)
    assert str(error) == "s.toml: robots.radius_m = 0.5: expected a radius < 0.4 (m)"
    shown = model_problem("s.toml", ModelError("robots.radius_m", 0.6, "x"), value=0.33)
    assert str(shown) == "s.toml: robots.radius_m = 0.33: expected x"
    path = "/data/" + "d" * 300 + "/map.yaml"
    assert str(model_problem("s", ModelError("world.map", path, "a map"))).endswith(
        "map.yaml': expected a map"
    )  # a file name is shown whole: its end names the file


_TOML_VALUES = st.recursive(
    st.none()
    | st.booleans()
    | st.integers(-(2**63), 2**63 - 1)
    | st.floats()
    | st.text(max_size=20),
    lambda inner: (
        st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=5), inner, max_size=3)
    ),
    max_leaves=10,
)


@settings(max_examples=150, deadline=None)
@given(key=st.sampled_from(field_names(Gadget)), value=_TOML_VALUES)
def test_any_value_of_any_key_builds_or_is_refused_in_one_line_naming_the_key(key, value):
    try:
        gadget = _build({key: value}, {key: "s.toml"})
    except ConfigError as refused:
        message = str(refused)
        assert "\n" not in message
        assert message.startswith(f"s.toml: [gadget{'.' + key if key == 'legs' else ''}")
        assert key in message
    else:
        assert isinstance(gadget, Gadget)
