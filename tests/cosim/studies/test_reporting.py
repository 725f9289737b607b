"""Study reports: derived metrics and log-log figures (cosim.studies.reporting)."""

import json
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from cosim.core.errors import ConfigError
from cosim.studies import load_study, run_study
from cosim.studies.derived import DERIVED_METRICS
from cosim.studies.reporting import loglog_figure, loglog_figures, report_study

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
X = "robots.count"
HALLS = {4: ([15.0, 15.0], 12), 16: ([17.0, 17.0], 18), 50: ([30.0, 30.0], 72)}
FIGURE = "wall_us_per_robot_s_vs_robots.count_loglog.png"

STUDY = """
[study]
name = "scale_small"
scenario = "fleet50"
seeds = 2
duration_s = 10

[overrides]
"record.messages" = false
{cases}
[report]
x = "robots.count"
metrics = ["collisions"]
loglog = ["wall_us_per_robot_s", "collisions"]
"""


def _cases() -> str:
    return "".join(
        f'\n[[cases]]\n"robots.count" = {n}\n"world.size_m" = {size}\n'
        f'"world.shelf_count" = {shelves}\n'
        for n, (size, shelves) in HALLS.items()
    )


def _study_folder(tmp_path: Path, rows: list[dict]) -> Path:
    """A study file for 4, 16 and 50 robots and a folder holding ``rows`` as its results."""
    path = tmp_path / "study.toml"
    path.write_text(STUDY.format(cases=_cases()))
    out = tmp_path / "out"
    out.mkdir()
    pd.DataFrame(rows).to_parquet(out / "results.parquet", index=False)
    return path


def _row(robots: int, seed: int, wall_time_s: float, collisions: int = 1) -> dict:
    size, shelves = HALLS[robots]
    return {
        "run_id": f"{robots}_s{seed}",
        "seed": seed,
        X: robots,
        "world.size_m": json.dumps(size),
        "world.shelf_count": shelves,
        "robots": robots,
        "sim_time_s": 10.0,
        "wall_time_s": wall_time_s,
        "collisions": collisions,
        "status": "ok",
        "error": "",
    }


ROWS = [
    _row(4, 1, 0.1),
    _row(4, 2, 0.12),
    _row(16, 1, 0.8),
    _row(16, 2, 0.8, collisions=0),
    _row(50, 1, 5.0),
    _row(50, 2, 6.0),
]


def test_a_report_naming_a_derived_metric_adds_it_to_the_results_exactly(tmp_path):
    failed = {**_row(50, 3, 0.4), "robots": None, "status": "error", "error": "boom"}
    path = _study_folder(tmp_path, [*ROWS, failed])
    report_study(load_study(path), tmp_path / "out")
    results = pd.read_parquet(tmp_path / "out" / "results.parquet")
    expected = [2500.0, 3000.0, 5000.0, 5000.0, 10000.0, 12000.0]
    assert results["wall_us_per_robot_s"].iloc[:6].tolist() == pytest.approx(expected)
    assert np.isnan(results["wall_us_per_robot_s"].iloc[6])  # the failed run has no robots


def test_a_loglog_report_writes_the_figure_links_it_and_tabulates_the_metric(tmp_path):
    path = _study_folder(tmp_path, ROWS)
    report = report_study(load_study(path), tmp_path / "out").read_text()
    png = tmp_path / "out" / "figures" / FIGURE
    assert png.read_bytes()[:8] == PNG_MAGIC and png.stat().st_size > 10_000
    assert f"(figures/{FIGURE})" in report
    assert "### wall_us_per_robot_s" in report
    table = report.split("### wall_us_per_robot_s")[1].split("##")[0]
    # mean of 2500 and 3000; two runs: the bootstrap interval of the mean is their range
    assert re.search(r"\|\s+4 \| 2\.75e\+03 \[2\.5e\+03, 3e\+03\] .*\|\s+2 \|", table)
    assert re.search(r"\|\s+16 \| 5e\+03 \[5e\+03, 5e\+03\] .*\|\s+2 \|", table)
    drawn = pd.read_csv(png.with_suffix(".csv"))
    assert list(drawn.columns) == [X, "n", "mean", "low", "high"]
    assert drawn.loc[0].tolist() == pytest.approx([4, 2, 2750.0, 2500.0, 3000.0])
    assert "1e6 x wall_time_s / (robots x sim_time_s)" in report
    # listed only under loglog: no linear figure of it; collisions (in metrics too) has both
    assert not (tmp_path / "out" / "figures" / "wall_us_per_robot_s_vs_robots.count.png").exists()
    assert (tmp_path / "out" / "figures" / "collisions_vs_robots.count.png").exists()
    assert (tmp_path / "out" / "figures" / "collisions_vs_robots.count_loglog.png").exists()


def test_runs_with_a_value_not_above_zero_are_left_out_of_a_loglog_figure_and_noted(tmp_path):
    path = _study_folder(tmp_path, ROWS)
    report = report_study(load_study(path), tmp_path / "out").read_text()
    assert "`collisions` on log-log axes: 1 of 6 runs left out" in report


def test_a_loglog_figure_has_log_axes_ticks_at_the_studied_values_and_the_means():
    frame = pd.DataFrame(ROWS)
    frame["wall_us_per_robot_s"] = DERIVED_METRICS["wall_us_per_robot_s"].compute(frame)
    figure = loglog_figure(frame, X, "wall_us_per_robot_s")
    (ax,) = figure.axes
    assert (ax.get_xscale(), ax.get_yscale()) == ("log", "log")
    assert [t.get_text() for t in ax.get_xticklabels()] == ["4", "16", "50"]
    (line,) = ax.get_lines()
    assert line.get_xdata().tolist() == [4.0, 16.0, 50.0]
    assert line.get_ydata().tolist() == pytest.approx([2750.0, 5000.0, 11000.0])


def test_a_loglog_figure_over_a_text_column_is_refused_naming_it(tmp_path):
    _study_folder(tmp_path, ROWS)
    expected = r"loglog: x = 'world.size_m' holds \w+ values; expected numbers > 0"
    with pytest.raises(ConfigError, match=expected):
        loglog_figures(tmp_path / "out", x="world.size_m", metrics=["wall_time_s"])


def test_a_real_scale_study_reports_wall_time_per_robot_second_from_its_runs(tmp_path):
    text = STUDY.format(cases=_cases()).replace("seeds = 2", "seeds = 1")
    text = text.replace("duration_s = 10", "duration_s = 1")
    path = tmp_path / "study.toml"
    path.write_text(text.replace('"robots.count" = 50', '"robots.count" = 8'))
    results = run_study(load_study(path), tmp_path / "out", workers=1)
    assert set(results["status"]) == {"ok"}
    written = pd.read_parquet(tmp_path / "out" / "results.parquet")
    robot_s = written["robots"] * written["sim_time_s"]
    assert written["wall_us_per_robot_s"].tolist() == pytest.approx(
        (1e6 * written["wall_time_s"] / robot_s).tolist()
    )
    assert (tmp_path / "out" / "figures" / FIGURE).stat().st_size > 10_000
