"""Each study figure has a ``<figure>.csv`` beside it with what it draws."""

import numpy as np
import pandas as pd
import pytest

from cosim.studies.analysis import heatmap, standard_figures
from cosim.studies.timeseries import timeseries_figures

X, HUE, FACET = "network.latency_ms", "assignment.protocol", "network.loss_prob"


def _results() -> pd.DataFrame:
    rng = np.random.default_rng(1)
    rows = [
        {
            "run_id": f"{loss}-{latency}-{protocol}-{seed}",
            "seed": seed,
            X: latency,
            HUE: protocol,
            FACET: loss,
            "tasks_per_min": max(0.0, 5.0 - 0.01 * latency + rng.normal(0, 2)),
            "status": "ok",
        }
        for loss in (0.0, 0.3)
        for latency in (0, 100)
        for protocol in ("cbba", "simplex")
        for seed in (1, 2, 3)
    ]
    return pd.DataFrame(rows)


def test_a_metric_figure_has_a_csv_beside_it_with_the_groups_n_and_the_band_drawn(tmp_path):
    results = _results()
    results.to_parquet(tmp_path / "results.parquet")
    (png,) = standard_figures(tmp_path, x=X, hue=HUE, facet=FACET, metrics=["tasks_per_min"])
    drawn = pd.read_csv(png.with_suffix(".csv"))
    assert list(drawn.columns) == [FACET, HUE, X, "n", "mean", "low", "high"]
    assert len(drawn) == 8 and (drawn["n"] == 3).all()
    for row in drawn.to_dict("records"):
        runs = results[
            (results[FACET] == row[FACET]) & (results[HUE] == row[HUE]) & (results[X] == row[X])
        ]["tasks_per_min"]
        assert row["mean"] == pytest.approx(runs.mean())
        assert runs.min() <= row["low"] <= row["mean"] <= row["high"] <= runs.max()


def test_a_heatmap_has_a_csv_beside_it_with_the_mean_of_each_cell(tmp_path):
    results = _results()
    png = heatmap(results, x=X, y=FACET, metric="tasks_per_min", out=tmp_path / "grid.png")
    drawn = pd.read_csv(png.with_suffix(".csv"))
    assert list(drawn.columns) == [FACET, X, "n", "mean", "low", "high"]
    means = results.groupby([FACET, X])["tasks_per_min"].mean().to_numpy()
    np.testing.assert_allclose(drawn["mean"], means)
    assert (drawn["n"] == 6).all()


def test_a_timeseries_figure_has_a_csv_of_the_series_drawn(tmp_path):
    results = _results()[lambda r: (r[FACET] == 0.0) & (r[HUE] == "cbba")]
    results.to_parquet(tmp_path / "results.parquet")
    for run in results.itertuples():
        tables = tmp_path / "runs" / str(run.run_id) / "tables"
        tables.mkdir(parents=True)
        t = np.arange(4.0)
        coverage = np.minimum(1.0, 0.3 * t * run.seed / 2)
        pd.DataFrame({"t_s": t, "coverage": coverage, "robot": "fleet"}).to_parquet(
            tables / "map_quality.parquet"
        )
    entry = {"table": "map_quality", "y": "coverage", "where": {"robot": "fleet"}}
    pngs = timeseries_figures(tmp_path, entry, x=X, hue=None, facet=None)
    assert [p.name for p in pngs] == [f"coverage_over_time_at_{X}={v}.png" for v in (0, 100)]
    drawn = pd.read_csv(pngs[0].with_suffix(".csv"))
    assert list(drawn.columns) == ["t_s", "n", "mean", "low", "high"]
    assert drawn["t_s"].tolist() == [0.0, 1.0, 2.0, 3.0] and (drawn["n"] == 3).all()
    # seeds 1, 2, 3 at t = 2 s: coverage 0.3, 0.6, 0.9
    assert drawn.loc[2, "mean"] == pytest.approx(0.6)
    assert 0.3 <= drawn.loc[2, "low"] <= 0.6 <= drawn.loc[2, "high"] <= 0.9
    assert (drawn["high"] <= 1.0).all() and (drawn["low"] >= 0.0).all()
