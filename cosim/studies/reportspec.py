"""The ``[report]`` section of a study file: its shape, and the columns it names.

The shape (types, x/facet pairs, log-log x values) is checked from the file alone
(:func:`check_report`, :func:`check_timeseries`); the metric, table and column names against
what the study's runs produce (:func:`check_report_names`), found by a millisecond run per
distinct set of adapters (:mod:`cosim.studies.validate`), so a misspelt metric is refused
before any run instead of after the whole study.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from cosim.core.errors import ConfigError
from cosim.scenario.fields import suggest

REPORT_KEYS = ("x", "hue", "facet", "metrics", "heatmaps", "loglog", "timeseries")
TIMESERIES_KEYS = ("table", "y", "where")
COLUMN_KEYS = ("x", "hue", "facet")
METRIC_KEYS = ("metrics", "heatmaps", "loglog")
ROW_COLUMNS = ("run_id", "seed", "status", "error", "wall_time_s")
"""Columns every result row has besides the overrides and the summary metrics."""
NOT_IN_ROWS = ("scenario", "source")
"""Summary entries a result row leaves out (provenance, not metrics)."""
TIME_COLUMN = "t_s"


@dataclass(frozen=True)
class RunColumns:
    """What a study's results will hold, known before any run.

    Attributes:
        metrics: summary metrics some run reports (the rows' metric columns).
        derived: derived metrics the report may name (name -> the metrics they need).
        tables: table name -> its columns, for every table some run writes.
    """

    metrics: frozenset[str]
    derived: Mapping[str, tuple[str, ...]]
    tables: Mapping[str, frozenset[str]]


def _fail(path: Path, where: str, message: str) -> ConfigError:
    return ConfigError(f"{path}: [{where}] {message}")


def study_keys(
    grid: Mapping[str, Any], overrides: Mapping[str, Any], cases: tuple[dict[str, Any], ...]
) -> set[str]:
    """Every ``section.key`` the study sets (a column of its results)."""
    return {*grid, *overrides, *(k for case in cases for k in case)}


def check_report(
    path: Path,
    report: dict[str, Any],
    grid: dict[str, Any],
    overrides: dict[str, Any],
    cases: tuple[dict[str, Any], ...],
) -> None:
    """Column names are strings, and a dotted one is a key the study sets.

    Undotted names are summary metrics (or ``seed``): :func:`check_report_names` checks them
    against what the runs report.
    """
    keys = study_keys(grid, overrides, cases)
    for key in COLUMN_KEYS:
        if key not in report:
            continue
        value = report[key]
        if not isinstance(value, str) or not value:
            raise _fail(path, "report", f"{key} = {value!r}: expected a column name")
        if "." in value and value not in keys:
            raise _fail(
                path,
                "report",
                f"{key} = {value!r}: not a key this study sets (expected one of "
                f"{', '.join(sorted(keys)) or 'none'}, or a summary metric)",
            )
    for key in METRIC_KEYS:
        value = report.get(key, [])
        if not isinstance(value, list) or not all(isinstance(m, str) and m for m in value):
            raise _fail(path, "report", f"{key} = {value!r}: expected a list of metric names")
    if report.get("heatmaps") and not ("x" in report and "facet" in report):
        raise _fail(path, "report", "heatmaps need x and facet (the heatmap's columns and rows)")
    if report.get("loglog"):
        _check_loglog_x(path, report, grid, overrides, cases)


def _check_loglog_x(
    path: Path,
    report: dict[str, Any],
    grid: dict[str, Any],
    overrides: dict[str, Any],
    cases: tuple[dict[str, Any], ...],
) -> None:
    """Log-log figures need an x whose values the study sets to be numbers > 0.

    An undotted x is a summary metric, checked when the report is drawn.
    """
    loglog = report["loglog"]
    if "x" not in report:
        raise _fail(path, "report", f"loglog = {loglog!r}: needs x (the horizontal log axis)")
    x = report["x"]
    places = [("grid", v) for v in grid.get(x, [])]
    places += [("overrides", overrides[x])] if x in overrides else []
    places += [(f"cases[{i}]", case[x]) for i, case in enumerate(cases) if x in case]
    for where, value in places:
        if isinstance(value, bool) or not isinstance(value, int | float) or value <= 0:
            raise _fail(
                path,
                "report",
                f"loglog = {loglog!r}: x = {x!r} is {value!r} in [{where}]; "
                "expected numbers > 0 on a log axis",
            )


def check_timeseries(path: Path, entries: Any, tables: tuple[str, ...]) -> None:
    """Each ``[report] timeseries`` entry names a kept table, a column and a filter."""
    if not isinstance(entries, list) or not all(isinstance(e, dict) for e in entries):
        raise _fail(path, "report", f"timeseries = {entries!r}: expected a list of tables")
    for i, entry in enumerate(entries):
        for key in entry:
            if key not in TIMESERIES_KEYS:
                raise _fail(
                    path,
                    f"report.timeseries[{i}]",
                    f"unknown key {key!r}" + suggest(key, list(TIMESERIES_KEYS)),
                )
        table, y, where = entry.get("table"), entry.get("y"), entry.get("where", {})
        if not isinstance(table, str) or not isinstance(y, str) or not table or not y:
            raise _fail(
                path, f"report.timeseries[{i}]", f"table = {table!r}, y = {y!r}: expected names"
            )
        if "*" not in tables and table not in tables:
            raise _fail(
                path,
                f"report.timeseries[{i}]",
                f"table = {table!r}: expected one the study keeps ([study] tables = "
                f"{list(tables)!r})",
            )
        if not isinstance(where, dict) or not all(
            isinstance(v, str | int | float | bool) for v in where.values()
        ):
            raise _fail(
                path, f"report.timeseries[{i}]", f"where = {where!r}: expected column = value"
            )


def names_to_check(report: Mapping[str, Any]) -> bool:
    """Whether the report names metrics, undotted columns or time series to check."""
    undotted = any("." not in str(report.get(key, ".")) for key in COLUMN_KEYS)
    return undotted or any(report.get(key) for key in (*METRIC_KEYS, "timeseries"))


def check_report_names(
    path: Path, report: Mapping[str, Any], keys: set[str], columns: RunColumns
) -> None:
    """Every metric, column and table the report names is one the study's results hold.

    Args:
        path: the study file (for messages).
        report: the checked ``[report]`` section (:func:`check_report`).
        keys: the ``section.key`` columns the study sets.
        columns: what the runs produce.

    Raises:
        ConfigError: naming the report key, the unknown name and the names expected.
    """
    metrics = set(columns.metrics) - set(NOT_IN_ROWS)
    derived = {
        name for name, inputs in columns.derived.items() if set(inputs) <= {*metrics, *ROW_COLUMNS}
    }
    known = sorted({*metrics, *ROW_COLUMNS, *derived} - {"run_id", "status", "error"})
    for key in COLUMN_KEYS:
        value = report.get(key)
        if isinstance(value, str) and "." not in value and value not in known:
            raise _fail(
                path,
                "report",
                f"{key} = {value!r}: no run of this study reports it" + suggest(value, known),
            )
    for key in METRIC_KEYS:
        for name in report.get(key, []):
            if name not in known and name not in keys:
                raise _fail(
                    path,
                    "report",
                    f"{key} = {list(report[key])!r}: no run of this study reports {name!r}"
                    + suggest(name, known),
                )
    for i, entry in enumerate(report.get("timeseries", [])):
        _check_series_names(path, f"report.timeseries[{i}]", entry, columns.tables)


def _check_series_names(
    path: Path, where: str, entry: Mapping[str, Any], tables: Mapping[str, frozenset[str]]
) -> None:
    table, y = str(entry["table"]), str(entry["y"])
    if table not in tables:
        known = suggest(table, [*tables])
        raise _fail(path, where, f"table = {table!r}: no run of this study has it{known}")
    have = sorted(tables[table])
    if TIME_COLUMN not in have:
        raise _fail(
            path, where, f"table = {table!r}: has no {TIME_COLUMN} column to plot over time"
        )
    for name in (y, *entry.get("where", {})):
        if name not in have:
            raise _fail(path, where, f"{table} has no column {name!r}" + suggest(name, have))
