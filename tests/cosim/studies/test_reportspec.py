"""A study's ``[report]``: its shape checked from the file, its names against what runs report."""

from __future__ import annotations

from pathlib import Path

import pytest

from cosim.core.errors import ConfigError
from cosim.studies.reportspec import (
    RunColumns,
    check_report,
    check_report_names,
    check_timeseries,
    names_to_check,
    study_keys,
)

PATH = Path("study.toml")
GRID = {"network.latency_ms": [0, 50], "assignment.protocol": ["cbba", "simplex"]}
OVERRIDES = {"robots.count": 4}
CASES = ({"network.loss_prob": 0.1}, {"network.loss_prob": 0.0, "robots.count": 8})
COLUMNS = RunColumns(
    metrics=frozenset({"tasks_per_min", "messages_sent", "robots", "scenario", "source"}),
    derived={
        "wall_us_per_robot_s": ("wall_time_s", "robots", "sim_time_s"),
        "per_robot": ("robots",),
    },
    tables={"map_quality": frozenset({"t_s", "robot", "iou"}), "links": frozenset({"a", "b"})},
)


def _shape(report: dict[str, object], *, grid: dict[str, object] | None = None) -> str:
    with pytest.raises(ConfigError) as refused:
        check_report(PATH, report, GRID if grid is None else grid, OVERRIDES, CASES)
    return str(refused.value)


def test_the_keys_a_study_sets_are_its_grid_overrides_and_cases():
    assert study_keys(GRID, OVERRIDES, CASES) == {
        "network.latency_ms", "assignment.protocol", "robots.count", "network.loss_prob",
    }  # fmt: skip


def test_a_report_naming_keys_the_study_sets_and_metrics_passes_its_shape_check():
    report = {
        "x": "robots.count",
        "hue": "assignment.protocol",
        "facet": "network.loss_prob",
        "metrics": ["tasks_per_min"],
        "heatmaps": ["tasks_per_min"],
        "loglog": ["wall_time_s"],
    }
    check_report(PATH, report, GRID, OVERRIDES, CASES)


@pytest.mark.parametrize(
    ("report", "said"),
    [
        ({"x": 3}, "[report] x = 3: expected a column name"),
        ({"hue": ""}, "[report] hue = '': expected a column name"),
        (
            {"metrics": "tasks_per_min"},
            "metrics = 'tasks_per_min': expected a list of metric names",
        ),
        ({"loglog": [1]}, "[report] loglog = [1]: expected a list of metric names"),
        ({"heatmaps": ["t"], "x": "robots.count"}, "heatmaps need x and facet"),
        ({"loglog": ["t"]}, "[report] loglog = ['t']: needs x (the horizontal log axis)"),
    ],
)
def test_a_report_of_the_wrong_shape_is_refused_naming_the_file_and_key(report, said):
    message = _shape(report)
    assert message.startswith(f"{PATH}: [report] ") and said in message


def test_a_dotted_column_must_be_a_key_the_study_sets_listing_them():
    assert _shape({"facet": "network.latency_mz"}) == (
        "study.toml: [report] facet = 'network.latency_mz': not a key this study sets (expected "
        "one of assignment.protocol, network.latency_ms, network.loss_prob, robots.count, or a "
        "summary metric)"
    )
    with pytest.raises(ConfigError, match=r"not a key this study sets \(expected one of none, or"):
        check_report(PATH, {"x": "a.b"}, {}, {}, ())


def test_log_log_figures_need_every_value_of_x_above_zero_wherever_it_is_set():
    report = {"x": "network.latency_ms", "loglog": ["tasks_per_min"]}
    assert _shape(report) == (
        "study.toml: [report] loglog = ['tasks_per_min']: x = 'network.latency_ms' is 0 in "
        "[grid]; expected numbers > 0 on a log axis"
    )
    in_case = {"x": "network.loss_prob", "loglog": ["tasks_per_min"]}
    assert "x = 'network.loss_prob' is 0.0 in [cases[1]]" in _shape(in_case)
    flag = {"x": "robots.count", "loglog": ["m"]}
    with pytest.raises(ConfigError, match=r"is True in \[overrides\]"):
        check_report(PATH, flag, {}, {"robots.count": True}, ())
    check_report(PATH, {"x": "robots.count", "loglog": ["m"]}, {}, OVERRIDES, ())
    check_report(PATH, {"x": "wall_time_s", "loglog": ["m"]}, {}, {}, ())  # a metric: later


