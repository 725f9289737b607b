"""The Python API's arguments (cosim.scenario.arguments): one line naming the argument.

``cosim.load_scenario``, ``Scenario.with_seed`` and ``cosim.study`` take their arguments
through these checks; ``cosim.run``'s are in tests/cosim/runner/test_arguments.py.
"""

from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import cosim
from cosim.core.errors import ConfigError
from cosim.scenario.arguments import (
    ArgumentError,
    flag_argument,
    overrides_argument,
    path_argument,
    seed_argument,
    shown,
)

anything = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(min_value=-(2**70), max_value=2**70),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=10),
    st.binary(max_size=4),
    st.lists(st.integers(), max_size=3),
    st.tuples(st.text(max_size=3), st.integers()),
    st.dictionaries(st.text(max_size=6), st.integers(), max_size=2),
    st.sets(st.integers(), max_size=2),
    st.just(object()),
    st.just(np.int64(3)),
    st.just(np.float32(0.5)),
    st.just(np.array([1, 2])),
    st.just(Path("x")),
)
"""Values of every kind a caller may pass by mistake."""


def one_line_naming(error: Exception, call: str, argument: str) -> None:
    text = str(error)
    assert "\n" not in text, text
    assert text.startswith(f"{call}({argument}="), text
    assert ": expected " in text, text


def test_an_argument_of_the_wrong_type_is_a_config_error_and_a_type_error():
    with pytest.raises(ArgumentError) as caught:
        seed_argument("cosim.run", "3")
    assert isinstance(caught.value, ConfigError) and isinstance(caught.value, TypeError)
    assert str(caught.value) == "cosim.run(seed='3'): expected an int >= 0"


@pytest.mark.parametrize("seed", [True, False, "3", 3.0, None, [3], np.bool_(True)])
def test_a_seed_that_is_no_int_is_refused_naming_it(seed):
    with pytest.raises(ArgumentError) as caught:
        seed_argument("Scenario.with_seed", seed)
    one_line_naming(caught.value, "Scenario.with_seed", "seed")


def test_a_negative_seed_is_out_of_bounds_and_numpy_s_ints_are_ints():
    with pytest.raises(ConfigError) as caught:
        seed_argument("cosim.run", -1)
    assert not isinstance(caught.value, ArgumentError)
    assert seed_argument("cosim.run", np.uint8(7)) == 7 and type(seed_argument("x", 2**80)) is int


def test_with_seed_refuses_a_bool_that_would_write_seed_true_to_the_run_s_scenario_toml():
    scenario = cosim.load_scenario("warehouse-random")
    with pytest.raises(ArgumentError, match=r"^Scenario.with_seed\(seed=True\): expected an int"):
        scenario.with_seed(True)
    assert scenario.with_seed(np.int64(5)).seed == 5


def test_overrides_that_are_no_mapping_are_refused_in_one_line():
    with pytest.raises(ArgumentError) as caught:
        cosim.load_scenario("warehouse-random", [("robots.count", 8)])  # type: ignore[arg-type]
    assert str(caught.value) == (
        "cosim.load_scenario(overrides=[('robots.count', 8)]): expected a mapping "
        "{'section.key': value} (a dict), or None"
    )


def test_override_keys_must_be_strings_and_numpy_values_become_python_ones():
    with pytest.raises(ArgumentError, match=r"keys that are strings 'section.key'"):
        overrides_argument("cosim.load_scenario", {("robots", "count"): 8})
    plain = overrides_argument("x", {"robots.count": np.int64(8), "world.size_m": np.array([9, 9])})
    assert plain == {"robots.count": 8, "world.size_m": [9, 9]}
    assert type(plain["robots.count"]) is int
    scenario = cosim.load_scenario("warehouse-random", {"robots.count": np.int64(8)})
    assert scenario.robots.count == 8


@pytest.mark.parametrize("spec", [b"warehouse-random", 3, None, "", "a\0b", ["warehouse-random"]])
def test_a_scenario_spec_that_is_no_name_nor_path_is_refused(spec):
    with pytest.raises(ArgumentError) as caught:
        cosim.load_scenario(spec)
    one_line_naming(caught.value, "cosim.load_scenario", "spec")
    assert "expected a preset name or a scenario file (a str or pathlib.Path)" in str(caught.value)


