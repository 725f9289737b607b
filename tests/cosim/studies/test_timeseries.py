"""Study figures over simulated time, from a table every run kept (``[report] timeseries``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from matplotlib.figure import Figure

from cosim.core.errors import ExportError
from cosim.studies import timeseries
from cosim.studies.timeseries import series_band, series_frame, timeseries_figures

X, HUE, FACET = "network.latency_ms", "assignment.protocol", "mapping.share"
T_S = np.arange(3.0)


def _iou(seed: int, latency: int, protocol: str) -> np.ndarray:
    """A run's fleet IoU at 0, 1 and 2 s."""
    return 0.1 * T_S + 0.01 * seed + (0.2 if protocol == "cbba" else 0.0) - 0.001 * latency


def _study(folder: Path, *, failed: str = "", without_table: str = "") -> Path:
    """Results of 2 latencies x 2 protocols x 2 share modes x 3 seeds, a map_quality table each.

    ``failed``: the run id given status error; ``without_table``: a run that kept no table.
    """
    rows = []
    for latency in (0, 100):
        for protocol in ("cbba", "simplex"):
            for share in ("none", "scans"):
                for seed in (1, 2, 3):
                    run_id = f"{latency}-{protocol}-{share}-{seed}"
                    status = "error" if run_id == failed else "ok"
                    rows.append({"run_id": run_id, "seed": seed, X: latency, HUE: protocol,
                                 FACET: share, "status": status})  # fmt: skip
                    if run_id == without_table:
                        continue
                    tables = folder / "runs" / run_id / "tables"
                    tables.mkdir(parents=True)
                    fleet = pd.DataFrame(
                        {"t_s": T_S, "robot": "fleet", "iou": _iou(seed, latency, protocol)}
                    )
                    robot = fleet.assign(robot="robot_1", iou=-1.0)  # left out by where
                    pd.concat([fleet, robot]).to_parquet(tables / "map_quality.parquet")
    pd.DataFrame(rows).to_parquet(folder / "results.parquet")
    return folder


