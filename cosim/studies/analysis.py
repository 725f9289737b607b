"""A study's results (DESIGN.md, "A study's folder"): statistics over seeds, figures, report.

Only ok runs are analysed. Figures are matplotlib ``Figure`` objects rendered on the Agg
canvas, never through pyplot and its global state.
"""

from __future__ import annotations

import difflib
import os
from collections.abc import Iterable, Sequence
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.colors import Normalize
from matplotlib.figure import Figure

from cosim.core.errors import ConfigError, ExportError
from cosim.studies.intervals import POINTS_UP_TO, band_caption, bootstrap_interval, y_limits
from cosim.studies.labels import axis_label, short_label
from cosim.studies.panels import PANELS_PER_ROW
from cosim.studies.panels import caption as _caption
from cosim.studies.panels import label_axes as _label_axes
from cosim.studies.panels import levels as _levels
from cosim.studies.panels import panels as _panels
from cosim.studies.panels import save_figure as save_figure
from cosim.studies.panels import value_label as _label

RESULTS_FILE = "results.parquet"
REPORT_FILE = "report.md"
FIGURES_DIR = "figures"
ERRORS_LISTED = 5  # failed runs quoted in a report; the others are only counted
MARKERS = "osD^v<>pPXh*"
_BAND = ("mean", "ci_low", "ci_high")
DRAWN = ("n", "mean", "low", "high")
"""Columns of the ``<figure>.csv`` beside each figure, after the group columns."""
INTERVAL_NOTE = (
    "Each cell: mean over the ok runs and, in brackets, the 95 % percentile bootstrap interval "
    "of the mean (2,000 resamples of the runs, seeded), which stays within the runs' range; "
    "the figures draw the same interval."
)


def load_results(study_dir: str | Path) -> pd.DataFrame:
    """Read a study's ``results.parquet``, a row per run (failed runs included).

    Columns: ``run_id``, ``seed``, one per override (by dotted key), the metrics (flat names
    carrying the units), ``status`` (``"ok"`` | ``"error"``), ``error``.

    Raises:
        ExportError: naming the path if the file is missing or unreadable, or lacks the
            ``run_id``, ``seed`` or ``status`` column.
    """
    path = Path(study_dir) / RESULTS_FILE
    try:
        frame = pd.read_parquet(path)
    except FileNotFoundError:
        raise ExportError(f"{path}: no such file; is {path.parent} a study's folder?") from None
    except (OSError, ValueError) as error:  # pyarrow's ArrowInvalid is a ValueError
        raise ExportError(f"{path}: cannot read the results of a study: {error}") from None
    if missing := [c for c in ("run_id", "seed", "status") if c not in frame.columns]:
        raise ExportError(f"{path}: not a study's results, no column {', '.join(missing)}")
    return frame


def aggregate(
    results: pd.DataFrame, by: Sequence[str], metrics: Sequence[str], *, confidence: float = 0.95
) -> pd.DataFrame:
    """Mean, standard deviation and bootstrap ``confidence`` interval of metrics per group.

    The interval is :func:`cosim.studies.intervals.bootstrap_interval` (percentile bootstrap
    of the mean, seeded): it never leaves the range of the group's runs. Only ok runs count;
    NaN values are dropped per metric; booleans count as 0/1.

    Returns:
        A row per group (one for ``by=[]``), ordered by each ``by`` column in turn (numbers
        ascending, others as they appear): ``by``, then ``{m}_mean``, ``{m}_std``, ``{m}_n``,
        ``{m}_ci_low``, ``{m}_ci_high`` per metric ``m``, in its unit; n=1 or equal values: no
        width (n=1: std NaN).

    Raises:
        ConfigError: a missing column, a non-numeric metric, or ``confidence`` not in (0, 1).
    """
    if not 0.0 < confidence < 1.0:
        raise ConfigError(f"confidence {confidence!r}: expected a level strictly in (0, 1)")
    keys, names = list(by), list(metrics)
    _require(results, ["status", *keys, *names])
    ok = results[results["status"] == "ok"]
    data = pd.DataFrame({m: _numeric(ok[m], m) for m in names}, index=ok.index)
    group_keys = [_ordered(ok[k]) for k in keys] if keys else np.zeros(len(data), dtype=int)
    grouped = data.groupby(group_keys, sort=True, dropna=False, observed=True)
    mean, std, count = grouped.mean(), grouped.std(), grouped.count()
    out = pd.DataFrame(index=mean.index)
    for m in names:
        band = grouped[m].apply(lambda s: bootstrap_interval(s, confidence=confidence))
        band = band.reindex(mean.index)
        out[f"{m}_mean"], out[f"{m}_std"], out[f"{m}_n"] = mean[m], std[m], count[m].astype(int)
        out[f"{m}_ci_low"] = [b[0] if isinstance(b, tuple) else np.nan for b in band]
        out[f"{m}_ci_high"] = [b[1] if isinstance(b, tuple) else np.nan for b in band]
    out = out.reset_index(drop=not keys)
    for k in keys:  # back from the ordered categories of _ordered
        out[k] = out[k].astype(ok[k].dtype)
    return out


