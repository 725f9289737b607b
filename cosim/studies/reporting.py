"""Figures and report.md of a study, from its ``[report]`` section."""

from __future__ import annotations

import sys
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from matplotlib.ticker import NullLocator

from cosim.core.errors import ConfigError
from cosim.studies.analysis import (
    FIGURES_DIR,
    RESULTS_FILE,
    heatmap,
    load_results,
    metric_figure_data,
    save_figure,
    standard_figures,
    write_report,
)
from cosim.studies.derived import DERIVED_METRICS
from cosim.studies.labels import axis_label, short_label
from cosim.studies.spec import StudySpec
from cosim.studies.timeseries import timeseries_figures
from cosim.studies.unset import fill_unset
from cosim.studies.writing import write_results

DEFAULT_METRICS = (
    "tasks_per_min",
    "mean_convergence_time_s",
    "optimality_gap",
    "conflicts",
    "messages_sent",
    "collisions",
)
MAX_X_TICKS = 12
"""Log-log figures label up to this many x values themselves, beyond it powers of ten."""


def report_study(
    spec: StudySpec, out: Path, *, notify: Callable[[str], None] | None = None
) -> Path:
    """Write ``figures/*.png`` and ``report.md`` for a finished (or partial) study.

    Runs that do not set a key the report groups by (x, hue, facet) are grouped under the
    value their scenario used (:func:`~cosim.studies.unset.fill_unset`); runs still left
    out are named in ``report.md`` and told to ``notify`` (default: stderr), a line each.

    Derived metrics the report names (:data:`~cosim.studies.derived.DERIVED_METRICS`) are added to
    ``results.parquet`` as columns first, so the tables, the figures and later analysis of
    the folder all see them. Metrics in ``loglog`` get a table and a log-log figure
    ``<metric>_vs_<x>_loglog.png``; a linear one only if ``metrics`` names them too.

    Raises:
        ExportError: the results cannot be read or a figure or the report cannot be written.
        ConfigError: a report column is not in the results, or a log-log x is not numeric.
    """
    report = spec.report
    varied = spec.varied_keys()
    x = report.get("x", varied[0] if varied else None)
    hue = report.get("hue")
    facet = report.get("facet")
    metrics = list(report.get("metrics", DEFAULT_METRICS))
    loglog = list(report.get("loglog", []))
    heatmaps = list(report.get("heatmaps", []))
    left_out = fill_unset(out, [x, hue, facet])
    for line in left_out:
        (notify or _warn)(line)
    derived = add_derived_metrics(out, [*metrics, *loglog, *heatmaps])
    figures = standard_figures(out, x=x, hue=hue, metrics=metrics, facet=facet)
    if heatmaps and x is not None and facet is not None:
        results = load_results(out)
        ok = results[results["status"] == "ok"]
        for metric in heatmaps:
            if metric in ok.columns and ok[metric].notna().any():
                target = out / FIGURES_DIR / f"{metric}_over_{x}_and_{facet}.png"
                figures.append(heatmap(ok, x=x, y=facet, metric=metric, facet=hue, out=target))
    notes = [*left_out, *(f"`{name}`: {DERIVED_METRICS[name].formula}." for name in derived)]
    if loglog and x is not None:
        drawn, left_out = loglog_figures(out, x=x, metrics=loglog, hue=hue, facet=facet)
        figures += drawn
        notes += left_out
    for entry in report.get("timeseries", []):
        figures += timeseries_figures(out, entry, x=x, hue=hue, facet=facet)
    description = "\n\n".join(part for part in (spec.description.strip(), *notes) if part)
    return write_report(
        out,
        name=spec.name,
        x=x,
        hue=hue,
        metrics=list(dict.fromkeys([*metrics, *loglog])),
        description=description,
        figures=figures,
        facet=facet,
    )


def _warn(line: str) -> None:
    sys.stderr.write(f"study: {line}\n")
    sys.stderr.flush()


