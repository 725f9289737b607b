"""Scenario files that extend a preset or another file (cosim.scenario.extends)."""

import string
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cosim.core.errors import ConfigError
from cosim.scenario import dump_scenario, load_scenario, preset_names
from cosim.scenario.extends import merged, resolve
from tests.conftest import cosim_main

SMALL = """\
[scenario]
name = "small"
duration_s = 2.0

[world]
size_m = [12.0, 12.0]
shelf_count = 2
obstacles = [[1.0, 1.0, 2.0, 2.0]]

[robots]
count = 2
"""


def write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    return path


def body(text: str) -> str:
    """A resolved dump without its first line (which names the file it came from)."""
    return text.split("\n", 1)[1]


def test_a_file_extending_a_preset_is_the_preset_with_the_keys_it_sets(tmp_path):
    path = write(tmp_path / "s.toml", 'extends = "warehouse-rows"\n[robots]\ncount = 2\n')
    scenario = load_scenario(path)
    assert dump_scenario(scenario) == dump_scenario(
        load_scenario("warehouse-rows", {"robots.count": 2})
    ).replace("preset warehouse-rows", str(path))
    assert scenario.source == str(path)
    assert "extends" not in dump_scenario(scenario)


def test_a_chain_of_files_resolves_each_over_the_one_it_extends(tmp_path):
    write(tmp_path / "base.toml", SMALL)
    write(tmp_path / "mid" / "mid.toml", 'extends = "../base.toml"\n[robots]\ncount = 3\n')
    top = write(
        tmp_path / "mid" / "top.toml",
        'extends = "mid.toml"\n[world]\nshelf_count = 1\nobstacles = []\n[scenario]\nseed = 7\n',
    )
    scenario = load_scenario(top)
    assert scenario.robots.count == 3  # from the middle file
    assert scenario.world.shelf_count == 1  # the top file's key over the base's
    assert scenario.world.size_m == (12.0, 12.0)  # a key of the same table kept
    assert scenario.world.obstacles == ()  # a list replaces, it does not append
    assert (scenario.seed, scenario.name, scenario.scenario.duration_s) == (7, "small", 2.0)


def test_the_resolved_scenario_loads_back_equal_without_extends(tmp_path):
    write(tmp_path / "base.toml", SMALL)
    top = write(tmp_path / "top.toml", 'extends = "base.toml"\n[robots]\ncount = 3\n')
    scenario = load_scenario(top)
    dumped = write(tmp_path / "resolved.toml", dump_scenario(scenario))
    assert load_scenario(dumped) == scenario


def test_set_overrides_apply_over_the_whole_chain(tmp_path):
    write(tmp_path / "base.toml", SMALL)
    top = write(tmp_path / "top.toml", 'extends = "base.toml"\n[robots]\ncount = 3\n')
    scenario = load_scenario(top, {"robots.count": 1, "world.shelf_count": 0})
    assert (scenario.robots.count, scenario.world.shelf_count) == (1, 0)


def test_a_bad_key_in_the_extended_file_is_named_with_that_file(tmp_path):
    base = write(tmp_path / "base.toml", SMALL + '\n[lidar]\nrate_hz = "fast"\n')
    top = write(tmp_path / "sub" / "top.toml", 'extends = "../base.toml"\n[robots]\ncount = 3\n')
    with pytest.raises(ConfigError) as error:
        load_scenario(top)
    assert str(error.value).startswith(f"{top.parent / '..' / 'base.toml'}: [lidar] rate_hz = ")
    assert Path(str(error.value).split(":")[0]).resolve() == base


def test_a_bad_key_in_the_extending_file_is_named_with_that_file(tmp_path):
    write(tmp_path / "base.toml", SMALL)
    top = write(tmp_path / "top.toml", 'extends = "base.toml"\n[robots]\ncont = 3\n')
    with pytest.raises(ConfigError, match=rf"^{top}: \[robots\] unknown key 'cont'; did you"):
        load_scenario(top)


