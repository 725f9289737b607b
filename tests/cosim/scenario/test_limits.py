"""Limits a scenario keeps: its name names a folder, a --set value's nesting stays shallow, its
duration stays within bounds (the TOML reader's own limits: test_tomlfile.py)."""

import pytest

import cosim
from cosim.core.errors import ConfigError
from cosim.scenario import parse_override, preset_names


@pytest.mark.parametrize("name", ["../escape", "a/b", "/abs", "..", ".", "", " a", "x\ny"])
def test_a_scenario_name_that_is_not_one_folder_name_is_refused_naming_the_file_and_key(
    tmp_path, name
):
    path = tmp_path / "s.toml"
    path.write_text(f"[scenario]\nname = {name!r}\n".replace("'", '"'), encoding="utf-8")
    with pytest.raises(ConfigError) as refused:
        cosim.load_scenario(path)
    message = str(refused.value)
    assert message.startswith(f"{path}: [scenario] name = ")
    assert "expected one folder name" in message and "\n" not in message


def test_a_scenario_name_given_with_set_is_refused_naming_the_flag():
    with pytest.raises(ConfigError, match=r"^--set scenario\.name: \[scenario\] name = '\.\./x'"):
        cosim.load_scenario("warehouse-random", {"scenario.name": "../x"})


def test_a_name_too_long_for_a_folder_is_refused():
    with pytest.raises(ConfigError, match="at most 100 bytes"):
        cosim.load_scenario("warehouse-random", {"scenario.name": "a" * 101})


@pytest.mark.parametrize("name", ["fleet50", "warehouse-random", "run_2.1+b", "ÜberLager"])
def test_folder_names_of_letters_digits_and_marks_are_accepted(name):
    assert cosim.load_scenario("warehouse-random", {"scenario.name": name}).name == name


def test_every_preset_still_loads_with_its_name():
    for preset in preset_names():
        assert cosim.load_scenario(preset).name == preset


def test_a_set_value_nested_thousands_deep_is_one_line_naming_the_key():
    with pytest.raises(ConfigError, match=r"^--set world\.obstacles: tables or arrays nested"):
        parse_override("world.obstacles=" + "[" * 2000 + "]" * 2000)
    with pytest.raises(ConfigError, match=r"^--set world\.obstacles: a dotted key of more"):
        parse_override("world.obstacles={" + ".".join(["a"] * 5000) + " = 1}")


@pytest.mark.parametrize("duration_s", [1e30, float("inf"), float("nan"), 0.0, -1.0, True])
def test_a_duration_given_in_code_keeps_the_bounds_of_the_key(duration_s):
    scenario = cosim.load_scenario("warehouse-random")
    with pytest.raises(
        ConfigError,
        match=r"^cosim.run\(duration_s=.*\): expected a number of seconds >= 1e-06 and <=",
    ):
        cosim.run(scenario, duration_s=duration_s)
    assert scenario.with_duration(1e7).scenario.duration_s == 1e7
