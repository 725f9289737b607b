"""Study files: what to sweep, validated before anything runs.

```toml
[study]
name = "comm_sweep"
scenario = "warehouse-random"     # a preset, or a path relative to the study file
seeds = 10                        # a count (seeds 1..N) or a list
duration_s = 300                  # optional: overrides scenario.duration_s
tables = false                    # keep each run's tables: false, true, or a list of names
description = "..."               # optional, for the report

[grid]                            # every combination of these lists, for every seed
"network.latency_ms" = [0, 5, 20]

[overrides]                       # the same for every run
"network.loss_model" = "bernoulli"

[[cases]]                         # optional: explicit combinations, crossed with the grid
"network.loss_model" = "bernoulli"
"network.loss_prob" = 0.1

[report]                          # optional: figures and report.md
x = "network.latency_ms"
hue = "assignment.protocol"
facet = "network.loss_prob"
metrics = ["tasks_per_min", "optimality_gap"]
heatmaps = ["tasks_per_min"]       # optional: x by facet, a panel per hue value
loglog = ["wall_us_per_robot_s"]  # optional: also drawn on log-log axes (x values > 0)
```

Every combination is loaded as a scenario before the study starts, and its adapters check
the sections they need together (:func:`cosim.runner.assembly.check_scenario`), so a bad key or
value, or a combination that cannot run, in any of them is reported (file, key, value,
expectation) and nothing runs.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from cosim.core.errors import ConfigError
from cosim.core.registry import AdapterRegistry
from cosim.runner.assembly import adapter_names, check_scenario
from cosim.runner.execute import execute
from cosim.scenario import load_scenario
from cosim.scenario.fields import show_name, show_value, suggest
from cosim.scenario.loader import preset_names
from cosim.scenario.tomlfile import read_toml_file

SECTIONS = ("study", "grid", "overrides", "cases", "report")
STUDY_KEYS = ("name", "scenario", "seeds", "duration_s", "tables", "description")
REPORT_KEYS = ("x", "hue", "facet", "metrics", "heatmaps", "loglog", "timeseries")
TIMESERIES_KEYS = ("table", "y", "where")


@dataclass(frozen=True)
class RunSpec:
    """One run of a study.

    Attributes:
        run_id: stable name, unique in the study (combination index and seed).
        seed: the scenario seed.
        overrides: ``section.key`` -> value for this run (study overrides, case, grid point).
    """

    run_id: str
    seed: int
    overrides: dict[str, Any]


@dataclass(frozen=True)
class StudySpec:
    """A validated study.

    Attributes:
        path: the study file.
        name: study name.
        scenario: preset name or absolute path of the scenario file.
        seeds: the seeds.
        duration_s: overrides ``scenario.duration_s`` when set.
        tables: table names to keep per run (empty: none; ``("*",)``: all).
        grid: key -> values crossed.
        overrides: keys set in every run.
        cases: explicit combinations crossed with the grid.
        report: the ``[report]`` section (x, hue, facet, metrics, heatmaps, loglog,
            timeseries).
        description: free text for the report.
    """

    path: Path
    name: str
    scenario: str
    seeds: tuple[int, ...]
    duration_s: float | None
    tables: tuple[str, ...]
    grid: dict[str, list[Any]]
    overrides: dict[str, Any]
    cases: tuple[dict[str, Any], ...]
    report: dict[str, Any]
    description: str

    def combinations(self) -> list[dict[str, Any]]:
        """Every override combination, in a fixed order: cases outer, grid inner."""
        keys = list(self.grid)
        points = [
            dict(zip(keys, values, strict=True))
            for values in itertools.product(*(self.grid[k] for k in keys))
        ]
        cases = list(self.cases) or [{}]
        return [{**self.overrides, **case, **point} for case in cases for point in points]

    def runs(self) -> list[RunSpec]:
        """Every run: each combination for each seed."""
        out = []
        for k, combination in enumerate(self.combinations()):
            for seed in self.seeds:
                out.append(RunSpec(f"{k:04d}_s{seed}", seed, dict(combination)))
        return out

    def varied_keys(self) -> list[str]:
        """Override keys that differ between runs (grid and cases)."""
        keys = list(self.grid)
        for case in self.cases:
            keys.extend(k for k in case if k not in keys)
        return keys


def _fail(path: Path, where: str, message: str) -> ConfigError:
    return ConfigError(f"{path}: [{where}] {message}")


def _check_keys(path: Path, section: str, table: dict[str, Any], allowed: tuple[str, ...]) -> None:
    for key in table:
        if key not in allowed:
            raise _fail(path, section, f"unknown key {key!r}" + suggest(key, list(allowed)))


def _dotted(path: Path, section: str, table: Any) -> dict[str, Any]:
    if not isinstance(table, dict):
        raise _fail(path, section, f'= {table!r}: expected a table of "section.key" = value')
    for key in table:
        if key.count(".") != 1:
            raise _fail(
                path, section, f'key {key!r}: expected "section.key", e.g. "network.latency_ms"'
            )
    return dict(table)


def load_study(path: str | Path) -> StudySpec:
    """Read and validate a study file (every combination is checked as a scenario).

    Raises:
        ConfigError: naming the file, the section, the key, the value and what was expected.
    """
    path = Path(path)
    if not path.is_file():
        raise ConfigError(f"{path}: study file not found")
    raw = read_toml_file(path, "study file")
    for section in raw:
        if section not in SECTIONS:
            raise ConfigError(
                f"{path}: unknown section [{show_name(section)}]" + suggest(section, list(SECTIONS))
            )
    study = raw.get("study")
    if not isinstance(study, dict):
        raise ConfigError(f"{path}: missing [study] section (name, scenario, seeds)")
    _check_keys(path, "study", study, STUDY_KEYS)
    for key in ("name", "scenario"):
        if not isinstance(study.get(key), str) or not study[key]:
            raise _fail(path, "study", f"{key} = {study.get(key)!r}: expected a non-empty string")
    scenario = study["scenario"]
    if scenario not in preset_names():
        candidate = (path.parent / scenario).resolve()
        if not candidate.is_file():
            raise _fail(
                path,
                "study",
                f"scenario = {scenario!r}: expected a preset "
                f"({', '.join(preset_names())}) or a file next to the study",
            )
        scenario = str(candidate)
    seeds = _seeds(path, study.get("seeds", 1))
    duration = study.get("duration_s")
    if duration is not None and (
        isinstance(duration, bool) or not isinstance(duration, int | float) or duration <= 0
    ):
        raise _fail(path, "study", f"duration_s = {duration!r}: expected a number > 0")
    tables = _tables(path, study.get("tables", False))
    grid = _dotted(path, "grid", raw.get("grid", {}))
    for key, values in grid.items():
        if not isinstance(values, list) or not values:
            raise _fail(path, "grid", f"{key!r} = {values!r}: expected a non-empty list of values")
    overrides = _dotted(path, "overrides", raw.get("overrides", {}))
    cases_raw = raw.get("cases", [])
    if not isinstance(cases_raw, list):
        raise _fail(path, "cases", "expected [[cases]] tables")
    cases = tuple(_dotted(path, f"cases[{i}]", case) for i, case in enumerate(cases_raw))
    report = raw.get("report", {})
    if not isinstance(report, dict):
        raise _fail(path, "report", "expected a table")
    _check_keys(path, "report", report, REPORT_KEYS)
    _check_report(path, report, grid, overrides, cases)
    _check_timeseries(path, report.get("timeseries", []), tables)
    spec = StudySpec(
        path=path,
        name=study["name"],
        scenario=scenario,
        seeds=seeds,
        duration_s=float(duration) if duration is not None else None,
        tables=tables,
        grid=grid,
        overrides=overrides,
        cases=cases,
        report=report,
        description=str(study.get("description", "")),
    )
    _validate_combinations(spec)
    return spec


def _seeds(path: Path, value: Any) -> tuple[int, ...]:
    if isinstance(value, int) and not isinstance(value, bool):
        if value < 1:
            raise _fail(path, "study", f"seeds = {value}: expected a count >= 1 or a list")
        return tuple(range(1, value + 1))
    if (
        isinstance(value, list)
        and value
        and all(isinstance(s, int) and not isinstance(s, bool) and s >= 0 for s in value)
    ):
        if len(set(value)) != len(value):
            raise _fail(path, "study", f"seeds = {value}: expected distinct seeds")
        return tuple(value)
    raise _fail(path, "study", f"seeds = {value!r}: expected a count >= 1 or a list of seeds >= 0")


def _tables(path: Path, value: Any) -> tuple[str, ...]:
    if value is False:
        return ()
    if value is True:
        return ("*",)
    if isinstance(value, list) and all(isinstance(v, str) for v in value):
        return tuple(value)
    raise _fail(path, "study", f"tables = {value!r}: expected true, false or a list of table names")


def _check_report(
    path: Path,
    report: dict[str, Any],
    grid: dict[str, Any],
    overrides: dict[str, Any],
    cases: tuple[dict[str, Any], ...],
) -> None:
    """Column names are strings, and a dotted one is a key the study sets.

    Undotted names are summary metrics (or ``seed``), known only once runs finish; a metric
    no run reports is noted in the report rather than failing a finished study.
    """
    study_keys = {*grid, *overrides, *(k for case in cases for k in case)}
    for key in ("x", "hue", "facet"):
        if key not in report:
            continue
        value = report[key]
        if not isinstance(value, str) or not value:
            raise _fail(path, "report", f"{key} = {value!r}: expected a column name")
        if "." in value and value not in study_keys:
            raise _fail(
                path,
                "report",
                f"{key} = {value!r}: not a key this study sets (expected one of "
                f"{', '.join(sorted(study_keys)) or 'none'}, or a summary metric)",
            )
    for key in ("metrics", "heatmaps", "loglog"):
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


def _check_timeseries(path: Path, entries: Any, tables: tuple[str, ...]) -> None:
    """Each ``[report] timeseries`` entry names a kept table, a column and a filter."""
    if not isinstance(entries, list) or not all(isinstance(e, dict) for e in entries):
        raise _fail(path, "report", f"timeseries = {entries!r}: expected a list of tables")
    for i, entry in enumerate(entries):
        _check_keys(path, f"report.timeseries[{i}]", entry, TIMESERIES_KEYS)
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


def _validate_combinations(spec: StudySpec) -> None:
    """Load and check every combination: what it cannot run stops the study here.

    A bad key or value, or a combination an adapter refuses
    (:func:`cosim.runner.assembly.check_scenario`), is reported before any run.

    When the study keeps named tables, one scenario per distinct set of adapters is also run
    for a millisecond (adapters create some tables only when they finish), so a table no run
    would produce is reported now rather than by every run.
    """
    origin = f"{spec.path} [grid/overrides/cases]"
    registry = AdapterRegistry.from_entry_points()
    named = [t for t in spec.tables if t != "*"]
    checked: set[tuple[str, ...]] = set()
    have: set[str] = set()
    for combination in spec.combinations():
        overrides = dict(combination)
        if spec.duration_s is not None:
            overrides["scenario.duration_s"] = spec.duration_s
        scenario = load_scenario(spec.scenario, overrides, override_origin=origin)
        try:
            check_scenario(scenario, registry=registry)
        except ConfigError as error:
            shown = ", ".join(f"{k} = {show_value(v)}" for k, v in combination.items())
            raise ConfigError(f"{origin} ({shown}): {error}") from None
        if named and (names := tuple(adapter_names(scenario))) not in checked:
            checked.add(names)
            have |= set(execute(scenario.with_duration(0.001)).tables)
    # a table some runs have is kept where it exists (a grid with and without people)
    if missing := [t for t in named if t not in have]:
        raise _fail(
            spec.path,
            "study",
            f"tables = {list(spec.tables)!r}: no run of this study has "
            f"{', '.join(map(repr, missing))} (expected some of "
            f"{', '.join(sorted(have))})",
        )
