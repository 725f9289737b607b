import math
from pathlib import Path

import pytest

import cosim
import cosim.scenario.migrations as migrations
from adapters.assignment.settings import AssignmentConfig
from cosim.core.errors import ConfigError
from cosim.scenario import dump_scenario, parse_override, preset_names, scenario_from_text
from cosim.scenario.loader import check_runnable


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "s.toml"
    path.write_text(text)
    return path


def test_every_preset_loads_and_validates():
    for name in preset_names():
        scenario = cosim.load_scenario(name)
        assert scenario.name == name


def test_a_scenario_file_fills_missing_keys_with_defaults(tmp_path):
    scenario = cosim.load_scenario(_write(tmp_path, "[robots]\ncount = 7\n"))
    assert scenario.robots.count == 7
    assert scenario.lidar.beams == 360
    assert scenario.source == str(tmp_path / "s.toml")


def test_an_unknown_key_is_rejected_with_a_suggestion(tmp_path):
    path = _write(tmp_path, "[lidar]\nrate_hzz = 10\n")
    with pytest.raises(ConfigError) as error:
        cosim.load_scenario(path)
    message = str(error.value)
    assert str(path) in message
    assert "[lidar] unknown key 'rate_hzz'" in message
    assert "did you mean 'rate_hz'?" in message


def test_an_unknown_section_is_rejected_with_a_suggestion(tmp_path):
    with pytest.raises(ConfigError, match=r"unknown section \[robot\]; did you mean 'robots'"):
        cosim.load_scenario(_write(tmp_path, "[robot]\ncount = 2\n"))


def test_a_value_of_the_wrong_type_names_key_value_and_expectation(tmp_path):
    path = _write(tmp_path, '[robots]\ncount = "four"\n')
    with pytest.raises(ConfigError) as error:
        cosim.load_scenario(path)
    assert (
        str(error.value)
        == f"{path}: [robots] count = 'four': expected an integer > 0 and <= 100000"
    )


def test_a_negative_rate_is_rejected(tmp_path):
    path = _write(tmp_path, "[lidar]\nrate_hz = -10\n")
    with pytest.raises(ConfigError) as error:
        cosim.load_scenario(path)
    assert (
        str(error.value) == f"{path}: [lidar] rate_hz = -10: expected a number >= 0.001 and <= 1000"
    )


def test_zero_robots_are_rejected(tmp_path):
    with pytest.raises(ConfigError, match=r"\[robots\] count = 0: expected an integer > 0"):
        cosim.load_scenario(_write(tmp_path, "[robots]\ncount = 0\n"))


def test_a_list_of_the_wrong_length_is_rejected(tmp_path):
    with pytest.raises(ConfigError, match=r"size_m = \[30.0\]: expected a list of 2 numbers"):
        cosim.load_scenario(_write(tmp_path, "[world]\nsize_m = [30.0]\n"))


def test_a_bound_applies_to_every_element_of_a_list(tmp_path):
    with pytest.raises(ConfigError, match=r"size_m = \[30.0, -1.0\].*\(every element\)"):
        cosim.load_scenario(_write(tmp_path, "[world]\nsize_m = [30.0, -1.0]\n"))


def test_a_value_outside_a_choice_lists_the_choices(tmp_path):
    with pytest.raises(ConfigError, match=r"layout = 'rows': expected one of 'random', 'all_rows'"):
        cosim.load_scenario(_write(tmp_path, '[world]\nlayout = "rows"\n'))


def test_cross_field_problems_name_the_key(tmp_path):
    with pytest.raises(
        ConfigError, match=r"\[lidar\] range_min_m = 12.0: expected a value < range_max_m"
    ):
        cosim.load_scenario(_write(tmp_path, "[lidar]\nrange_min_m = 12.0\n"))


def test_malformed_toml_names_the_file_and_line_and_shows_the_line(tmp_path):
    path = _write(tmp_path, '[scenario]\nname = "x"\n\n[robots\ncount = 3\n')
    with pytest.raises(ConfigError) as error:
        cosim.load_scenario(path)
    assert str(error.value) == (
        f"{path}: line 4: [robots  <- expected ']' at the end of a table declaration "
        "(malformed TOML)"
    )


def test_bytes_that_are_not_utf8_name_their_line(tmp_path):
    path = tmp_path / "s.toml"
    path.write_bytes(b'[robots]\ncount = 3\nname = "\xff"\n')
    with pytest.raises(ConfigError, match=rf"{path}: line 3: byte 0xff is not UTF-8"):
        cosim.load_scenario(path)


def test_a_very_long_bad_line_is_shortened_in_the_message(tmp_path):
    path = _write(tmp_path, "[robots]\ncount = " + "9 " * 200 + "\n")
    with pytest.raises(ConfigError) as error:
        cosim.load_scenario(path)
    assert "line 2: count = 9 9" in str(error.value) and len(str(error.value)) < 250


def test_a_missing_file_is_reported(tmp_path):
    with pytest.raises(ConfigError, match="scenario file not found"):
        cosim.load_scenario(tmp_path / "nope.toml")


