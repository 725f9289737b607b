"""Study files: what to sweep, validated before anything runs.

```toml
[study]
name = "comm_sweep"               # a folder name: letters, digits, '_', '-', '.', '+'
scenario = "warehouse-random"     # a preset, or a path relative to the study file
seeds = 10                        # a count (seeds 1..N) or a list (0 to 2**63 - 1)
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

The study decides each run's ``scenario.seed`` (from ``seeds``) and, with ``duration_s``,
its ``scenario.duration_s``: a grid, case or override of those keys would be recorded in the
results without being run, so it is refused. So are grids and cases over ``record`` keys
that study runs ignore (they write no bag; ``tables`` decides the tables kept).

``cosim study --set KEY=VALUE`` sets a key in every run, over ``[overrides]``
(:func:`with_sets`); a key the study varies or sets itself is refused, naming both.

Every combination is loaded as a scenario before the study starts, and its adapters check
the sections they need together (:func:`cosim.studies.validate.load_study` reads the file
with :func:`read_study`, then validates it), so a bad key or value, a combination that
cannot run, or a report metric no run reports is named (file, key, value, expectation) and
nothing runs.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from cosim.core.errors import ConfigError
from cosim.scenario.fields import show_name, show_value, suggest
from cosim.scenario.loader import preset_names
from cosim.scenario.names import NAME_RULE, name_problem
from cosim.scenario.tomlfile import read_toml_file
from cosim.studies.reportspec import REPORT_KEYS, check_report, check_timeseries

SECTIONS = ("study", "grid", "overrides", "cases", "report")
STUDY_KEYS = ("name", "scenario", "seeds", "duration_s", "tables", "description")
SEED_MAX = 2**63 - 1
"""Largest seed: results hold seeds as int64 (numpy's and Parquet's), and so do plans."""
MAX_RUNS = 1_000_000
"""Most runs a study may have (its plan is written out before the first run)."""
IGNORED_IN_STUDIES = ("record.bag", "record.topics", "record.compression", "record.tables")
"""Keys study runs ignore: they write no bag, and ``[study] tables`` picks the tables kept."""


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
        name: study name (one safe folder name).
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
        sets: ``cosim study --set`` overrides: set in every run, over ``overrides``
            (:func:`with_sets`).
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
    sets: dict[str, Any] = field(default_factory=dict)

    def combinations(self) -> list[dict[str, Any]]:
        """Every override combination, in a fixed order: cases outer, grid inner."""
        keys = list(self.grid)
        points = [
            dict(zip(keys, values, strict=True))
            for values in itertools.product(*(self.grid[k] for k in keys))
        ]
        cases = list(self.cases) or [{}]
        every = {**self.overrides, **self.sets}
        return [{**every, **case, **point} for case in cases for point in points]

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


def read_study(path: str | Path) -> StudySpec:
    """Read a study file and check its structure and values, without loading scenarios.

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
    name = _name(path, study["name"])
    scenario = _scenario(path, study["scenario"])
    seeds = _seeds(path, study.get("seeds", 1))
    duration = _duration(path, study.get("duration_s"))
    tables = _tables(path, study.get("tables", False))
    description = study.get("description", "")
    if not isinstance(description, str):
        raise _fail(path, "study", f"description = {description!r}: expected a string")
    grid = _dotted(path, "grid", raw.get("grid", {}))
    for key, values in grid.items():
        if not isinstance(values, list) or not values:
            raise _fail(path, "grid", f"{key!r} = {values!r}: expected a non-empty list of values")
    overrides = _dotted(path, "overrides", raw.get("overrides", {}))
    cases_raw = raw.get("cases", [])
    if not isinstance(cases_raw, list):
        raise _fail(path, "cases", "expected [[cases]] tables")
    cases = tuple(_dotted(path, f"cases[{i}]", case) for i, case in enumerate(cases_raw))
    _check_study_set(path, duration, [("grid", grid), ("overrides", overrides)], cases)
    _check_size(path, grid, cases, seeds)
    report = raw.get("report", {})
    if not isinstance(report, dict):
        raise _fail(path, "report", "expected a table")
    _check_keys(path, "report", report, REPORT_KEYS)
    check_report(path, report, grid, overrides, cases)
    check_timeseries(path, report.get("timeseries", []), tables)
    return StudySpec(
        path=path,
        name=name,
        scenario=scenario,
        seeds=seeds,
        duration_s=duration,
        tables=tables,
        grid=grid,
        overrides=overrides,
        cases=cases,
        report=report,
        description=description,
    )


