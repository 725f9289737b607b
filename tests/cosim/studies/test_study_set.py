"""``cosim study --set KEY=VALUE``: a key set in every run (cosim.studies.spec.with_sets)."""

import json
import string

import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cosim.core.errors import ConfigError
from cosim.scenario import load_scenario, parse_override
from cosim.studies import load_study
from cosim.studies.spec import read_study, with_sets
from tests.conftest import cosim_main
from tests.cosim.studies.small import finished, row_times, scenario_file, small_study

GRID = '\n[grid]\n"robots.count" = [1, 2]\n'
CASES = '\n[[cases]]\n"lidar.beams" = 90\n\n[[cases]]\n"lidar.rate_hz" = 5.0\n'


def test_a_set_key_is_in_every_run_over_the_studys_own_overrides(tmp_path):
    spec = read_study(small_study(tmp_path, extra=GRID))
    spec = with_sets(spec, {"world.shelf_count": 1, "lidar.beams": 45})
    assert [run.overrides["world.shelf_count"] for run in spec.runs()] == [1] * 6
    assert {run.overrides["lidar.beams"] for run in spec.runs()} == {45}
    assert {run.overrides["robots.count"] for run in spec.runs()} == {1, 2}  # still varied


def test_a_set_key_the_grid_varies_is_refused_naming_both(tmp_path):
    path = small_study(tmp_path, extra=GRID)
    with pytest.raises(ConfigError) as error:
        with_sets(read_study(path), {"robots.count": 3})
    assert str(error.value) == (
        f"{path}: --set robots.count = 3: the study varies 'robots.count' in [grid]; expected "
        "a key it does not vary (drop it from --set, or from [grid])"
    )


def test_a_set_key_a_case_varies_is_refused_naming_the_case(tmp_path):
    path = small_study(tmp_path, extra=CASES)
    with pytest.raises(ConfigError, match=r"--set lidar.rate_hz = 10: .* in \[cases\[1\]\]"):
        with_sets(read_study(path), {"lidar.rate_hz": 10})


@pytest.mark.parametrize(
    ("key", "duration", "fragment"),
    [
        ("scenario.seed", 1.0, "the study sets every run's seed from [study] seeds"),
        ("scenario.duration_s", 1.0, "[study] duration_s = 1 sets every run's duration"),
    ],
)
def test_a_set_key_the_study_sets_itself_is_refused(tmp_path, key, duration, fragment):
    path = small_study(tmp_path, duration_s=duration)
    with pytest.raises(ConfigError) as error:
        with_sets(read_study(path), {key: 5})
    assert str(error.value).startswith(f"{path}: --set {key} = 5: {fragment}")


def test_the_duration_may_be_set_when_the_study_leaves_it_to_the_scenario(tmp_path):
    spec = with_sets(read_study(small_study(tmp_path, duration_s=None)), {"scenario.duration_s": 2})
    assert {run.overrides["scenario.duration_s"] for run in spec.runs()} == {2}


def test_a_bad_set_value_gives_the_same_error_as_cosim_run_set(tmp_path):
    path = small_study(tmp_path, extra=GRID)
    with pytest.raises(ConfigError) as in_study:
        load_study(path, {"lidar.rate_hz": -3})
    with pytest.raises(ConfigError) as in_run:
        load_scenario("warehouse-random", {"lidar.rate_hz": -3})
    assert str(in_study.value) == str(in_run.value)
    assert str(in_study.value).startswith("--set lidar.rate_hz: [lidar] rate_hz = -3: expected")


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (["--set", "robots.count=3"], "the study varies 'robots.count' in [grid]"),
        (["--set", "robots.count"], "--set robots.count: expected section.key=value"),
        (["--set", "robot.count=3"], "--set robot.count: unknown section [robot]"),
        (["--set", "scenario.seed=2"], "--set scenario.seed = 2: the study sets every run's"),
    ],
)
def test_the_command_line_refuses_a_bad_set_with_exit_2_in_one_line(tmp_path, args, fragment):
    path = small_study(tmp_path, extra=GRID)
    out = tmp_path / "out"
    done = cosim_main("study", str(path), "--out", str(out), *args)
    assert done.returncode == 2, done.stdout
    assert done.stderr.startswith("cosim: error: ") and done.stderr.count("\n") == 1
    assert fragment in done.stderr, done.stderr
    assert not out.exists()


def _run(path, out, *extra):
    return cosim_main("study", str(path), "--out", str(out), "--workers", "1", "--quiet", *extra)


def test_set_reaches_every_run_and_a_changed_set_is_refused_on_resume(tmp_path):
    scenario_file(tmp_path)
    path = small_study(tmp_path, scenario="scenario.toml", seeds="[1, 2]")
    out = tmp_path / "out"
    done = _run(path, out, "--set", "world.shelf_count=1")
    assert done.returncode == 0, done.stderr
    results = pd.read_parquet(out / "results.parquet")
    assert list(results["world.shelf_count"]) == [1, 1]
    for run_id in finished(out):
        assert "shelf_count = 1\n" in (out / "runs" / run_id / "scenario.toml").read_text()
    plan = json.loads((out / "plan.json").read_text())
    assert all(run["overrides"] == {"world.shelf_count": 1} for run in plan["runs"])
    times = row_times(out)

    same = _run(path, out, "--set", "world.shelf_count=1", "--resume")
    assert same.returncode == 0, same.stderr
    for changed in (["--set", "world.shelf_count=0"], []):
        refused = _run(path, out, *changed, "--resume")
        assert refused.returncode == 2, refused.stdout
        assert refused.stderr.count("\n") == 1
        assert refused.stderr.startswith(f"cosim: error: {path}: the study's runs changed (run ")
        assert "world.shelf_count = 1 then" in refused.stderr
    assert row_times(out) == times  # nothing run again


KEYS = st.sampled_from(["robots.count", "lidar.rate_hz", "world.shelf_count", "scenario.seed"])
RAW = st.one_of(
    st.integers(-5, 5).map(str),
    st.floats(allow_nan=True).map(repr),
    st.text(string.printable, max_size=8),
)


@settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(key=KEYS, raw=RAW)
def test_fuzz_any_set_on_a_study_loads_or_is_refused_in_one_line(tmp_path, key, raw):
    path = small_study(tmp_path, extra=GRID)
    try:
        parsed = dict([parse_override(f"{key}={raw}")])
        spec = load_study(path, parsed)
    except ConfigError as error:
        message = str(error)
        assert "\n" not in message and message
        assert key in message
        return
    assert key != "robots.count" and key != "scenario.seed"  # varied, or set by the study
    assert all(run.overrides[key] == parsed[key] for run in spec.runs())