def test_an_unknown_section_of_the_extended_file_names_that_file(tmp_path):
    base = write(tmp_path / "base.toml", SMALL + "\n[robot]\ncount = 1\n")
    top = write(tmp_path / "top.toml", 'extends = "base.toml"\n')
    with pytest.raises(ConfigError, match=rf"^{base}: unknown section \[robot\]"):
        load_scenario(top)


def test_a_section_the_extended_file_gives_as_a_value_is_refused_naming_it(tmp_path):
    base = write(tmp_path / "base.toml", "robots = 3\n")
    top = write(tmp_path / "top.toml", 'extends = "base.toml"\n[robots]\ncount = 2\n')
    with pytest.raises(ConfigError, match=rf"^{base}: robots = 3: expected a \[robots\] table"):
        load_scenario(top)


def test_a_malformed_extended_file_names_its_line(tmp_path):
    base = write(tmp_path / "base.toml", "[robots\n")
    top = write(tmp_path / "top.toml", 'extends = "base.toml"\n')
    with pytest.raises(ConfigError, match=rf"^{base}: line 1: \[robots  <- "):
        load_scenario(top)


def test_a_relative_file_name_is_resolved_against_the_file_that_sets_it(tmp_path):
    base = '[network]\nlatency_model = "empirical"\nlatency_csv = "delays.csv"\n'
    write(tmp_path / "data" / "base.toml", base)
    top = write(tmp_path / "top.toml", 'extends = "data/base.toml"\n[robots]\ncount = 2\n')
    scenario = load_scenario(top)
    assert scenario.network.latency_csv == str((tmp_path / "data" / "delays.csv").resolve())


def test_a_key_the_extended_file_sets_still_beats_a_profile_the_extending_file_picks(tmp_path):
    write(tmp_path / "base.toml", "[network]\nlatency_ms = 33.0\n")
    top = write(
        tmp_path / "top.toml", 'extends = "base.toml"\n[network]\nprofile = "wifi_stress"\n'
    )
    network = load_scenario(top).network
    assert (network.profile, network.latency_ms) == ("wifi_stress", 33.0)


@pytest.mark.parametrize(
    ("value", "expected"),
    [
        ("3", "extends = 3: expected a preset name or the path of a scenario file"),
        ('""', "extends = '': expected a preset name or the path of a scenario file"),
        ('["warehouse-rows"]', "extends = ['warehouse-rows']: expected a preset name"),
        ("{ preset = 'x' }", "extends = {{preset = 'x'}}: expected a preset name"),
        ('"warehouse-rowz"', "extends = 'warehouse-rowz': not a preset; did you mean 'warehouse-"),
        ('"gone.toml"', "extends = 'gone.toml': no scenario file {folder}/gone.toml"),
        ('"folder/"', "extends = 'folder/': {folder}/folder is a folder; expected a scenario"),
        ('"self.toml"', "extends = 'self.toml': a cycle ({folder}/self.toml extends {folder}/s"),
    ],
)
def test_a_bad_extends_is_refused_in_one_line_naming_the_file_and_the_value(
    tmp_path, value, expected
):
    (tmp_path / "folder").mkdir()
    path = write(tmp_path / "self.toml", f"extends = {value}\n")
    with pytest.raises(ConfigError) as error:
        load_scenario(path)
    message = str(error.value)
    assert message.startswith(f"{path}: " + expected.format(folder=tmp_path)), message
    assert "\n" not in message


def test_a_cycle_through_three_files_names_them_all_and_the_file_closing_it(tmp_path):
    a = write(tmp_path / "a.toml", 'extends = "b.toml"\n')
    b = write(tmp_path / "b.toml", 'extends = "c.toml"\n')
    c = write(tmp_path / "c.toml", 'extends = "a.toml"\n')
    with pytest.raises(ConfigError) as error:
        load_scenario(b)
    assert str(error.value) == (
        f"{a}: extends = 'b.toml': a cycle ({b} extends {c} extends {a} extends {b}); "
        "expected a chain that ends in a scenario extending nothing"
    )