def metric_figure(
    results: pd.DataFrame,
    x: str,
    metric: str,
    *,
    hue: str | None = None,
    facet: str | None = None,
    title: str | None = None,
    confidence: float = 0.95,
    logx: bool = False,
) -> Figure:
    """The figure of :func:`plot_metric`, unsaved (to inspect its axes)."""
    return metric_figure_data(
        results, x, metric, hue=hue, facet=facet, title=title, confidence=confidence, logx=logx
    )[0]


def metric_figure_data(
    results: pd.DataFrame,
    x: str,
    metric: str,
    *,
    hue: str | None = None,
    facet: str | None = None,
    title: str | None = None,
    confidence: float = 0.95,
    logx: bool = False,
) -> tuple[Figure, pd.DataFrame]:
    """The figure of :func:`plot_metric` and what it draws (group columns, n, mean, low, high).

    Each group's mean with its bootstrap band (:func:`aggregate`); when no group has more
    than :data:`~cosim.studies.intervals.POINTS_UP_TO` runs, each run's value as a small dot.
    """
    stats, ok = _plot_stats(results, [facet, hue, x], metric, confidence)
    numeric_x = pd.api.types.is_numeric_dtype(ok[x]) and not pd.api.types.is_bool_dtype(ok[x])
    if logx and not numeric_x:
        raise ConfigError(f"logx: x column {x!r} holds {ok[x].dtype} values, expected numbers")
    x_levels, hues = _levels(ok[x]), _levels(ok[hue]) if hue else [None]
    facets, figure, axes = _panels(stats, facet, width_in=4.8)
    runs = ok.assign(_value=pd.to_numeric(ok[metric], errors="coerce")).dropna(subset=["_value"])
    dots = int(stats[f"{metric}_n"].max()) <= POINTS_UP_TO
    drawn: list[np.ndarray] = []
    for ax, facet_value in zip(axes, facets, strict=True):
        panel = _where(stats, facet, facet_value)
        for i, hue_value in enumerate(hues):
            if (rows := _where(panel, hue, hue_value)).empty:
                continue
            mean, low, high = (rows[f"{metric}_{s}"].to_numpy(float) for s in _BAND)
            color, marker = f"C{i % 10}", MARKERS[i % len(MARKERS)]
            label = _label(hue_value) if hue else None
            points = _where(_where(runs, facet, facet_value), hue, hue_value)
            drawn += [mean, low, high, points["_value"].to_numpy(float)]
            offset = 0.5 * ((i + 0.5) / len(hues) - 0.5)
            if numeric_x:
                xs, run_xs = rows[x].to_numpy(float), points[x].to_numpy(float)
                ax.plot(xs, mean, color=color, marker=marker, label=label)
                ax.fill_between(xs, low, high, color=color, alpha=0.2, linewidth=0)
            else:  # no order to draw a line along: points, hue values side by side
                xs = _positions(x_levels, rows[x]) + offset
                run_xs = _positions(x_levels, points[x]) + offset
                yerr = np.vstack([mean - low, high - mean])
                ax.errorbar(xs, mean, yerr, color=color, marker=marker, ls="none", label=label)
            if dots:
                ax.scatter(run_xs, points["_value"], s=9, color=color, alpha=0.45, linewidths=0)
        if not numeric_x:
            ax.set_xticks(range(len(x_levels)), [_label(v) for v in x_levels])
            ax.set_xlim(-0.5, len(x_levels) - 0.5)
        elif logx:  # symlog: linear up to the smallest positive x (0 can stay), log beyond
            positive = ok[x][ok[x] > 0]
            ax.set_xscale("symlog", linthresh=float(positive.min()) if len(positive) else 1.0)
        ax.grid(True, alpha=0.3)
    if (limits := y_limits(np.concatenate(drawn))) is not None:
        axes[0].set_ylim(*limits)  # shared by every panel
        for artist in (a for ax in axes for a in (*ax.lines, *ax.collections)):
            artist.set_clip_on(False)  # a flat line on the axis stays whole
    _label_axes(axes, x, metric)
    if hue:  # beside the first row, where it covers no data
        axes[min(len(axes), PANELS_PER_ROW) - 1].legend(
            title=short_label(hue), fontsize=8, loc="upper left", bbox_to_anchor=(1.02, 1.0)
        )
    title = title or f"{axis_label(metric)} vs {short_label(x)}"
    _caption(figure, title, band_caption(stats[f"{metric}_n"].to_numpy(int)))
    return figure, _drawn(stats, [facet, hue, x], metric)


