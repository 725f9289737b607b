"""cosim.run's arguments (cosim.runner.arguments): a result, or one line naming the argument."""

import contextlib
import re
import string
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import cosim
from adapters.unity.server import UnityOptions
from cosim.core.errors import ConfigError, CosimError
from cosim.recording.foxglove import LiveOptions
from cosim.runner.arguments import adapters_argument, run_arguments
from cosim.runner.result import RunResult
from cosim.runner.stopping import StopRequest
from cosim.scenario.arguments import ArgumentError

TINY = {
    "scenario.duration_s": 0.05,
    "world.size_m": [6.0, 6.0],
    "world.shelf_count": 1,
    "robots.count": 1,
    "lidar.beams": 8,
    "record.bag": "none",
}
"""A run of a twentieth of a second: about 0.1 s of wall time."""

DEFAULTS = {
    "seed": None,
    "duration_s": None,
    "out": None,
    "force": False,
    "progress": None,
    "live": None,
    "on_ready": None,
    "adapters": (),
    "stop": None,
    "figures": False,
    "unity": None,
}

mistakes = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(min_value=-(2**66), max_value=2**66),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(alphabet=string.ascii_letters + "-_.", max_size=6),
    st.binary(max_size=3),
    st.lists(st.sampled_from(["lidar", "x", 3, None]), max_size=3),
    st.dictionaries(st.text(max_size=3), st.integers(), max_size=2),
    st.just(object()),
    st.just(np.int64(2)),
    st.just(np.float64(0.02)),
    st.just(lambda: None),
    st.just(lambda a, b, c: None),
    st.just(StopRequest()),
    st.just(LiveOptions(port=-1)),
)
"""Values a caller may pass by mistake (or not) for any argument."""


@pytest.fixture(scope="module")
def tiny():
    return cosim.load_scenario("warehouse-random", TINY)


def refused_naming(error: CosimError, argument: str) -> None:
    text = str(error)
    assert "\n" not in text, text
    assert text.startswith((f"cosim.run({argument}=", "cosim.run(adapters=[")), text


@pytest.mark.parametrize(
    ("kwargs", "line"),
    [
        ({"seed": "3"}, "cosim.run(seed='3'): expected an int >= 0, or None (the scenario's own)"),
        (
            {"seed": True},
            "cosim.run(seed=True): expected an int >= 0, or None (the scenario's own)",
        ),
        ({"seed": -1}, "cosim.run(seed=-1): expected an int >= 0, or None (the scenario's own)"),
        ({"out": b"runs/x"}, "cosim.run(out=b'runs/x'): expected a folder (a str or pathlib.Path)"),
        ({"force": "yes"}, "cosim.run(force='yes'): expected True or False"),
        (
            {"progress": lambda sim_s: None},
            "cosim.run(progress=<function <lambda> at",
        ),
        (
            {"adapters": 3},
            "cosim.run(adapters=3): expected registered adapter names (str, `cosim plugins`) or "
            "adapter classes: one, or a list of them",
        ),
        ({"adapters": ["lidar", None]}, "cosim.run(adapters=[..., None, ...]): expected"),
        ({"live": LiveOptions(port=70000)}, "cosim.run(live=...): live.port = 70000: expected a"),
        ({"live": LiveOptions(rate=0.0)}, "cosim.run(live=...): live.rate = 0.0: expected a"),
        ({"unity": UnityOptions(host="no host")}, "cosim.run(unity=...): unity.host = 'no host'"),
        ({"stop": True}, "cosim.run(stop=True): expected a StopRequest"),
        ({"duration_s": "5"}, "cosim.run(duration_s='5'): expected a number of seconds"),
        ({"threads": 0}, "cosim.run(threads=0): expected an int from 1 to 64, or None"),
        ({"threads": 2.0}, "cosim.run(threads=2.0): expected an int from 1 to 64, or None"),
        ({"threads": True}, "cosim.run(threads=True): expected an int from 1 to 64, or None"),
    ],
)
def test_a_wrong_argument_is_refused_in_one_line_before_anything_runs(tiny, tmp_path, kwargs, line):
    with contextlib.chdir(tmp_path), pytest.raises(ConfigError) as caught:
        cosim.run(tiny, **kwargs)
    assert str(caught.value).startswith(line), str(caught.value)
    assert "\n" not in str(caught.value)
    assert list(tmp_path.iterdir()) == []


def test_a_type_is_refused_as_a_type_error_and_a_value_out_of_bounds_as_a_config_error(tiny):
    with pytest.raises(TypeError):
        cosim.run(tiny, seed="3")
    with pytest.raises(ConfigError) as caught:
        cosim.run(tiny, seed=-1)
    assert not isinstance(caught.value, TypeError)


