"""Checking a study before any run (cosim.studies.validate): report names, kept tables."""

import time

import pytest

from cosim.core.errors import ConfigError
from cosim.studies import load_study
from tests.conftest import cosim_main
from tests.cosim.studies.small import small_study

LONG = {"seeds": "40", "duration_s": 3000.0}
"""A study of 40 runs of 3,000 simulated seconds: minutes of work if it started."""


@pytest.mark.slow
def test_a_report_metric_no_run_reports_is_refused_before_any_run(tmp_path):
    path = small_study(tmp_path, **LONG, extra='\n[report]\nmetrics = ["no_such_metric"]\n')
    out = tmp_path / "out"
    start = time.monotonic()
    done = cosim_main("study", str(path), "--out", str(out))
    took = time.monotonic() - start
    assert done.returncode == 2, done.stdout
    assert done.stderr.startswith(
        f"cosim: error: {path}: [report] metrics = ['no_such_metric']: no run of this study "
        "reports 'no_such_metric'"
    ), done.stderr
    assert done.stderr.count("\n") == 1
    assert not out.exists()  # no plan, no runs/
    assert took < 30, f"refusing took {took:.1f} s: the study ran before the check"


@pytest.mark.parametrize(
    ("report", "fragment"),
    [
        ('metrics = ["tasks_per_mn"]', "reports 'tasks_per_mn'; did you mean 'tasks_per_min'?"),
        ('x = "robots.count"\nhue = "protocl"', "hue = 'protocl': no run of this study reports it"),
        ('x = "robots.count"\nloglog = ["wall_tim_s"]', "did you mean 'wall_time_s'?"),
    ],
)
def test_a_misspelt_report_name_is_refused_with_a_suggestion(tmp_path, report, fragment):
    extra = '\n[grid]\n"robots.count" = [2, 3]\n[report]\n' + report + "\n"
    path = small_study(tmp_path, extra=extra)
    path.write_text(path.read_text().replace('"robots.count" = 2\n', ""))
    with pytest.raises(ConfigError) as refused:
        load_study(path)
    assert fragment in str(refused.value) and str(path) in str(refused.value)


def test_report_names_every_run_reports_are_accepted(tmp_path):
    extra = '\n[report]\nmetrics = ["tasks_per_min", "optimality_gap"]\nx = "seed"\n'
    spec = load_study(small_study(tmp_path, extra=extra))
    assert spec.report["metrics"] == ["tasks_per_min", "optimality_gap"]


def test_a_kept_table_no_run_writes_is_refused_naming_it(tmp_path):
    path = small_study(tmp_path)
    path.write_text(path.read_text().replace("seeds = [1, 2, 3]", 'seeds = 1\ntables = ["psoes"]'))
    with pytest.raises(
        ConfigError, match=r"tables = \['psoes'\]: no run of this study has 'psoes'"
    ):
        load_study(path)
