"""Study files: the ``[report] loglog`` key (cosim.studies.spec)."""

import subprocess
import sys
from pathlib import Path

import pytest

from cosim.core.errors import ConfigError
from cosim.studies import load_study

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
