"""Limits a scenario file keeps: its name names a folder, and its nesting stays shallow."""

import pytest

import cosim
from cosim.core.errors import ConfigError
from cosim.scenario import parse_override, preset_names
from cosim.scenario.tomlfile import MAX_DEPTH, parse_toml, read_toml_file


@pytest.mark.parametrize("name", ["../escape", "a/b", "/abs", "..", ".", "", "a b", "x\ny"])
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


@pytest.mark.parametrize(
    "value",
    [
        "[" * 1500 + "]" * 1500,
        "{b = " * 1500 + "1" + "}" * 1500,
        "[" * 100_000 + "]" * 100_000,
    ],
    ids=["arrays", "inline tables", "a hundred thousand arrays"],
)
def test_a_file_nested_thousands_deep_is_one_line_naming_the_file(tmp_path, value):
    path = tmp_path / "deep.toml"
    path.write_text(f"a = {value}\n", encoding="utf-8")
    with pytest.raises(ConfigError) as refused:
        read_toml_file(path, "scenario file")
    assert str(refused.value) == (
        f"{path}: tables or arrays nested deeper than {MAX_DEPTH} levels; expected at most "
        f"{MAX_DEPTH} (a scenario needs 4)"
    )


def test_a_dotted_key_of_many_parts_is_refused_before_the_reader_takes_its_time():
    text = "[scenario]\n" + ".".join(["a"] * 100_000) + " = 1\n"
    with pytest.raises(ConfigError, match=r"^s\.toml: line 2: a dotted key of more than 100 parts"):
        parse_toml(text, "s.toml")


def test_tables_a_hundred_and_one_deep_are_refused_once_read():
    key = ".".join(["a"] * (MAX_DEPTH - 1)) + " = 1\n"  # 98 tables in each other
    assert parse_toml("[x]\n" + key, "s.toml")  # the file, x and 98 tables: 100 levels
    with pytest.raises(ConfigError, match="nested deeper than 100 levels"):
        parse_toml("[x.y]\n" + key, "s.toml")


def test_long_lists_of_numbers_are_not_taken_for_dotted_keys():
    text = "[world]\nobstacles = [" + ", ".join(["[1.0, 2.0, 3.5, 4.5]"] * 2000) + "]\n"
    assert len(parse_toml(text, "s.toml")["world"]["obstacles"]) == 2000


def test_a_set_value_nested_thousands_deep_is_one_line_naming_the_key():
    with pytest.raises(ConfigError, match=r"^--set world\.obstacles: tables or arrays nested"):
        parse_override("world.obstacles=" + "[" * 2000 + "]" * 2000)
    with pytest.raises(ConfigError, match=r"^--set world\.obstacles: a dotted key of more"):
        parse_override("world.obstacles={" + ".".join(["a"] * 5000) + " = 1}")


@pytest.mark.parametrize("duration_s", [1e30, float("inf"), float("nan"), 0.0, -1.0, True])
def test_a_duration_given_in_code_keeps_the_bounds_of_the_key(duration_s):
    scenario = cosim.load_scenario("warehouse-random")
    with pytest.raises(ConfigError, match=r"^duration_s = .*: expected a number >= 1e-06 and <="):
        cosim.run(scenario, duration_s=duration_s)
    assert scenario.with_duration(1e7).scenario.duration_s == 1e7