def _drawn(stats: pd.DataFrame, columns: Iterable[str | None], metric: str) -> pd.DataFrame:
    """The group columns and n, mean, low, high of ``metric``: a figure's ``.csv``."""
    keys = list(dict.fromkeys(c for c in columns if c is not None))
    names = ("n", *_BAND)
    table = stats[[*keys, *(f"{metric}_{s}" for s in names)]]
    return table.set_axis([*keys, *DRAWN], axis=1).reset_index(drop=True)


def plot_metric(
    results: pd.DataFrame,
    *,
    x: str,
    metric: str,
    hue: str | None = None,
    facet: str | None = None,
    out: Path,
    title: str | None = None,
    confidence: float = 0.95,
    logx: bool = False,
) -> Path:
    """Plot to ``out`` (PNG) the mean over ok runs of ``metric`` vs ``x``, a series per ``hue``.

    Numeric ``x``: lines with markers and shaded ``confidence`` bands (``logx``: symlog).
    Other ``x``: categories in order of appearance, points with error bars. A series is one
    ``Line2D``; ``facet`` gives a subplot per value; axes are labelled in words and units
    (:func:`cosim.studies.labels.axis_label`). What is drawn goes to ``out`` with ``.csv``.

    Raises:
        ConfigError: a column is missing, or ``logx`` with a categorical ``x``.
        ExportError: no ok run has a value of ``metric``, or ``out`` cannot be written.
    """
    figure, drawn = metric_figure_data(
        results, x, metric, hue=hue, facet=facet, title=title, confidence=confidence, logx=logx
    )
    return save_figure(figure, Path(out), data=drawn)


def heatmap(
    results: pd.DataFrame,
    *,
    x: str,
    y: str,
    metric: str,
    facet: str | None = None,
    out: Path,
    title: str | None = None,
) -> Path:
    """Plot to ``out`` (PNG) the mean over ok runs of ``metric`` on an ``x`` by ``y`` grid.

    Numbers ascending, each cell annotated; facets share one colour scale. What is drawn, with
    the bootstrap interval of each cell, goes to ``out`` with ``.csv``. Errors as for
    :func:`plot_metric`.
    """
    stats, ok = _plot_stats(results, [facet, y, x], metric, 0.95)
    x_levels, y_levels = _levels(ok[x]), _levels(ok[y])
    facets, figure, axes = _panels(stats, facet, width_in=max(4.0, 0.8 * len(x_levels) + 2))
    means = stats[f"{metric}_mean"].to_numpy(float)
    norm = Normalize(vmin=float(means.min()), vmax=float(means.max()))
    for ax, facet_value in zip(axes, facets, strict=True):
        panel = _where(stats, facet, facet_value)
        grid = np.full((len(y_levels), len(x_levels)), np.nan)
        cells = (_positions(y_levels, panel[y]), _positions(x_levels, panel[x]))
        grid[cells] = panel[f"{metric}_mean"].to_numpy(float)
        image = ax.imshow(grid, origin="lower", aspect="auto", cmap="viridis", norm=norm)
        for (i, j), value in np.ndenumerate(grid):
            if np.isfinite(value):
                color = "white" if norm(value) < 0.5 else "black"  # viridis is dark below
                ax.text(j, i, f"{value:.3g}", ha="center", va="center", fontsize=8, color=color)
        ax.set_xticks(range(len(x_levels)), [_label(v) for v in x_levels])
        ax.set_yticks(range(len(y_levels)), [_label(v) for v in y_levels])
    _label_axes(axes, x, y)
    figure.colorbar(image, ax=axes, label=f"{axis_label(metric)}, mean")
    n = stats[f"{metric}_n"].to_numpy(int)
    note = f"cells: mean of n = {n.min()}" + (f"-{n.max()}" if n.max() > n.min() else "")
    title = title or f"{axis_label(metric)} over {short_label(x)} and {short_label(y)}"
    _caption(figure, title, note + " seeds; 95 % bootstrap intervals in the .csv")
    return save_figure(figure, Path(out), data=_drawn(stats, [facet, y, x], metric))