@pytest.fixture
def drawn(monkeypatch: pytest.MonkeyPatch) -> list[Figure]:
    """The figures the time series draw (and still write)."""
    figures: list[Figure] = []
    original = timeseries.save_figure

    def keep(figure: Figure, path: Path, **kwargs: object) -> Path:
        figures.append(figure)
        return original(figure, path, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(timeseries, "save_figure", keep)
    return figures


ENTRY = {"table": "map_quality", "y": "iou", "where": {"robot": "fleet"}}


def test_the_series_are_every_ok_run_s_rows_that_match_with_the_run_s_keys(tmp_path):
    study = _study(tmp_path, failed="0-cbba-none-1", without_table="100-simplex-scans-3")
    frame = series_frame(study, "map_quality", "iou", {"robot": "fleet"}, [X, HUE])
    assert list(frame.columns) == ["t_s", "iou", "run_id", "seed", X, HUE]
    assert len(frame) == (24 - 2) * len(T_S)  # the failed run and the run without a table
    assert (frame["iou"] > -1).all()  # robot_1's rows filtered out
    cbba = frame[(frame[X] == 0) & (frame[HUE] == "cbba") & (frame["seed"] == 2)]
    assert len(cbba) == 2 * len(T_S)  # two share modes
    np.testing.assert_allclose(cbba["iou"].to_numpy()[:3], _iou(2, 0, "cbba"))


def test_no_table_kept_or_a_table_without_the_columns_is_an_export_error(tmp_path):
    study = _study(tmp_path)
    with pytest.raises(ExportError, match=r"no run kept tables/poses\.parquet$"):
        series_frame(study, "poses", "x_m", {}, [])
    with pytest.raises(ExportError, match=r"map_quality\.parquet: no column 'coverage' or t_s"):
        series_frame(study, "map_quality", "coverage", {}, [])


def test_the_band_is_the_mean_and_its_bootstrap_interval_at_each_time_nans_left_out():
    lines = pd.DataFrame(
        {"t_s": [0.0, 0.0, 0.0, 1.0, 1.0, 1.0], "iou": [0.1, 0.2, 0.3, 0.5, np.nan, 0.7]}
    )
    band = series_band(lines, "iou")
    assert list(band.columns) == ["t_s", "n", "mean", "low", "high"]
    assert band["t_s"].tolist() == [0.0, 1.0] and band["n"].tolist() == [3, 2]
    assert band["mean"].tolist() == pytest.approx([0.2, 0.6])
    assert (band["low"] <= band["mean"]).all() and (band["mean"] <= band["high"]).all()
    assert band.loc[0, "low"] >= 0.1 and band.loc[0, "high"] <= 0.3  # within the runs' range


def test_a_figure_per_x_value_named_after_it_with_a_line_per_hue_and_a_panel_per_facet(
    tmp_path, drawn
):
    study = _study(tmp_path)
    pngs = timeseries_figures(study, ENTRY, x=X, hue=HUE, facet=FACET)
    assert [p.name for p in pngs] == [f"iou_over_time_at_{X}={v}.png" for v in (0, 100)]
    assert all(p.parent == study / "figures" and p.is_file() for p in pngs)
    figure = drawn[0]
    assert figure.get_suptitle().startswith(
        "Map IoU over time, Network latency = 0 ms (robot = fleet)\nband: 95 % bootstrap "
        "interval of the mean, n = 3 seeds per point"
    )
    panels = [ax for ax in figure.axes if ax.get_title()]
    assert [ax.get_title() for ax in panels] == ["Map sharing = none", "Map sharing = scans"]
    for ax in panels:
        assert [line.get_label() for line in ax.get_lines()] == ["cbba", "simplex"]
        assert ax.get_xlabel() == "Simulated time (s)"
    assert panels[0].get_ylabel() == "Map IoU (vs ground truth)"
    legend = panels[-1].get_legend()
    assert legend is not None and legend.get_title().get_text() == "Assignment protocol"


def test_the_csv_beside_a_figure_holds_the_band_of_each_facet_and_hue(tmp_path):
    study = _study(tmp_path)
    png, _ = timeseries_figures(study, ENTRY, x=X, hue=HUE, facet=FACET)
    drawn = pd.read_csv(png.with_suffix(".csv"))
    assert list(drawn.columns) == [FACET, HUE, "t_s", "n", "mean", "low", "high"]
    assert len(drawn) == 2 * 2 * len(T_S) and (drawn["n"] == 3).all()
    cbba = drawn[(drawn[FACET] == "none") & (drawn[HUE] == "cbba")]
    # seeds 1, 2, 3: their mean adds 0.02 to the line
    np.testing.assert_allclose(cbba["mean"], 0.1 * T_S + 0.02 + 0.2)


def test_without_x_hue_or_facet_one_figure_draws_every_run_s_values_per_time(tmp_path, drawn):
    study = _study(tmp_path)
    (png,) = timeseries_figures(study, {"table": "map_quality", "y": "iou"}, x=None, hue=None,
                                facet=None)  # fmt: skip
    assert png.name == "iou_over_time.png"
    (ax,) = drawn[0].axes
    assert len(ax.get_lines()) == 1 and ax.get_legend() is None
    # no filter: a fleet and a robot_1 row per run and time, 48 values per time
    assert drawn[0].get_suptitle().endswith("n = 48 values (24 runs) per point")


def test_the_caption_counts_every_run_pooled_in_a_figure_not_only_distinct_seeds(tmp_path, drawn):
    # each latency's figure pools 12 runs: 2 protocols x 2 share modes x 3 seeds
    study = _study(tmp_path)
    timeseries_figures(study, {"table": "map_quality", "y": "iou"}, x=X, hue=None, facet=None)
    for figure in drawn:
        assert figure.get_suptitle().endswith("n = 24 values (12 runs) per point")
