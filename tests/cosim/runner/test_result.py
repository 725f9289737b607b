"""A run's result: its tables, and those of them that equal runs reproduce exactly."""

import pandas as pd

from cosim.runner.result import RunResult


def test_the_deterministic_tables_leave_out_only_the_wall_clock_columns(small_scenario):
    realtime = pd.DataFrame({"t_s": [0.0, 0.5], "lateness_ms": [1.2, 0.3], "events": [4, 2]})
    poses = pd.DataFrame({"t_s": [0.0, 0.1], "x_m": [1.0, 1.1]})
    result = RunResult(
        small_scenario,
        {"scenario": "x"},
        {"realtime": realtime, "poses": poses},
        volatile={"realtime": ("lateness_ms",)},
    )
    tables = result.deterministic_tables()
    assert list(tables["realtime"].columns) == ["t_s", "events"]
    pd.testing.assert_frame_equal(tables["poses"], poses)
    assert list(result.tables["realtime"].columns) == ["t_s", "lateness_ms", "events"]


def test_a_fresh_run_result_keeps_its_tables_and_summary_and_reports_nothing_else(small_scenario):
    poses = pd.DataFrame({"t_s": [0.0]})
    result = RunResult(small_scenario, {"scenario": "x", "events": 3}, {"poses": poses})
    assert result.summary == {"scenario": "x", "events": 3}
    assert result.tables["poses"] is poses
    assert (result.out, result.bag, result.stopped, result.failure) == (None, None, None, None)
    assert (result.recorded, result.maps, result.files) == ({}, {}, {})
    assert result.compile_time_s == 0.0
    assert "tables={" not in repr(result)  # DataFrames stay out of the repr