def add_derived_metrics(study_dir: Path, names: Sequence[str]) -> list[str]:
    """Add to ``results.parquet`` the derived metrics among ``names`` whose inputs it has.

    Returns:
        The derived metrics added (recomputed if already there), in the order named.

    Raises:
        ExportError: the results cannot be read or written.
    """
    results = load_results(study_dir)
    added = []
    for name in dict.fromkeys(names):
        metric = DERIVED_METRICS.get(name)
        if metric is not None and all(c in results.columns for c in metric.inputs):
            results[name] = metric.compute(results)
            added.append(name)
    if added:
        write_results(results, Path(study_dir) / RESULTS_FILE)
    return added


def loglog_figures(
    study_dir: Path,
    *,
    x: str,
    metrics: Sequence[str],
    hue: str | None = None,
    facet: str | None = None,
) -> tuple[list[Path], list[str]]:
    """Plot each metric against ``x`` on log-log axes to ``figures/<metric>_vs_<x>_loglog.png``.

    Means over seeds with their 95 % bootstrap bands, as
    :func:`cosim.studies.analysis.plot_metric` draws them, and what is drawn in
    ``<figure>.csv``; runs whose ``x`` or metric is not > 0 are left out. A metric no ok run
    reports is skipped (the report's tables say why).

    Returns:
        The figures written, and a note for the report per metric with runs left out.

    Raises:
        ConfigError: ``x`` (or ``hue``, ``facet``) is not a column of the results, or
            ``x`` holds values that are not numbers.
        ExportError: the results cannot be read or a figure cannot be written.
    """
    results = load_results(study_dir)
    ok = results[results["status"] == "ok"]
    for column in (x, hue, facet):
        if column is not None and column not in ok.columns:
            raise ConfigError(f"[report] loglog: the results have no column {column!r}")
    if pd.api.types.is_bool_dtype(ok[x]) or not pd.api.types.is_numeric_dtype(ok[x]):
        raise ConfigError(
            f"[report] loglog: x = {x!r} holds {ok[x].dtype} values; expected numbers > 0"
        )
    paths, notes = [], []
    for metric in metrics:
        if metric not in ok.columns:
            continue
        values = pd.to_numeric(ok[metric], errors="coerce")
        usable = values.notna() & (values > 0) & (ok[x] > 0)
        if dropped := int((values.notna() & ~usable).sum()):
            notes.append(
                f"`{metric}` on log-log axes: {dropped} of {int(values.notna().sum())} "
                f"runs left out (`{x}` or `{metric}` not > 0)."
            )
        if not usable.any():
            continue
        figure, drawn = loglog_figure_data(ok[usable], x, metric, hue=hue, facet=facet)
        target = Path(study_dir) / FIGURES_DIR / f"{metric}_vs_{x}_loglog.png"
        paths.append(save_figure(figure, target, data=drawn))
    return paths, notes


def loglog_figure(
    results: pd.DataFrame,
    x: str,
    metric: str,
    *,
    hue: str | None = None,
    facet: str | None = None,
) -> Figure:
    """The figure of :func:`cosim.studies.analysis.metric_figure` on log-log axes (values > 0)."""
    return loglog_figure_data(results, x, metric, hue=hue, facet=facet)[0]


def loglog_figure_data(
    results: pd.DataFrame,
    x: str,
    metric: str,
    *,
    hue: str | None = None,
    facet: str | None = None,
) -> tuple[Figure, pd.DataFrame]:
    """:func:`loglog_figure` and what it draws (group columns, n, mean, low, high)."""
    title = f"{axis_label(metric)} vs {short_label(x)} (log-log)"
    figure, drawn = metric_figure_data(results, x, metric, hue=hue, facet=facet, title=title)
    levels = np.unique(results[x].to_numpy(dtype=float))
    for ax in figure.axes:
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.grid(True, which="minor", axis="y", alpha=0.15)
        if len(levels) <= MAX_X_TICKS:  # the studied values themselves, not powers of ten
            ax.set_xticks(levels, [f"{v:g}" for v in levels])
            ax.xaxis.set_minor_locator(NullLocator())
    return figure, drawn