def with_sets(spec: StudySpec, sets: Mapping[str, Any]) -> StudySpec:
    """The study with ``cosim study --set`` overrides set in every run (over ``[overrides]``).

    Args:
        spec: the study as read (:func:`read_study`).
        sets: ``section.key`` -> value, as :func:`~cosim.scenario.loader.parse_override`
            reads them.

    Raises:
        ConfigError: naming the study file and the ``--set``, for a key the study varies
            (``[grid]``, ``[[cases]]``) or sets itself (``scenario.seed``; with ``[study]
            duration_s``, ``scenario.duration_s``).
    """
    for key, value in sets.items():
        where = f"{spec.path}: --set {key} = {show_value(value)}"
        varied_in = ["grid"] if key in spec.grid else []
        varied_in += [f"cases[{i}]" for i, case in enumerate(spec.cases) if key in case]
        if varied_in:
            raise ConfigError(
                f"{where}: the study varies {key!r} in [{varied_in[0]}]; expected a key it "
                f"does not vary (drop it from --set, or from [{varied_in[0]}])"
            )
        if problem := _study_set_problem(key, spec.duration_s, varied=False):
            raise ConfigError(f"{where}: {problem}")
    return replace(spec, sets={**spec.sets, **sets})


def _name(path: Path, name: str) -> str:
    """The study's name becomes a folder name: one path component, nothing to escape with."""
    problem = name_problem(name)
    if problem is not None:
        raise _fail(
            path, "study", f"name = {name!r}: expected {NAME_RULE}, e.g. 'comm_sweep'; {problem}"
        )
    return name


def _scenario(path: Path, scenario: str) -> str:
    if scenario in preset_names():
        return scenario
    try:
        candidate = (path.parent / scenario).resolve()
        found = candidate.is_file()
    except (OSError, ValueError):  # a name too long, or with a NUL byte
        found = False
    if not found:
        raise _fail(
            path,
            "study",
            f"scenario = {scenario!r}: expected a preset "
            f"({', '.join(preset_names())}) or a file next to the study",
        )
    return str(candidate)


def _seeds(path: Path, value: Any) -> tuple[int, ...]:
    if isinstance(value, int) and not isinstance(value, bool):
        if not 1 <= value <= MAX_RUNS:
            raise _fail(
                path, "study", f"seeds = {value}: expected a count from 1 to {MAX_RUNS:,} or a list"
            )
        return tuple(range(1, value + 1))
    if isinstance(value, list) and value and all(_is_int(s) for s in value):
        if bad := [s for s in value if not 0 <= s <= SEED_MAX]:
            raise _fail(
                path,
                "study",
                f"seeds = {show_value(value)}: seed {bad[0]} is out of range; expected seeds "
                f"from 0 to {SEED_MAX} (2**63 - 1, what numpy's int64 and Parquet hold)",
            )
        if len(set(value)) != len(value):
            raise _fail(path, "study", f"seeds = {show_value(value)}: expected distinct seeds")
        return tuple(value)
    raise _fail(
        path, "study", f"seeds = {show_value(value)}: expected a count >= 1 or a list of seeds >= 0"
    )


def _is_int(value: Any) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def _duration(path: Path, value: Any) -> float | None:
    if value is None:
        return None
    if (
        isinstance(value, bool)
        or not isinstance(value, int | float)
        or not math.isfinite(value)
        or value <= 0
    ):
        raise _fail(path, "study", f"duration_s = {value!r}: expected a number > 0")
    return float(value)


def _tables(path: Path, value: Any) -> tuple[str, ...]:
    if value is False:
        return ()
    if value is True:
        return ("*",)
    if isinstance(value, list) and all(isinstance(v, str) for v in value):
        return tuple(value)
    raise _fail(path, "study", f"tables = {value!r}: expected true, false or a list of table names")


def _check_study_set(
    path: Path,
    duration: float | None,
    sections: list[tuple[str, dict[str, Any]]],
    cases: tuple[dict[str, Any], ...],
) -> None:
    """Refuse keys the study sets itself, or that its runs ignore, where they would vary.

    Such a key would be a column of the results whose values no run used.
    """
    places = [*sections, *((f"cases[{i}]", case) for i, case in enumerate(cases))]
    for where, table in places:
        for key, value in table.items():
            if problem := _study_set_problem(key, duration, varied=where != "overrides"):
                raise _fail(path, where, f"{key!r} = {show_value(value)}: {problem}")


def _study_set_problem(key: str, duration: float | None, *, varied: bool) -> str | None:
    if key == "scenario.seed":
        return (
            "the study sets every run's seed from [study] seeds; list the seeds there "
            "instead (seeds = [1, 2, 3])"
        )
    if key == "scenario.duration_s" and duration is not None:
        return (
            f"[study] duration_s = {duration:g} sets every run's duration; drop one of the "
            "two (without [study] duration_s, the runs take scenario.duration_s from here)"
        )
    if varied and key in IGNORED_IN_STUDIES:
        return (
            "study runs ignore it (they write no bag; [study] tables decides the tables "
            "kept), so varying it would record values no run used"
        )
    return None


def _check_size(
    path: Path,
    grid: dict[str, list[Any]],
    cases: tuple[dict[str, Any], ...],
    seeds: tuple[int, ...],
) -> None:
    total = math.prod(len(values) for values in grid.values()) * max(len(cases), 1) * len(seeds)
    if total > MAX_RUNS:
        raise ConfigError(
            f"{path}: {total:,} runs ([grid] x [[cases]] x seeds): expected at most {MAX_RUNS:,}"
        )