def test_the_same_file_reached_by_two_spellings_is_a_cycle(tmp_path):
    write(tmp_path / "sub" / "a.toml", 'extends = "../sub/./a.toml"\n')
    with pytest.raises(ConfigError, match="a cycle"):
        load_scenario(tmp_path / "sub" / "a.toml")


def test_extends_inside_a_section_is_an_unknown_key(tmp_path):
    path = write(tmp_path / "s.toml", '[robots]\nextends = "warehouse-rows"\n')
    with pytest.raises(ConfigError, match=r"\[robots\] unknown key 'extends'"):
        load_scenario(path)


def test_cosim_check_print_shows_the_resolved_scenario_of_a_file_that_extends(tmp_path):
    write(tmp_path / "base.toml", SMALL)
    top = write(tmp_path / "top.toml", 'extends = "base.toml"\n[robots]\ncount = 3\n')
    done = cosim_main("check", str(top), "--print")
    assert done.returncode == 0, done.stderr
    printed = done.stdout
    assert body(printed) == body(dump_scenario(load_scenario(top)))
    assert "count = 3" in printed and "shelf_count = 2" in printed and "extends" not in printed


def test_cosim_check_refuses_a_missing_extended_file_with_exit_2_and_one_line(tmp_path):
    top = write(tmp_path / "top.toml", 'extends = "base.toml"\n')
    done = cosim_main("check", str(top))
    assert done.returncode == 2
    assert done.stderr == (
        f"cosim: error: {top}: extends = 'base.toml': no scenario file {tmp_path}/base.toml "
        "(a path is relative to the extending file)\n"
    )


def test_tables_merge_key_by_key_at_any_depth_and_other_values_replace():
    below = {"a": {"b": 1, "c": {"d": 2, "e": [1, 2]}}, "f": [1], "g": 3}
    above = {"a": {"c": {"e": [3]}, "h": 4}, "f": [2], "g": {"x": 1}}
    assert merged(below, above) == {
        "a": {"b": 1, "c": {"d": 2, "e": [3]}, "h": 4},
        "f": [2],
        "g": {"x": 1},
    }
    assert below == {"a": {"b": 1, "c": {"d": 2, "e": [1, 2]}}, "f": [1], "g": 3}


def _presets(texts):
    """A reader of the presets ``texts`` (name -> raw TOML), as the loader reads presets."""

    def read(name):
        return f"preset {name}", texts[name]

    return read


def test_a_preset_may_extend_a_preset_and_each_key_names_the_preset_that_set_it():
    read = _presets({"base": {"robots": {"count": 2, "driver": "wander"}}})
    top = {"extends": "base", "robots": {"count": 5}}
    layers = resolve("preset top", top, read=read, presets=lambda: ["base", "top"])
    assert layers.raw == {"robots": {"count": 5, "driver": "wander"}}
    assert layers.keys == {("robots", "count"): "preset top", ("robots", "driver"): "preset base"}
    assert layers.sections == {"robots": "preset top"}


def test_a_preset_cannot_extend_a_file():
    with pytest.raises(ConfigError) as error:
        resolve("preset top", {"extends": "a.toml"}, read=_presets({}), presets=lambda: ["top"])
    assert str(error.value) == (
        "preset top: extends = 'a.toml': a preset extends only presets; expected a preset name"
    )


# --- fuzzing: whatever extends holds, one line naming the file and the value -----------------

non_strings = st.one_of(
    st.booleans(),
    st.integers(-(2**63), 2**63 - 1),
    st.floats(allow_nan=False, allow_infinity=False),
    st.lists(st.integers(-9, 9), max_size=3),
    st.dictionaries(st.text(string.ascii_letters, min_size=1, max_size=4), st.integers()),
)
missing_presets = st.text(min_size=1, max_size=20).filter(
    lambda s: s not in preset_names() and "/" not in s and not s.endswith(".toml")
)
missing_files = st.text(string.ascii_letters + string.digits + "_- ", min_size=1, max_size=20).map(
    lambda s: f"missing/{s}.toml"
)
FUZZ = settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)