def markdown_table(frame: pd.DataFrame, floatfmt: str = ".3g") -> str:
    """A frame as a markdown table; the index is shown unless it is a plain range."""
    return frame.to_markdown(index=not isinstance(frame.index, pd.RangeIndex), floatfmt=floatfmt)


def standard_figures(
    study_dir: Path,
    *,
    x: str | None,
    hue: str | None,
    metrics: Sequence[str],
    facet: str | None = None,
) -> list[Path]:
    """Plot each usable metric to ``DIR/figures/<metric>_vs_<x>.png``; return the paths.

    Without ``x``: a point per ``hue`` value, ``<metric>_by_<hue>.png`` (none without ``hue``).

    Raises:
        ExportError: the results cannot be read or a figure cannot be written.
        ConfigError: ``x``, ``hue`` or ``facet`` is not a column of the results.
    """
    results = load_results(study_dir)
    _require(results, [x, hue, facet])
    ok, folder = results[results["status"] == "ok"], Path(study_dir) / FIGURES_DIR
    if (along := x or hue) is None:
        return []
    outs = {m: folder / f"{m}_{'vs' if x else 'by'}_{along}.png" for m in metrics}
    series = hue if x else None
    return [
        plot_metric(ok, x=along, metric=m, hue=series, facet=facet, out=out)
        for m, out in outs.items()
        if _metric_problem(ok, m) is None
    ]


FAULT_WORDS = {
    "plugin": "a plugin's fault",
    "cosim": "cosim's own bug",
    "external": "an external system",
    "input": "bad input",
}
"""How report.md says whose fault a failed run was (``failure_kind``)."""


def write_report(
    study_dir: Path,
    *,
    name: str,
    x: str | None,
    hue: str | None,
    metrics: Sequence[str],
    description: str = "",
    figures: Sequence[Path] = (),
    facet: str | None = None,
) -> Path:
    """Write ``DIR/report.md`` for the study ``name`` and return its path.

    Run counts, failed runs, per metric a table by (``facet``, ``hue``, ``x``) of the mean and
    its 95 % bootstrap interval (as the figures draw it), ``figures`` links (relative paths:
    to ``DIR``), notes on skipped metrics and on parameters pooled over.

    Raises:
        ExportError: the results cannot be read or the report cannot be written.
        ConfigError: ``x`` or ``hue`` is not a column of the results.
    """
    study_dir = Path(study_dir)
    results = load_results(study_dir)
    by = list(dict.fromkeys(c for c in (facet, hue, x) if c is not None))
    _require(results, by)
    ok, failed = results[results["status"] == "ok"], results[results["status"] != "ok"]
    lines = [f"# {name}", ""] + ([description.strip(), ""] if description.strip() else [])
    seeds = results["seed"].nunique()
    over = f"{seeds} seed" + ("s" if seeds != 1 else "")
    lines += ["## Runs", "", f"{len(ok)} ok, {len(failed)} failed, over {over}.", ""]
    if len(failed):
        lines += ["### Failed runs", ""]
        for run in failed.head(ERRORS_LISTED).itertuples(index=False):
            message = (str(getattr(run, "error", "")).strip() or "no message").splitlines()[0]
            kind = getattr(run, "failure_kind", "")
            whose = f", {FAULT_WORDS.get(kind, kind)}" if isinstance(kind, str) and kind else ""
            failure_path = Path("runs") / str(run.run_id) / "failure.txt"
            trace = (
                f" ([traceback]({failure_path.as_posix()}))"
                if (study_dir / failure_path).is_file()
                else ""
            )
            lines.append(f"- `{run.run_id}` (seed {run.seed}{whose}): {message[:300]}{trace}")
        lines += [f"- … and {len(failed) - ERRORS_LISTED} more"] * (len(failed) > ERRORS_LISTED)
        lines.append("")
    lines += ["## Results", ""]
    if ok.empty:
        lines += ["No run finished successfully: there is nothing to aggregate.", ""]
    else:
        lines += _tables(ok, by, metrics)
    lines += ["## Figures", ""] if figures else []
    for png in map(Path, figures):
        link = Path(os.path.relpath(png, study_dir))
        lines += [f"![{png.stem}]({link.as_posix()})", ""]
    path = study_dir / REPORT_FILE
    try:
        path.write_text("\n".join(lines), encoding="utf-8")
    except OSError as error:
        raise ExportError(f"{path}: cannot write: {error.strerror or error}") from None
    return path