def test_an_unknown_preset_suggests_the_nearest_one():
    with pytest.raises(ConfigError, match="did you mean 'warehouse-random'"):
        cosim.load_scenario("warehouse-randon")


def test_overrides_are_type_checked_and_name_their_origin():
    with pytest.raises(ConfigError) as error:
        cosim.load_scenario("warehouse-random", {"lidar.beams": 2.5})
    assert str(error.value) == (
        "--set lidar.beams: [lidar] beams = 2.5: expected an integer >= 0 and <= 100000"
    )


def test_overrides_replace_file_values():
    scenario = cosim.load_scenario(
        "warehouse-random", {"robots.count": 9, "world.layout": "all_rows"}
    )
    assert scenario.robots.count == 9
    assert scenario.world.layout == "all_rows"


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("lidar.rate_hz=20", ("lidar.rate_hz", 20)),
        ("world.layout=all_rows", ("world.layout", "all_rows")),
        ('world.layout="all_rows"', ("world.layout", "all_rows")),
        ("world.size_m=[10, 20.5]", ("world.size_m", [10, 20.5])),
        ("record.messages=false", ("record.messages", False)),
    ],
)
def test_override_values_are_read_as_toml(text, expected):
    assert parse_override(text) == expected


@pytest.mark.parametrize("text", ["lidar", "rate_hz=3", "a.b.c=1", ".x=1"])
def test_malformed_overrides_are_rejected(text):
    with pytest.raises(ConfigError, match=r"expected section\.key=value"):
        parse_override(text)


def test_the_resolved_dump_loads_back_to_an_equal_scenario():
    scenario = cosim.load_scenario(
        "warehouse-random",
        {
            "robots.placement": "explicit",
            "robots.count": 2,
            "robots.positions": [[2.0, 3.0, 0.5], [5.0, 6.0, -1.0]],
            "record.topics": ["*", '!/a "quoted" \\ topic'],
        },
    )
    text = dump_scenario(scenario)
    assert scenario_from_text(text, "dump") == scenario
    assert "[robots]" in text and "[lidar]" in text


def test_a_network_profile_fills_the_link_keys_and_explicit_keys_override_it(tmp_path):
    path = _write(tmp_path, '[network]\nprofile = "wifi_degraded"\nlatency_ms = 7.5\n')
    network = cosim.load_scenario(path).network
    assert network.latency_ms == 7.5
    assert network.loss_model == "gilbert_elliott"
    assert network.bandwidth_mbps == 10.0


def test_an_unknown_network_profile_suggests_the_nearest(tmp_path):
    with pytest.raises(ConfigError, match=r"profile = 'wifi_nominl'.*did you mean 'wifi_nominal'"):
        cosim.load_scenario(_write(tmp_path, '[network]\nprofile = "wifi_nominl"\n'))


def test_a_problem_coming_from_a_profile_says_so(tmp_path):
    path = _write(tmp_path, '[network]\nprofile = "wifi_nominal"\nloss_model = "none"\n')
    with pytest.raises(
        ConfigError, match=r"\(profile wifi_nominal\): \[network\] loss_prob = 0.01"
    ):
        cosim.load_scenario(path)


def test_partitions_are_validated_as_tables_and_round_trip_through_the_dump():
    scenario = cosim.load_scenario(
        "warehouse-random",
        {
            "network.partitions": [
                {"from_s": 1.0, "to_s": 2.5, "hosts": ["robot_1", "base"]},
                {"from_s": 3.0, "to_s": 4.0, "links": [["robot_1", "robot_2"]]},
            ]
        },
    )
    assert scenario.network.partitions[1].links == (("robot_1", "robot_2"),)
    assert scenario_from_text(dump_scenario(scenario), "dump") == scenario


def test_an_unknown_key_inside_a_partition_is_named_with_its_index():
    with pytest.raises(ConfigError, match=r"\[network.partitions\[0\]\] unknown key 'form_s'"):
        cosim.load_scenario(
            "warehouse-random", {"network.partitions": [{"form_s": 1.0, "to_s": 2.0}]}
        )


# --- the scenario of an older run, read to draw it ---------------------------------------------


def test_a_renamed_key_whose_model_changed_is_refused_naming_the_new_key(tmp_path):
    path = _write(tmp_path, "[humans]\nworkers = 2\nyield_s = 10.0\n")
    with pytest.raises(ConfigError) as refused:
        cosim.load_scenario(path)
    assert str(refused.value) == (
        f"{path}: [humans] unknown key 'yield_s': renamed humans.avoid_robots in 462a048 "
        "(people keep clear of robots through a speed model instead of stopping for one at "
        "most yield_s s; yield_s = 0 (never stopping) is avoid_robots = false); set "
        "humans.avoid_robots instead"
    )
    with pytest.raises(ConfigError, match=r"^--set humans\.yield_s: \[humans\] unknown key"):
        cosim.load_scenario("warehouse-random", {"humans.yield_s": 3.0})


