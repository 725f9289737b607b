"""Study figures over simulated time, from a table every run kept (``[report] timeseries``).

A study that keeps a table per run (``tables = ["map_quality"]``) can ask for a metric of
it over time: ``timeseries = [{table = "map_quality", y = "iou", where = {robot = "fleet"}}]``.
For each value of the report's ``x`` a figure shows, per ``facet`` a panel and per ``hue``
a line, the mean over seeds of ``y`` against ``t_s`` with its 95 % bootstrap band
(:mod:`cosim.studies.intervals`), and beside each figure a ``.csv`` of the series drawn.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from cosim.core.errors import ExportError
from cosim.studies.analysis import DRAWN, FIGURES_DIR, load_results
from cosim.studies.intervals import band_caption, bootstrap_interval, y_limits
from cosim.studies.labels import short_label, with_unit
from cosim.studies.panels import (
    PANELS_PER_ROW,
    caption,
    label_axes,
    levels,
    panels,
    save_figure,
    value_label,
)


def series_frame(
    study_dir: Path, table: str, y: str, where: Mapping[str, Any], keys: Sequence[str]
) -> pd.DataFrame:
    """Rows ``t_s``, ``y``, ``run_id``, ``seed`` and the ``keys`` (x, hue, facet) of ok runs."""
    results = load_results(study_dir)
    ok = results[results["status"] == "ok"]
    frames = []
    for row in ok.to_dict("records"):
        path = Path(study_dir) / "runs" / str(row["run_id"]) / "tables" / f"{table}.parquet"
        if not path.is_file():
            continue
        frame = pd.read_parquet(path)
        if y not in frame.columns or "t_s" not in frame.columns:
            raise ExportError(f"{path}: no column {y!r} or t_s; expected the table to have both")
        for column, value in where.items():
            frame = frame[frame[column].astype(str) == str(value)]
        part = frame[["t_s", y]].copy()
        part["run_id"] = row["run_id"]
        part["seed"] = row["seed"]
        for key in keys:
            part[key] = row[key]
        frames.append(part)
    if not frames:
        raise ExportError(f"{study_dir}: no run kept tables/{table}.parquet")
    return pd.concat(frames, ignore_index=True)


def timeseries_figures(
    study_dir: Path,
    entry: Mapping[str, Any],
    *,
    x: str | None,
    hue: str | None,
    facet: str | None,
) -> list[Path]:
    """The figures of one ``[report] timeseries`` entry; their paths."""
    table, y = str(entry["table"]), str(entry["y"])
    where = dict(entry.get("where", {}))
    keys = [k for k in (x, hue, facet) if k is not None]
    data = series_frame(study_dir, table, y, where, keys)
    written = []
    for x_value in pd.unique(data[x]) if x else [None]:
        part = data[data[x] == x_value] if x else data
        suffix = f"_at_{x}={value_label(x_value)}" if x else ""
        target = Path(study_dir) / FIGURES_DIR / f"{y}_over_time{suffix}.png"
        title = f"{short_label(y)} over time" + (
            f", {with_unit(x, value_label(x_value))}" if x else ""
        )
        if where:
            title += " (" + ", ".join(f"{k} = {v}" for k, v in where.items()) + ")"
        written.append(_draw(part, y, hue, facet, title, target))
    return written


def series_band(lines: pd.DataFrame, y: str) -> pd.DataFrame:
    """Per ``t_s``: n, mean, and the 95 % bootstrap interval of the mean of ``y`` (NaN dropped)."""
    rows = []
    for t, values in lines.dropna(subset=[y]).groupby("t_s", sort=True)[y]:
        low, high = bootstrap_interval(values.to_numpy(float))
        rows.append({"t_s": t, "n": len(values), "mean": values.mean(), "low": low, "high": high})
    return pd.DataFrame(rows, columns=["t_s", *DRAWN])


def _draw(
    data: pd.DataFrame, y: str, hue: str | None, facet: str | None, title: str, target: Path
) -> Path:
    facets, figure, axes = panels(data, facet, width_in=4.8)
    hues = levels(data[hue]) if hue else [None]
    drawn = []
    for ax, facet_value in zip(axes, facets, strict=True):
        panel = data[data[facet] == facet_value] if facet else data
        for i, hue_value in enumerate(hues):
            lines = panel[panel[hue] == hue_value] if hue else panel
            if lines.empty:
                continue
            band = series_band(lines, y)
            t, color = band["t_s"].to_numpy(float), f"C{i % 10}"
            label = value_label(hue_value) if hue else None
            ax.plot(t, band["mean"].to_numpy(float), color=color, label=label)
            ax.fill_between(t, band["low"], band["high"], color=color, alpha=0.2, linewidth=0)
            keys = [k for k in (facet, hue) if k is not None]
            for key, value in zip((facet, hue), (facet_value, hue_value), strict=True):
                if key is not None:
                    band[key] = np.full(len(band), value, dtype=object)
            drawn.append(band[[*keys, "t_s", *DRAWN]])
        ax.grid(True, alpha=0.3)
    table = pd.concat(drawn, ignore_index=True)
    values = table[["mean", "low", "high"]].to_numpy(float)
    if (limits := y_limits(values)) is not None:
        axes[0].set_ylim(*limits)
    label_axes(axes, "t_s", y)
    if hue:
        axes[min(len(facets), PANELS_PER_ROW) - 1].legend(
            title=short_label(hue), fontsize=8, loc="upper left", bbox_to_anchor=(1.02, 1.0)
        )
    runs = data["run_id"].nunique()  # runs may differ in keys the figure does not split on
    one_each = len(data) == runs * data["t_s"].nunique()  # a value per run and time
    unit = "seeds" if one_each else f"values ({runs} runs)"
    note = band_caption(table["n"].to_numpy(int), unit=unit, dots=False)
    caption(figure, title, note)
    return save_figure(figure, target, data=table)
