"""Study files: the ``[report] loglog`` key (cosim.studies.spec)."""

import subprocess
import sys
from pathlib import Path

import pytest

from cosim.core.errors import ConfigError
from cosim.studies import load_study
from cosim.studies.spec import read_study
from tests.conftest import cosim_main
from tests.cosim.studies.small import small_study

BASE = """
[study]
name = "scale_small"
scenario = "fleet50"
seeds = 1
duration_s = 5

[grid]
"robots.count" = [4, 8]

[overrides]
"world.size_m" = [15.0, 15.0]
"world.shelf_count" = 12
"""


def _study(tmp_path: Path, report: str, base: str = BASE) -> Path:
    path = tmp_path / "study.toml"
    path.write_text(base + "\n[report]\n" + report)
    return path


def test_a_loglog_list_with_a_positive_numeric_x_is_kept_in_the_report_section(tmp_path):
    report = 'x = "robots.count"\nloglog = ["wall_us_per_robot_s", "wall_time_s"]\n'
    spec = load_study(_study(tmp_path, report))
    assert spec.report["loglog"] == ["wall_us_per_robot_s", "wall_time_s"]


@pytest.mark.parametrize(
    ("report", "fragment"),
    [
        (
            'x = "robots.count"\nloglog = "wall_us_per_robot_s"\n',
            "[report] loglog = 'wall_us_per_robot_s': expected a list of metric names",
        ),
        (
            'x = "robots.count"\nloglog = true\n',
            "[report] loglog = True: expected a list of metric names",
        ),
        (
            'x = "robots.count"\nloglog = [""]\n',
            "[report] loglog = ['']: expected a list of metric names",
        ),
        (
            'loglog = ["wall_us_per_robot_s"]\n',
            "[report] loglog = ['wall_us_per_robot_s']: needs x (the horizontal log axis)",
        ),
        (
            'x = "robots.count"\nlog_log = ["wall_us_per_robot_s"]\n',
            "[report] unknown key 'log_log'; did you mean 'loglog'?",
        ),
    ],
)
def test_a_bad_loglog_is_refused_naming_the_file_key_and_value(tmp_path, report, fragment):
    path = _study(tmp_path, report)
    with pytest.raises(ConfigError) as refused:
        load_study(path)
    message = str(refused.value)
    assert fragment in message and str(path) in message and "\n" not in message


@pytest.mark.parametrize(
    ("edit", "x", "fragment"),
    [
        (
            lambda t: t.replace("[4, 8]", "[0, 8]"),
            "robots.count",
            "x = 'robots.count' is 0 in [grid]; expected numbers > 0 on a log axis",
        ),
        (
            lambda t: t.replace('"world.shelf_count" = 12', '"world.shelf_count" = 0'),
            "world.shelf_count",
            "x = 'world.shelf_count' is 0 in [overrides]; expected numbers > 0",
        ),
    ],
)
def test_a_loglog_x_the_study_sets_to_zero_is_refused_before_any_run(tmp_path, edit, x, fragment):
    path = _study(tmp_path, f'x = "{x}"\nloglog = ["wall_time_s"]\n', base=edit(BASE))
    with pytest.raises(ConfigError, match="loglog") as refused:
        load_study(path)
    assert fragment in str(refused.value)


def test_a_loglog_x_of_zero_in_a_case_names_the_case(tmp_path):
    base = BASE.replace('[grid]\n"robots.count" = [4, 8]\n', "")
    base += '\n[[cases]]\n"robots.count" = 4\n\n[[cases]]\n"robots.count" = 0\n'
    path = _study(tmp_path, 'x = "robots.count"\nloglog = ["wall_time_s"]\n', base=base)
    with pytest.raises(ConfigError, match=r"x = 'robots.count' is 0 in \[cases\[1\]\]"):
        load_study(path)