def _tables(ok: pd.DataFrame, by: list[str], metrics: Sequence[str]) -> list[str]:
    lines = [INTERVAL_NOTE, ""]
    dotted = [str(c) for c in ok.columns if "." in str(c) and c not in by]
    if pooled := [f"`{c}`" for c in dotted if ok[c].nunique(dropna=False) > 1]:
        lines += [f"Runs are pooled over {', '.join(pooled)} (varied, not grouped by).", ""]
    skipped = []
    for metric in metrics:
        if (problem := _metric_problem(ok, metric)) is not None:
            skipped.append(f"- `{metric}`: {problem}, skipped.")
            continue
        stats = aggregate(ok, by, [metric])
        table, n = stats[by].copy(), stats[f"{metric}_n"].to_numpy(int)
        mean, low, high = (stats[f"{metric}_{s}"].to_numpy(float) for s in _BAND)
        cells = [f"{m:.3g} [{lo:.3g}, {h:.3g}]" for m, lo, h in zip(mean, low, high, strict=True)]
        table[metric] = np.where(n > 1, cells, np.where(n == 1, [f"{m:.3g}" for m in mean], "–"))
        table["n"] = n
        lines += [f"### {metric}", "", markdown_table(table), ""]
    return lines + (["### Skipped metrics", "", *skipped, ""] if skipped else [])


def _metric_problem(ok: pd.DataFrame, metric: str) -> str | None:
    if metric not in ok.columns:
        return "no such column in the results"
    try:
        values = _numeric(ok[metric], metric)
    except ConfigError:
        return f"not numeric ({ok[metric].dtype})"
    return None if values.notna().any() else "no value in any ok run"


def _plot_stats(
    results: pd.DataFrame, columns: Iterable[str | None], metric: str, confidence: float
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The groups to draw (with a value and every key) and the ok runs."""
    keys = list(dict.fromkeys(c for c in columns if c is not None))
    stats = aggregate(results, keys, [metric], confidence=confidence).dropna(subset=keys)
    if (stats := stats[stats[f"{metric}_n"] > 0]).empty:
        raise ExportError(f"nothing to plot: no ok run has a value of {metric!r}")
    return stats, results[results["status"] == "ok"]


def _require(frame: pd.DataFrame, columns: Iterable[str | None]) -> None:
    known = [str(c) for c in frame.columns]
    for column in columns:
        if column is not None and column not in known:
            close = difflib.get_close_matches(column, known, n=1)
            hint = f"did you mean {close[0]!r}?" if close else f"expected one of {known}"
            raise ConfigError(f"results have no column {column!r}: {hint}")


def _numeric(series: pd.Series, name: str) -> pd.Series:
    try:
        return pd.to_numeric(series, errors="raise").astype("float64")
    except (TypeError, ValueError):
        raise ConfigError(f"metric {name!r} holds {series.dtype} values, not numbers") from None


def _ordered(column: pd.Series) -> pd.Series:
    """A grouping key that sorts as :func:`_levels` orders the values of ``column``."""
    if pd.api.types.is_numeric_dtype(column):
        return column
    ordered = pd.Categorical(column, categories=_levels(column))
    return pd.Series(ordered, index=column.index, name=column.name)


def _positions(levels: list[object], values: pd.Series) -> np.ndarray:
    return pd.Index(levels).get_indexer(pd.Index(values))


def _where(frame: pd.DataFrame, column: str | None, value: object) -> pd.DataFrame:
    return frame if column is None else frame[frame[column] == value]
