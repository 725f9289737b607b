import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from matplotlib.collections import PathCollection, PolyCollection

from cosim.core.errors import ConfigError, ExportError
from cosim.studies.analysis import (
    aggregate,
    heatmap,
    load_results,
    markdown_table,
    metric_figure,
    plot_metric,
    standard_figures,
    write_report,
)

PROTOCOLS = ["simplex", "cbba", "hungarian"]  # deliberately not alphabetical
LATENCIES = [100, 0, 20, 5]  # deliberately not sorted
SEEDS = [1, 2, 3, 4, 5]
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
X, HUE = "network.latency_ms", "assignment.protocol"


def _results() -> pd.DataFrame:
    """3 protocols x 4 latencies x 5 seeds of known means plus noise, and 2 failed runs."""
    rng = np.random.default_rng(7)
    rows = []
    for protocol_index, protocol in enumerate(PROTOCOLS):
        for latency in LATENCIES:
            for seed in SEEDS:
                rows.append(
                    {
                        "run_id": f"{protocol}-{latency}-{seed}",
                        "seed": seed,
                        HUE: protocol,
                        X: latency,
                        "network.loss_prob": 0.1,
                        "tasks_per_min": 10.0
                        + protocol_index
                        - 0.02 * latency
                        + rng.normal(0, 0.5),
                        "messages_dropped": int(rng.integers(0, 50)),
                        "status": "ok",
                        "error": "",
                    }
                )
    for seed, message in [(6, "ScenarioError: shelves do not fit\nTraceback ..."), (7, "")]:
        rows.append(
            {
                "run_id": f"broken-{seed}",
                "seed": seed,
                HUE: "cbba",
                X: 5,
                "network.loss_prob": 0.1,
                "tasks_per_min": 1e6,  # would show in every statistic if it were counted
                "messages_dropped": 10**6,
                "status": "error",
                "error": message,
            }
        )
    return pd.DataFrame(rows)


@pytest.fixture
def results() -> pd.DataFrame:
    return _results()


@pytest.fixture
def study(tmp_path: Path) -> Path:
    _results().to_parquet(tmp_path / "results.parquet")
    return tmp_path


def _group(results: pd.DataFrame, protocol: str, latency: int) -> np.ndarray:
    ok = results[results["status"] == "ok"]
    return ok[(ok[HUE] == protocol) & (ok[X] == latency)]["tasks_per_min"].to_numpy()


def test_aggregate_matches_a_seeded_percentile_bootstrap_of_the_mean_for_every_group(results):
    table = aggregate(results, [HUE, X], ["tasks_per_min"], confidence=0.9)
    assert len(table) == len(PROTOCOLS) * len(LATENCIES)
    for row in table.to_dict("records"):
        values = _group(results, row[HUE], row[X])
        mean, std, n = values.mean(), values.std(ddof=1), len(values)
        rng = np.random.default_rng(0)
        means = values[rng.integers(0, n, size=(2000, n))].mean(axis=1)
        low, high = np.quantile(means, [0.05, 0.95])
        assert row["tasks_per_min_n"] == n == len(SEEDS)
        assert row["tasks_per_min_mean"] == pytest.approx(mean)
        assert row["tasks_per_min_std"] == pytest.approx(std)
        assert row["tasks_per_min_ci_low"] == pytest.approx(low)
        assert row["tasks_per_min_ci_high"] == pytest.approx(high)
        assert values.min() <= low < mean < high <= values.max()


def test_aggregate_gives_every_statistic_column_for_every_metric(results):
    table = aggregate(results, [X], ["tasks_per_min", "messages_dropped"])
    for metric in ["tasks_per_min", "messages_dropped"]:
        for suffix in ["mean", "std", "n", "ci_low", "ci_high"]:
            assert f"{metric}_{suffix}" in table.columns
    assert table["messages_dropped_n"].tolist() == [len(PROTOCOLS) * len(SEEDS)] * len(LATENCIES)