def test_a_preset_name_or_a_scenario_file_is_loaded_as_load_scenario_would(tmp_path):
    by_name = cosim.run("warehouse-random", seed=2, duration_s=0.05)
    assert by_name.summary["scenario"] == "warehouse-random" and by_name.summary["seed"] == 2
    path = tmp_path / "s.toml"
    path.write_text('extends = "warehouse-random"\n[scenario]\nname = "склад"\nduration_s = 0.05\n')
    by_file = cosim.run(path)
    assert by_file.summary["scenario"] == "склад"
    assert cosim.run(str(path)).summary["source"] == str(path)


def test_a_name_that_is_no_preset_nor_file_says_so_in_one_line():
    with pytest.raises(ConfigError, match=r"^warehouse-randm: not a scenario file nor a preset; "):
        cosim.run("warehouse-randm")


@pytest.mark.parametrize("scenario", [None, 3, b"warehouse-random", ["warehouse-random"]])
def test_a_scenario_of_another_kind_says_what_run_takes(scenario):
    with pytest.raises(ArgumentError) as caught:
        cosim.run(scenario)
    assert str(caught.value).endswith(
        "expected a Scenario (from cosim.load_scenario), a preset name (`cosim scenarios`) or "
        "a scenario file (a str or pathlib.Path)"
    )


def test_one_adapter_name_alone_is_a_list_of_one_not_a_list_of_letters(tiny):
    assert adapters_argument("lidar") == ("lidar",)
    assert adapters_argument(["lidar", "poses"]) == ("lidar", "poses")
    result = cosim.run(tiny, adapters="poses")
    assert isinstance(result, RunResult)


def test_a_numpy_seed_runs_and_is_written_as_a_plain_int(tiny, tmp_path):
    result = cosim.run(tiny, seed=np.int64(3), out=tmp_path / "run")
    assert result.summary["seed"] == 3 and type(result.scenario.seed) is int
    assert "seed = 3\n" in (tmp_path / "run" / "scenario.toml").read_text()


ARGUMENTS = sorted(DEFAULTS)


def _long(value: object) -> bool:
    """A number of seconds longer than a test should simulate (valid or not)."""
    if isinstance(value, bool) or not isinstance(value, int | float | np.integer | np.floating):
        return False
    return bool(np.isfinite(float(value)) and float(value) > 1.0)


@settings(
    max_examples=120,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
)
@given(argument=st.sampled_from(ARGUMENTS), value=mistakes)
def test_any_value_of_any_argument_runs_or_is_refused_in_one_line_naming_it(
    tiny, tmp_path_factory, argument, value
):
    if argument in ("live", "unity") and isinstance(value, LiveOptions | UnityOptions):
        return  # a valid one serves the run in real time: checked without running, below
    folder = tmp_path_factory.mktemp("fuzz")
    if argument == "duration_s" and _long(value):
        # a long duration is taken or refused as the run would: checked without running
        # it for hours
        try:
            checked = run_arguments(tiny, **{**DEFAULTS, "duration_s": value})
        except ConfigError as error:
            refused_naming(error, argument)
        else:
            assert checked.scenario.scenario.duration_s == float(value)
        return
    with contextlib.chdir(folder):
        try:
            result = cosim.run(tiny, **{argument: value})
        except ConfigError as error:
            refused_naming(error, argument)
        except CosimError as error:  # a name registered nowhere: the registry says so
            assert argument == "adapters", error
            refused_naming(error, argument)
        else:
            assert isinstance(result, RunResult)


fields = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(min_value=-(2**20), max_value=2**20),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=8),
    st.sampled_from(["127.0.0.1", "::1", "localhost", "0.0.0.0"]),
)


@settings(max_examples=150, deadline=None)
@given(host=fields, port=fields, rate=fields, wait=fields, unity=st.booleans())
def test_live_and_unity_options_of_any_values_are_taken_or_refused_naming_the_field(
    host, port, rate, wait, unity
):
    options = UnityOptions(host, port) if unity else LiveOptions(host, port, rate, wait)
    argument = "unity" if unity else "live"
    kwargs = {**DEFAULTS, argument: options}
    try:
        checked = run_arguments(Path("nowhere.toml"), **kwargs)
    except ConfigError as error:
        text = str(error)
        assert "\n" not in text
        assert text.startswith(f"cosim.run({argument}=...): {argument}.") or text.startswith(
            "nowhere.toml: scenario file not found"
        )
    else:
        raise AssertionError(f"{checked}: nowhere.toml does not exist")


def test_the_lines_the_runs_guide_shows_are_the_lines_cosim_says(tiny, tmp_path):
    guide = (Path(__file__).parents[3] / "docs" / "guides" / "runs.md").read_text()
    row = r"^\| `(cosim\.[^`]+)` \| (?:`` (.+?) ``|`([^`]+)`)(?: \(.*\))? \|$"
    rows = re.findall(row, guide, re.MULTILINE)
    assert len(rows) >= 8
    names = {"cosim": cosim, "scenario": tiny, "LiveOptions": LiveOptions}
    for call, quoted, plain in rows:
        with contextlib.chdir(tmp_path), pytest.raises(ConfigError) as caught:
            eval(call, names)  # the guide's own example
        assert str(caught.value) == (quoted or plain), call