def toml_text(value):
    """``value`` as TOML text."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        escaped = (
            f"\\u{ord(c):04x}" if c in '"\\' or ord(c) < 0x20 or ord(c) == 0x7F else c
            for c in value
        )
        return '"' + "".join(escaped) + '"'
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k} = {toml_text(v)}" for k, v in value.items()) + "}"
    if isinstance(value, list):
        return "[" + ", ".join(toml_text(v) for v in value) + "]"
    return repr(value)


def refused(path: Path, value_shown: str) -> str:
    with pytest.raises(ConfigError) as error:
        load_scenario(path)
    message = str(error.value)
    assert "\n" not in message
    assert message.startswith(f"{path}: extends = {value_shown}"), message
    return message


@FUZZ
@given(value=non_strings)
def test_fuzz_an_extends_that_is_not_a_string_is_refused(tmp_path, value):
    from cosim.scenario.fields import show_value

    path = write(tmp_path / "s.toml", f"extends = {toml_text(value)}\n")
    refused(path, show_value(value))


@FUZZ
@given(name=missing_presets)
def test_fuzz_an_extends_naming_no_preset_is_refused(tmp_path, name):
    from cosim.scenario.fields import show_value

    path = write(tmp_path / "s.toml", f"extends = {toml_text(name)}\n")
    assert ": not a preset" in refused(path, show_value(name))


@FUZZ
@given(name=missing_files)
def test_fuzz_an_extends_naming_no_file_is_refused(tmp_path, name):
    path = write(tmp_path / "s.toml", f"extends = {toml_text(name)}\n")
    assert f"no scenario file {tmp_path / name}" in refused(path, repr(name))


@FUZZ
@given(length=st.integers(1, 6), start=st.integers(0, 5))
def test_fuzz_a_cycle_of_any_length_is_refused_naming_its_files(tmp_path, length, start):
    names = [f"c{length}_{i}.toml" for i in range(length)]
    for i, name in enumerate(names):
        write(tmp_path / name, f'extends = "{names[(i + 1) % length]}"\n')
    first = start % length
    closing = names[(first - 1) % length]  # the file whose extends comes back
    with pytest.raises(ConfigError) as error:
        load_scenario(tmp_path / names[first])
    message = str(error.value)
    assert message.startswith(f"{tmp_path / closing}: extends = '{names[first]}': a cycle (")
    assert all(str(tmp_path / name) in message for name in names)


@FUZZ
@given(name=st.text(string.ascii_letters, min_size=1, max_size=10), slash=st.booleans())
def test_fuzz_an_extends_naming_a_folder_is_refused(tmp_path, name, slash):
    (tmp_path / "dirs" / name).mkdir(parents=True, exist_ok=True)
    value = f"dirs/{name}" + ("/" if slash else "")
    path = write(tmp_path / "s.toml", f'extends = "{value}"\n')
    assert "is a folder; expected a scenario file" in refused(path, repr(value))


def test_a_study_runs_a_file_that_extends_and_refuses_to_resume_after_the_base_changed(tmp_path):
    from tests.cosim.studies.small import SCENARIO, small_study

    base = write(tmp_path / "base" / "small.toml", SCENARIO)
    write(tmp_path / "top.toml", 'extends = "base/small.toml"\n[world]\nshelf_count = 1\n')
    path = small_study(tmp_path, scenario="top.toml", seeds="[1]")
    out = tmp_path / "out"
    args = ("study", str(path), "--out", str(out), "--workers", "1", "--quiet")
    done = cosim_main(*args)
    assert done.returncode == 0, done.stderr
    resolved = (out / "runs" / "0000_s1" / "scenario.toml").read_text()
    assert "shelf_count = 1\n" in resolved and "count = 2\n" in resolved
    assert "extends" not in resolved
    base.write_text(SCENARIO.replace("count = 2", "count = 3"))
    resumed = cosim_main(*args, "--resume")
    assert resumed.returncode == 2
    assert "`count = 2` then, `count = 3` now" in resumed.stderr