def test_groups_are_ordered_numbers_ascending_and_strings_as_they_first_appear(results):
    table = aggregate(results, [HUE, X], ["tasks_per_min"])
    assert list(dict.fromkeys(table[HUE])) == PROTOCOLS
    assert table[X].tolist()[: len(LATENCIES)] == sorted(LATENCIES)
    assert table[HUE].dtype == results[HUE].dtype  # not left as a categorical


def test_failed_runs_are_left_out_of_every_statistic(results):
    table = aggregate(results, [HUE, X], ["tasks_per_min"])
    row = table[(table[HUE] == "cbba") & (table[X] == 5)].iloc[0]
    assert row["tasks_per_min_n"] == len(SEEDS)
    assert row["tasks_per_min_mean"] == pytest.approx(_group(results, "cbba", 5).mean())
    assert row["tasks_per_min_mean"] < 100


def test_a_group_of_one_run_has_no_std_and_an_interval_of_no_width(results):
    one = results[results["seed"] == 1]
    table = aggregate(one, [HUE, X], ["tasks_per_min"])
    assert (table["tasks_per_min_n"] == 1).all()
    assert table["tasks_per_min_std"].isna().all()
    assert (table["tasks_per_min_ci_low"] == table["tasks_per_min_mean"]).all()
    assert (table["tasks_per_min_ci_high"] == table["tasks_per_min_mean"]).all()


def test_nan_values_are_dropped_per_metric_and_not_counted(results):
    results.loc[results["seed"] <= 2, "tasks_per_min"] = np.nan
    results.loc[(results[X] == 0) & (results[HUE] == "cbba"), "tasks_per_min"] = np.nan
    table = aggregate(results, [HUE, X], ["tasks_per_min", "messages_dropped"])
    empty = table[(table[HUE] == "cbba") & (table[X] == 0)].iloc[0]
    assert empty["tasks_per_min_n"] == 0
    assert np.isnan(empty[["tasks_per_min_mean", "tasks_per_min_ci_low"]].astype(float)).all()
    others = table.drop(index=empty.name)
    assert (others["tasks_per_min_n"] == 3).all()
    assert (table["messages_dropped_n"] == len(SEEDS)).all()  # the other metric keeps all
    values = _group(results, "hungarian", 20)
    row = table[(table[HUE] == "hungarian") & (table[X] == 20)].iloc[0]
    assert row["tasks_per_min_mean"] == pytest.approx(np.nanmean(values))


def test_aggregate_by_no_column_gives_one_row_over_all_ok_runs(results):
    table = aggregate(results, [], ["tasks_per_min"])
    assert len(table) == 1
    ok = results[results["status"] == "ok"]["tasks_per_min"]
    assert table["tasks_per_min_mean"].iloc[0] == pytest.approx(ok.mean())
    assert table["tasks_per_min_n"].iloc[0] == len(ok)


def test_boolean_metrics_average_to_the_fraction_of_true_runs():
    frame = pd.DataFrame(
        {
            "run_id": list("abcd"),
            "seed": [1, 2, 1, 2],
            "ui.enabled": [True, True, False, False],
            "deadlock": [True, False, False, False],
            "status": "ok",
        }
    )
    table = aggregate(frame, ["ui.enabled"], ["deadlock"])
    assert table["ui.enabled"].tolist() == [False, True]
    assert table["deadlock_mean"].tolist() == [0.0, 0.5]


def test_a_missing_column_is_a_config_error_suggesting_the_closest_name(results):
    with pytest.raises(
        ConfigError, match=r"'network\.latency'.*did you mean 'network\.latency_ms'"
    ):
        aggregate(results, ["network.latency"], ["tasks_per_min"])


def test_a_non_numeric_metric_or_a_bad_confidence_is_a_config_error(results):
    with pytest.raises(ConfigError, match="run_id"):
        aggregate(results, [X], ["run_id"])
    with pytest.raises(ConfigError, match="confidence"):
        aggregate(results, [X], ["tasks_per_min"], confidence=95)


