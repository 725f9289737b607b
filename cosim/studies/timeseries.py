"""Study figures over simulated time, from a table every run kept (``[report] timeseries``).

A study that keeps a table per run (``tables = ["map_quality"]``) can ask for a metric of
it over time: ``timeseries = [{table = "map_quality", y = "iou", where = {robot = "fleet"}}]``.
For each value of the report's ``x`` a figure shows, per ``facet`` a panel and per ``hue``
a line, the mean over seeds of ``y`` against ``t_s`` with its 95 % Student t band.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from scipy import stats as scipy_stats

from cosim.core.errors import ExportError
from cosim.studies.analysis import FIGURES_DIR, load_results

PANELS_PER_ROW = 3
DPI = 150


def _label(value: Any) -> str:
    return f"{value:g}" if isinstance(value, float) else str(value)


def series_frame(
    study_dir: Path, table: str, y: str, where: Mapping[str, Any], keys: Sequence[str]
) -> pd.DataFrame:
    """Rows ``t_s``, ``y`` and the run's ``keys`` (x, hue, facet) of every ok run's table."""
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
        suffix = f"_at_{x}={_label(x_value)}" if x else ""
        target = Path(study_dir) / FIGURES_DIR / f"{y}_over_time{suffix}.png"
        title = f"{table}.{y} over time" + (f", {x} = {_label(x_value)}" if x else "")
        if where:
            title += " (" + ", ".join(f"{k} = {v}" for k, v in where.items()) + ")"
        written.append(_draw(part, y, hue, facet, title, target))
    return written


def _draw(
    data: pd.DataFrame, y: str, hue: str | None, facet: str | None, title: str, target: Path
) -> Path:
    facets = list(pd.unique(data[facet])) if facet else [None]
    rows = (len(facets) + PANELS_PER_ROW - 1) // PANELS_PER_ROW
    cols = min(len(facets), PANELS_PER_ROW)
    figure = Figure(figsize=(4.6 * cols + 1.6, 3.6 * rows + 0.6), layout="constrained")
    axes = figure.subplots(rows, cols, sharey=True, squeeze=False).ravel()
    for ax in axes[len(facets) :]:
        ax.remove()
    hues = list(pd.unique(data[hue])) if hue else [None]
    for ax, facet_value in zip(axes, facets, strict=False):
        panel = data[data[facet] == facet_value] if facet else data
        for i, hue_value in enumerate(hues):
            lines = panel[panel[hue] == hue_value] if hue else panel
            if lines.empty:
                continue
            grouped = lines.groupby("t_s")[y]
            mean, std, n = grouped.mean(), grouped.std(), grouped.count()
            half = scipy_stats.t.ppf(0.975, np.maximum(n - 1, 1)) * std / np.sqrt(n)
            half = half.where(n >= 2, 0.0).fillna(0.0)
            t = mean.index.to_numpy(float)
            color = f"C{i % 10}"
            ax.plot(t, mean.to_numpy(float), color=color, label=_label(hue_value) if hue else None)
            ax.fill_between(t, mean - half, mean + half, color=color, alpha=0.2, linewidth=0)
        if facet:
            ax.set_title(f"{facet} = {_label(facet_value)}", fontsize=10)
        ax.grid(True, alpha=0.3)
        ax.set_xlabel("time (s)")
    for ax in axes[:: max(cols, 1)]:
        ax.set_ylabel(y)
    if hue:
        axes[min(len(facets), PANELS_PER_ROW) - 1].legend(
            title=hue, fontsize=8, loc="upper left", bbox_to_anchor=(1.02, 1.0)
        )
    figure.suptitle(title)
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        FigureCanvasAgg(figure)
        figure.savefig(target, dpi=DPI, bbox_inches="tight")
    except OSError as error:
        raise ExportError(f"{target}: cannot write: {error.strerror or error}") from None
    return target