def test_time_series_name_a_kept_table_a_column_and_a_filter():
    entries = [{"table": "map_quality", "y": "iou", "where": {"robot": "fleet"}}]
    check_timeseries(PATH, entries, ("map_quality",))
    check_timeseries(PATH, entries, ("*",))  # every table kept


@pytest.mark.parametrize(
    ("entries", "said"),
    [
        ({"table": "t"}, "[report] timeseries = {'table': 't'}: expected a list of tables"),
        (
            [{"table": "map_quality", "y": "iou", "wher": {}}],
            "[report.timeseries[0]] unknown key 'wher'; did you mean 'where'?",
        ),
        ([{"table": "map_quality"}], "[report.timeseries[0]] table = 'map_quality', y = None"),
        (
            [{"table": "poses", "y": "x_m"}],
            "[report.timeseries[0]] table = 'poses': expected one the study keeps ([study] tables "
            "= ['map_quality'])",
        ),
        (
            [{"table": "map_quality", "y": "iou", "where": {"robot": ["a"]}}],
            "where = {'robot': ['a']}: expected column = value",
        ),
    ],
)
def test_a_time_series_entry_of_the_wrong_shape_is_refused_naming_its_index(entries, said):
    with pytest.raises(ConfigError) as refused:
        check_timeseries(PATH, entries, ("map_quality",))
    assert str(refused.value).startswith(f"{PATH}: [report")
    assert said in str(refused.value)


@pytest.mark.parametrize(
    ("report", "names"),
    [
        ({}, False),
        ({"x": "network.latency_ms", "facet": "robots.count"}, False),
        ({"x": "tasks_per_min"}, True),
        ({"metrics": ["tasks_per_min"]}, True),
        ({"timeseries": [{"table": "t", "y": "y"}]}, True),
    ],
)
def test_only_undotted_columns_metrics_and_time_series_need_the_runs_names(report, names):
    assert names_to_check(report) is names


def test_names_the_runs_report_pass_and_derived_ones_only_with_their_inputs():
    keys = study_keys(GRID, OVERRIDES, CASES)
    report = {
        "x": "network.latency_ms",
        "hue": "seed",
        "metrics": ["tasks_per_min", "per_robot", "wall_time_s", "network.latency_ms"],
        "timeseries": [{"table": "map_quality", "y": "iou", "where": {"robot": "fleet"}}],
    }
    check_report_names(PATH, report, keys, COLUMNS)
    # wall_us_per_robot_s needs sim_time_s, which no run of this study reports
    with pytest.raises(ConfigError, match=r"no run of this study reports 'wall_us_per_robot_s'"):
        check_report_names(PATH, {"metrics": ["wall_us_per_robot_s"]}, set(), COLUMNS)
    reported = RunColumns(COLUMNS.metrics | {"sim_time_s"}, COLUMNS.derived, COLUMNS.tables)
    check_report_names(PATH, {"metrics": ["wall_us_per_robot_s"]}, set(), reported)


@pytest.mark.parametrize(
    ("report", "said"),
    [
        ({"x": "task_per_min"}, "[report] x = 'task_per_min': no run of this study reports it; "
         "did you mean 'tasks_per_min'?"),
        ({"metrics": ["tasks_per_min", "mesages_sent"]}, "[report] metrics = ['tasks_per_min', "
         "'mesages_sent']: no run of this study reports 'mesages_sent'; did you mean "
         "'messages_sent'?"),
        ({"metrics": ["source"]}, "no run of this study reports 'source'"),
        ({"metrics": ["status"]}, "no run of this study reports 'status'"),
        ({"timeseries": [{"table": "map_qualty", "y": "iou"}]},
         "[report.timeseries[0]] table = 'map_qualty': no run of this study has it; did you mean "
         "'map_quality'?"),
        ({"timeseries": [{"table": "links", "y": "a"}]},
         "[report.timeseries[0]] table = 'links': has no t_s column to plot over time"),
        ({"timeseries": [{"table": "map_quality", "y": "iuo"}]},
         "[report.timeseries[0]] map_quality has no column 'iuo'; did you mean 'iou'?"),
        ({"timeseries": [{"table": "map_quality", "y": "iou", "where": {"robt": "a"}}]},
         "map_quality has no column 'robt'; did you mean 'robot'?"),
    ],
)  # fmt: skip
def test_a_name_no_run_reports_is_refused_naming_the_report_key_and_the_nearest(report, said):
    with pytest.raises(ConfigError) as refused:
        check_report_names(PATH, report, set(), COLUMNS)
    assert str(refused.value).startswith(f"{PATH}: [report")
    assert said in str(refused.value)