def test_metric_figure_draws_a_line_a_band_and_each_runs_point_per_hue_value(results):
    figure = metric_figure(results, X, "tasks_per_min", hue=HUE)
    (ax,) = figure.axes[:1]
    lines = ax.get_lines()
    assert len(lines) == len(PROTOCOLS)
    bands = [c for c in ax.collections if isinstance(c, PolyCollection)]
    dots = [c for c in ax.collections if type(c) is PathCollection]
    assert len(bands) == len(dots) == len(PROTOCOLS)
    assert [len(d.get_offsets()) for d in dots] == [len(LATENCIES) * len(SEEDS)] * 3
    assert [text.get_text() for text in ax.get_legend().get_texts()] == PROTOCOLS
    assert ax.get_legend().get_title().get_text() == "Assignment protocol"
    assert ax.get_xlabel() == "Network latency (ms)" and ax.get_ylabel() == "Tasks per minute"
    assert "band: 95 % bootstrap interval of the mean, n = 5 seeds per point" in (
        figure.get_suptitle()
    )
    table = aggregate(results, [HUE, X], ["tasks_per_min"])
    first = table[table[HUE] == PROTOCOLS[0]]
    np.testing.assert_array_equal(lines[0].get_xdata(), sorted(LATENCIES))
    np.testing.assert_allclose(lines[0].get_ydata(), first["tasks_per_min_mean"])


def test_faceting_gives_a_subplot_per_value_sharing_the_y_axis(results):
    figure = metric_figure(results, X, "tasks_per_min", hue="seed", facet=HUE)
    assert len(figure.axes) == len(PROTOCOLS)
    assert [ax.get_title() for ax in figure.axes] == [
        f"Assignment protocol = {p}" for p in PROTOCOLS
    ]
    assert all(len(ax.get_lines()) == len(SEEDS) for ax in figure.axes)
    assert figure.axes[0].get_shared_y_axes().joined(figure.axes[0], figure.axes[2])


def test_a_string_x_is_a_categorical_axis_in_the_given_order(results):
    figure = metric_figure(results, HUE, "tasks_per_min", hue=X)
    ax = figure.axes[0]
    assert [label.get_text() for label in ax.get_xticklabels()] == PROTOCOLS
    assert len(ax.get_lines()) == len(LATENCIES)
    with pytest.raises(ConfigError, match="logx"):
        metric_figure(results, HUE, "tasks_per_min", logx=True)


def test_a_boolean_x_is_categorical_false_before_true():
    frame = pd.DataFrame(
        {"seed": [1, 2, 1, 2], "ui.enabled": [True, False, True, False], "rate": [1.0, 2, 3, 4]}
    )
    frame["status"] = "ok"
    ax = metric_figure(frame, "ui.enabled", "rate").axes[0]
    assert [label.get_text() for label in ax.get_xticklabels()] == ["False", "True"]
    np.testing.assert_allclose(ax.get_lines()[0].get_ydata(), [3.0, 2.0])


def test_plot_metric_and_heatmap_write_png_files(results, tmp_path):
    line = plot_metric(
        results, x=X, metric="tasks_per_min", hue=HUE, out=tmp_path / "a" / "line.png", logx=True
    )
    grid = heatmap(results, x=X, y=HUE, metric="tasks_per_min", out=tmp_path / "grid.png")
    faceted = heatmap(
        results, x=X, y="seed", metric="tasks_per_min", facet=HUE, out=tmp_path / "facets.png"
    )
    for path in (line, grid, faceted):
        assert path.read_bytes()[:8] == PNG_MAGIC


def test_plotting_a_metric_without_any_value_is_an_export_error(results, tmp_path):
    results["tasks_per_min"] = np.nan
    with pytest.raises(ExportError, match="tasks_per_min"):
        plot_metric(results, x=X, metric="tasks_per_min", out=tmp_path / "x.png")


def test_standard_figures_draw_each_usable_metric_against_x(study):
    metrics = ["tasks_per_min", "messages_dropped", "not_a_metric"]
    paths = standard_figures(study, x=X, hue=HUE, metrics=metrics)
    assert paths == [
        study / "figures" / f"tasks_per_min_vs_{X}.png",
        study / "figures" / f"messages_dropped_vs_{X}.png",
    ]
    assert all(path.read_bytes()[:8] == PNG_MAGIC for path in paths)