def test_a_path_argument_keeps_a_str_as_a_preset_name_and_takes_a_path_as_a_file(tmp_path):
    assert cosim.load_scenario("warehouse-rows").source == "preset warehouse-rows"
    with pytest.raises(ConfigError, match="scenario file not found"):
        cosim.load_scenario(tmp_path / "warehouse-rows")
    assert path_argument("f", "out", tmp_path) == tmp_path


def test_flags_are_bools_alone():
    assert flag_argument("f", "force", np.bool_(True)) is True
    for value in (1, "yes", None):
        with pytest.raises(ArgumentError, match=r"expected True or False$"):
            flag_argument("f", "force", value)


def test_a_value_is_shown_short_whatever_it_is():
    class Broken:
        def __repr__(self) -> str:
            raise RuntimeError("no repr")

    assert shown(Broken()).startswith("<Broken ")
    assert len(shown(list(range(10_000)))) < 40 and len(shown("x" * 10_000)) < 70


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(spec=anything, overrides=anything)
def test_load_scenario_with_any_arguments_loads_or_says_which_argument_is_wrong(spec, overrides):
    try:
        cosim.load_scenario(spec, overrides)
    except ArgumentError as error:
        text = str(error)
        assert "\n" not in text
        assert text.startswith(("cosim.load_scenario(spec=", "cosim.load_scenario(overrides="))
    except ConfigError as error:  # a name that is no preset, a key that is unknown
        assert "\n" not in str(error)


@settings(max_examples=120, deadline=None)
@given(seed=anything)
def test_with_seed_of_any_value_gives_a_scenario_or_one_line_naming_the_seed(seed):
    scenario = cosim.load_scenario("warehouse-random")
    try:
        seeded = scenario.with_seed(seed)
    except ConfigError as error:
        one_line_naming(error, "Scenario.with_seed", "seed")
    else:
        assert type(seeded.seed) is int and seeded.seed >= 0


@pytest.mark.parametrize(
    ("kwargs", "line"),
    [
        ({"workers": 0}, "cosim.study(workers=0): expected an int >= 1, or None"),
        ({"workers": "2"}, "cosim.study(workers='2'): expected an int >= 1, or None"),
        ({"resume": "yes"}, "cosim.study(resume='yes'): expected True or False"),
        ({"scheduler": 8786}, "cosim.study(scheduler=8786): expected a str"),
        ({"report": 1}, "cosim.study(report=1): expected True or False"),
        ({"notify": "x"}, "cosim.study(notify='x'): expected a function of one line"),
        ({"verbose": True}, "cosim.study(): unexpected keyword argument 'verbose'; expected one"),
    ],
)
def test_cosim_study_names_a_wrong_argument_before_reading_the_study(tmp_path, kwargs, line):
    with pytest.raises(ConfigError) as caught:
        cosim.study(tmp_path / "missing.toml", tmp_path / "out", **kwargs)
    assert str(caught.value).startswith(line) and "\n" not in str(caught.value)
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("path", [None, 3, b"s.toml", ""])
def test_cosim_study_names_a_study_file_that_is_no_path(tmp_path, path):
    with pytest.raises(ArgumentError, match=r"^cosim.study\(path=.*\): expected a study file"):
        cosim.study(path, tmp_path / "out")


def test_a_section_asked_for_by_name_instead_of_class_says_how_to_read_it_by_name():
    scenario = cosim.load_scenario("warehouse-random")
    with pytest.raises(ArgumentError) as caught:
        scenario.section("navigation")  # type: ignore[arg-type]
    assert str(caught.value) == (
        "Scenario.section(kind='navigation'): expected a settings class (NavigationConfig); "
        "by name: scenario.sections[name]"
    )


@pytest.mark.parametrize(
    ("name", "section", "argument"),
    [(3, None, "name"), ("robots", {"count": 9}, "section"), ("robots", int, "section")],
)
def test_with_section_takes_a_name_and_a_settings_instance(name, section, argument):
    scenario = cosim.load_scenario("warehouse-random")
    with pytest.raises(ArgumentError, match=rf"^Scenario.with_section\({argument}="):
        scenario.with_section(name, section)


@pytest.mark.parametrize("spec", ["\n", " ", "ware\nhouse", "a\n/b.toml"])
def test_a_scenario_name_with_a_line_break_or_nothing_in_it_is_refused_quoted_in_one_line(spec):
    with pytest.raises(ConfigError) as refused:
        cosim.load_scenario(spec)
    message = str(refused.value)
    assert "\n" not in message and message.startswith(repr(spec) + ":")