def test_a_run_read_for_its_results_takes_the_renamed_key_with_a_note(tmp_path):
    path = _write(tmp_path, "[humans]\nworkers = 2\nyield_s = 0.0\n")
    scenario = cosim.load_scenario(path, reading=True)
    assert scenario.humans.avoid_robots is False and scenario.humans.workers == 2
    assert scenario.notes == (
        f"note: {path}: [humans] yield_s = 0.0 read as humans.avoid_robots = false (renamed "
        "in 462a048: people keep clear of robots through a speed model instead of stopping for "
        "one at most yield_s s; yield_s = 0 (never stopping) is avoid_robots = false)",
    )


def test_a_renamed_key_of_the_same_meaning_runs_with_a_note(tmp_path, monkeypatch):
    same = migrations.Rename("lidar.rays", "lidar.beams", "0000000", int, True, "the same")
    monkeypatch.setattr(migrations, "RENAMES", (*migrations.RENAMES, same))
    path = _write(tmp_path, "[lidar]\nrays = 90\n")
    scenario = cosim.load_scenario(path)
    assert scenario.lidar.beams == 90
    assert scenario.notes == (
        f"note: {path}: [lidar] rays = 90 read as lidar.beams = 90 (renamed in 0000000: the same)",
    )
    with pytest.raises(ConfigError, match=rf"^{path}: \[lidar\] beams = -5: expected"):
        cosim.load_scenario(_write(tmp_path, "[lidar]\nrays = -5\n"))  # named where it came from


ODOKIT = """# resolved from preset warehouse-random

[provenance]
cosim = "0.1.0"
odokit = "0.3.0"

[scenario]
adapters = ["odometer"]

[assignment]
protocol = "sealed_bid"

[odometer]
rate_hz = 5.0
wheels = [1, 2]
"""


def test_a_section_of_a_plugin_not_installed_any_more_is_refused_naming_the_package(tmp_path):
    path = _write(tmp_path, ODOKIT)
    with pytest.raises(ConfigError) as refused:
        cosim.load_scenario(path)
    assert str(refused.value) == (
        f"{path}: unknown section [odometer]: no installed package registers it; the file was "
        "resolved with odokit 0.3.0, not installed here: install it to run this scenario "
        "(`cosim plot` and studies' reports read a run's tables without it)"
    )


def test_sections_and_names_of_a_plugin_not_installed_are_carried_where_a_run_is_read(tmp_path):
    path = _write(tmp_path, ODOKIT)
    scenario = cosim.load_scenario(path, reading=True)
    assert dict(scenario.carried) == {"odometer": {"rate_hz": 5.0, "wheels": [1, 2]}}
    assert scenario.scenario.adapters == ("odometer",)
    assert scenario.section(AssignmentConfig).protocol == "sealed_bid"
    assert scenario.notes == (
        f"note: {path}: [odometer], scenario.adapters = ['odometer'], assignment.protocol = "
        "'sealed_bid' carried unread: no installed package provides them (the run used "
        "odokit 0.3.0); the run's tables are read without it",
    )
    dumped = dump_scenario(scenario)
    assert dumped.endswith("\n[odometer]\nrate_hz = 5.0\nwheels = [1, 2]\n")
    again = cosim.load_scenario(_write(tmp_path, dumped), reading=True)
    assert again == scenario
    with pytest.raises(ConfigError) as refused:
        check_runnable(scenario)
    assert str(refused.value) == (
        f"{path}: unknown section [odometer]: no installed package registers it; it was read "
        "to draw a run, not to run one (install odokit 0.3.0 to run it)"
    )


def test_an_unknown_section_without_provenance_still_gets_a_suggestion(tmp_path):
    path = _write(tmp_path, '[provenance]\ncosim = "0.1.0"\n\n[robot]\ncount = 2\n')
    with pytest.raises(ConfigError, match=r"unknown section \[robot\]; did you mean 'robots'"):
        cosim.load_scenario(path)


def test_a_carried_section_keeps_what_toml_can_say_through_a_dump(tmp_path):
    text = (
        "[gone]\nx = nan\ny = [inf, -inf]\nwhen = 2026-11-28T10:00:00Z\nday = 2026-11-28\n"
        'at = 07:32:00\n"odd key" = {a = 1, "b\\nc" = "d\\u0000"}\n'
    )
    scenario = cosim.load_scenario(_write(tmp_path, text), reading=True)
    dumped = dump_scenario(scenario)
    assert "\n[gone]\nx = nan\ny = [inf, -inf]\nwhen = 2026-11-28T10:00:00+00:00\n" in dumped
    again = cosim.load_scenario(_write(tmp_path, dumped), reading=True).carried["gone"]
    assert again["when"] == scenario.carried["gone"]["when"]
    assert (
        again["day"] == scenario.carried["gone"]["day"]
        and again["at"] == scenario.carried["gone"]["at"]
    )
    assert again["odd key"] == {"a": 1, "b\nc": "d\x00"}
    assert again["x"] != again["x"] and again["y"] == [math.inf, -math.inf]