def test_standard_figures_without_x_draw_a_point_per_hue_value(study):
    (path,) = standard_figures(study, x=None, hue=HUE, metrics=["tasks_per_min"])
    assert path == study / "figures" / f"tasks_per_min_by_{HUE}.png"
    assert path.read_bytes()[:8] == PNG_MAGIC


def test_the_report_has_counts_errors_a_table_per_metric_and_figure_links(study):
    figures = standard_figures(study, x=X, hue=HUE, metrics=["tasks_per_min"])
    path = write_report(
        study,
        name="comm_sweep",
        x=X,
        hue=HUE,
        metrics=["tasks_per_min", "not_a_metric"],
        description="Throughput against latency.",
        figures=figures,
    )
    text = path.read_text()
    assert path == study / "report.md"
    assert text.startswith("# comm_sweep\n\nThroughput against latency.")
    assert "60 ok, 2 failed" in text
    assert "- `broken-6` (seed 6): ScenarioError: shelves do not fit\n" in text
    assert "- `broken-7` (seed 7): no message" in text
    assert "### tasks_per_min" in text
    assert f"| {HUE}" in text and "95 % percentile bootstrap interval of the mean" in text
    assert re.search(r"\| \d+\.?\d* \[\d+\.?\d*, \d+\.?\d*\] +\| +5 \|", text)
    assert text.count("| simplex ") == len(LATENCIES)
    assert "- `not_a_metric`: no such column in the results, skipped." in text
    assert f"![tasks_per_min_vs_{X}](figures/tasks_per_min_vs_{X}.png)" in text


def test_the_report_names_varying_parameters_it_pools_over(study):
    text = write_report(study, name="s", x=X, hue=None, metrics=["tasks_per_min"]).read_text()
    assert f"pooled over `{HUE}`" in text
    assert "network.loss_prob" not in text  # constant: nothing is pooled over it


def test_a_study_without_ok_runs_gets_a_report_saying_so_and_no_figures(tmp_path):
    failed = _results().assign(status="error", error="boom")
    failed.to_parquet(tmp_path / "results.parquet")
    assert standard_figures(tmp_path, x=X, hue=HUE, metrics=["tasks_per_min"]) == []
    text = write_report(tmp_path, name="s", x=X, hue=HUE, metrics=["tasks_per_min"]).read_text()
    assert "0 ok, 62 failed" in text
    assert "No run finished successfully" in text
    assert "- … and 57 more" in text
    assert "### tasks_per_min" not in text and "## Figures" not in text


def test_load_results_reads_every_run_back(study):
    frame = load_results(str(study))
    assert len(frame) == 62
    assert {"run_id", "seed", X, HUE, "tasks_per_min", "status", "error"} <= set(frame.columns)


def test_load_results_on_a_missing_folder_names_the_path(tmp_path):
    missing = tmp_path / "no_such_study"
    with pytest.raises(ExportError, match=re.escape(str(missing / "results.parquet"))):
        load_results(missing)


def test_load_results_on_a_corrupt_file_names_the_path(tmp_path):
    (tmp_path / "results.parquet").write_bytes(b"not parquet at all")
    with pytest.raises(ExportError, match=r"results\.parquet: cannot read"):
        load_results(tmp_path)
    pd.DataFrame({"a": [1]}).to_parquet(tmp_path / "results.parquet")
    with pytest.raises(ExportError, match="no column run_id, seed, status"):
        load_results(tmp_path)


def _header(table: str) -> list[str]:
    return [cell.strip() for cell in table.splitlines()[0].split("|")[1:-1]]


def test_markdown_table_formats_floats_and_shows_only_a_meaningful_index():
    text = markdown_table(pd.DataFrame({"x": [1, 2], "y": [0.123456, 2.0]}))
    assert _header(text) == ["x", "y"]
    assert "0.123" in text and "0.123456" not in text
    indexed = pd.DataFrame({"y": [1.0]}, index=pd.Index([3], name="x"))
    assert _header(markdown_table(indexed)) == ["x", "y"]