@pytest.mark.slow
def test_the_command_line_exits_2_with_one_line_on_a_bad_loglog(tmp_path):
    path = _study(tmp_path, 'x = "robots.count"\nloglog = "wall_time_s"\n')
    done = subprocess.run(
        [sys.executable, "-m", "cosim", "study", str(path), "--out", str(tmp_path / "out")],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 2, done.stdout
    assert "loglog = 'wall_time_s': expected a list of metric names" in done.stderr
    assert done.stderr.count("\n") == 1 and str(path) in done.stderr
    assert not (tmp_path / "out").exists()


def test_a_combination_an_adapter_cannot_run_is_refused_before_any_run_naming_it(tmp_path):
    path = tmp_path / "traffic_mapping.toml"
    path.write_text(
        '[study]\nname = "t"\nscenario = "fleet50"\nseeds = 1\nduration_s = 2\n\n'
        '[grid]\n"navigation.traffic" = ["none", "pibt"]\n\n'
        '[overrides]\n"mapping.enabled" = true\n"robots.count" = 4\n'
    )
    with pytest.raises(ConfigError) as refused:
        load_study(path)
    message = str(refused.value)
    assert message.startswith(f"{path} [grid/overrides/cases] (")
    assert "navigation.traffic = 'pibt'" in message
    assert "[navigation] traffic = 'pibt' with [mapping] enabled = true" in message


# --- keys the study sets itself, names, seeds (cosim.studies.spec) ---------------------------

SEED_PLACES = [
    ('\n[grid]\n"scenario.seed" = [1, 2]\n', "[grid] 'scenario.seed' = [1, 2]"),
    ('\n[[cases]]\n"scenario.seed" = 7\n', "[cases[0]] 'scenario.seed' = 7"),
    ('\n[grid]\n"robots.count" = [2]\n[[cases]]\n"scenario.seed" = 7\n', "[cases[0]]"),
]


@pytest.mark.parametrize(("extra", "fragment"), SEED_PLACES)
def test_a_grid_or_case_over_the_seed_is_refused_naming_the_study_file_and_key(
    tmp_path, extra, fragment
):
    path = small_study(tmp_path, extra=extra)
    done = cosim_main("study", str(path), "--out", str(tmp_path / "out"))
    assert done.returncode == 2, done.stdout
    assert done.stderr.startswith(f"cosim: error: {path}: {fragment}"), done.stderr
    assert "the study sets every run's seed from [study] seeds" in done.stderr
    assert done.stderr.count("\n") == 1, done.stderr
    assert not (tmp_path / "out").exists()


def test_an_override_of_the_seed_is_refused_naming_the_study_file_and_key(tmp_path):
    path = small_study(tmp_path)
    path.write_text(path.read_text().replace("[overrides]\n", '[overrides]\n"scenario.seed" = 3\n'))
    with pytest.raises(ConfigError) as refused:
        read_study(path)
    assert str(refused.value).startswith(f"{path}: [overrides] 'scenario.seed' = 3: the study sets")


def test_a_duration_grid_beside_the_studys_duration_is_refused(tmp_path):
    path = small_study(tmp_path, extra='\n[grid]\n"scenario.duration_s" = [1, 2]\n')
    done = cosim_main("study", str(path), "--out", str(tmp_path / "out"))
    assert done.returncode == 2 and done.stderr.count("\n") == 1, done.stderr
    assert f"{path}: [grid] 'scenario.duration_s' = [1, 2]: [study] duration_s = 1 sets" in (
        done.stderr
    )
    assert not (tmp_path / "out").exists()


def test_a_duration_grid_without_the_studys_duration_sets_each_runs_duration(tmp_path):
    path = small_study(
        tmp_path, duration_s=None, extra='\n[grid]\n"scenario.duration_s" = [1, 2]\n'
    )
    spec = read_study(path)
    assert spec.duration_s is None
    assert [r.overrides["scenario.duration_s"] for r in spec.runs()] == [1, 1, 1, 2, 2, 2]


@pytest.mark.parametrize("key", ["record.bag", "record.tables"])
def test_a_grid_over_a_record_key_study_runs_ignore_is_refused(tmp_path, key):
    path = small_study(tmp_path, extra=f'\n[grid]\n"{key}" = [true, false]\n')
    with pytest.raises(ConfigError, match="study runs ignore it") as refused:
        read_study(path)
    assert str(refused.value).startswith(f"{path}: [grid] '{key}' = [true, false]")


@pytest.mark.parametrize("name", ["../escape", "a/b", "..", ".", "/abs", "a\\\\b", "x" * 101])
def test_a_study_name_that_is_not_one_folder_name_is_refused_and_nothing_is_written(tmp_path, name):
    work = tmp_path / "work"
    work.mkdir()
    path = small_study(work, name=name)
    before = sorted(tmp_path.rglob("*"))
    # without --out the study folder would be runs/studies/NAME: the name must not escape it
    done = cosim_main("study", str(path), cwd=work)
    assert done.returncode == 2, done.stdout
    assert f"{path}: [study] name = " in done.stderr
    assert "expected one folder name" in done.stderr and done.stderr.count("\n") == 1
    assert sorted(tmp_path.rglob("*")) == before


def test_an_empty_study_name_is_refused(tmp_path):
    path = small_study(tmp_path, name="")
    with pytest.raises(ConfigError, match=r"\[study\] name = '': expected a non-empty string"):
        read_study(path)


def test_a_name_of_dots_pluses_and_dashes_inside_is_one_folder_name(tmp_path):
    assert read_study(small_study(tmp_path, name="comm-sweep_v1.2+rc")).name == "comm-sweep_v1.2+rc"


def test_a_thirty_digit_seed_is_refused_before_anything_runs(tmp_path):
    seed = "1" * 30
    path = small_study(tmp_path, seeds=f"[1, {seed}]")
    done = cosim_main("study", str(path), "--out", str(tmp_path / "out"))
    assert done.returncode == 2, done.stdout
    assert f"{path}: [study] seeds = [1, {seed}]: seed {seed} is out of range" in done.stderr
    assert f"expected seeds from 0 to {2**63 - 1}" in done.stderr
    assert done.stderr.count("\n") == 1 and not (tmp_path / "out").exists()


@pytest.mark.parametrize(
    ("seeds", "fragment"),
    [
        (f"[{2**63}]", f"seed {2**63} is out of range"),
        ("[-1]", "seed -1 is out of range"),
        ("[1, 1]", "expected distinct seeds"),
        ("0", "seeds = 0: expected a count from 1"),
        ("2.0", "seeds = 2.0: expected a count >= 1 or a list"),
        ("[true]", "seeds = [true]: expected a count >= 1 or a list"),
    ],
)
def test_seeds_that_do_not_fit_int64_or_repeat_are_refused(tmp_path, seeds, fragment):
    path = small_study(tmp_path, seeds=seeds)
    with pytest.raises(ConfigError) as refused:
        read_study(path)
    assert fragment in str(refused.value) and str(path) in str(refused.value)


def test_the_largest_int64_seed_is_a_seed(tmp_path):
    assert read_study(small_study(tmp_path, seeds=f"[0, {2**63 - 1}]")).seeds == (0, 2**63 - 1)
