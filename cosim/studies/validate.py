"""Loading a study: its file read (:func:`cosim.studies.spec.read_study`), then checked.

Before any run, every combination is loaded as a scenario (each must load and be able to
run) and its adapters check the sections they need together
(:func:`cosim.runner.assembly.check_scenario`). When the study keeps named tables or its
``[report]`` names metrics, tables or columns, one scenario per distinct set of adapters is
also run for a millisecond: adapters create some tables only when they finish, and summary
metrics are known only from a run, so a name no run would produce is reported now rather
than after the whole study.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from cosim.core.errors import ConfigError
from cosim.core.registry import AdapterRegistry
from cosim.runner.assembly import adapter_names, check_scenario
from cosim.runner.execute import execute
from cosim.scenario import Scenario, load_scenario
from cosim.scenario.fields import show_value
from cosim.studies.derived import DERIVED_METRICS
from cosim.studies.reportspec import RunColumns, check_report_names, names_to_check, study_keys
from cosim.studies.spec import StudySpec, read_study, with_sets
from cosim.studies.worker import run_overrides

PROBE_S = 0.001
"""Simulated seconds of the probe run that shows a set of adapters' tables and metrics."""


def combination_scenarios(spec: StudySpec) -> list[Scenario]:
    """Every combination loaded and checked as a scenario (seed left as the scenario's).

    Raises:
        ConfigError: naming the study file, the combination, the key and the value.
    """
    origin = f"{spec.path} [grid/overrides/cases]"
    named = dict.fromkeys(spec.sets, "--set")
    registry = AdapterRegistry.from_entry_points()
    scenarios = []
    for combination in spec.combinations():
        overrides = run_overrides(combination, seed=None, duration_s=spec.duration_s)
        try:
            scenario = load_scenario(
                spec.scenario, overrides, override_origin=origin, override_origins=named
            )
        except ConfigError as error:
            raise _in_study(spec, error) from None
        try:
            check_scenario(scenario, registry=registry)
        except ConfigError as error:
            shown = ", ".join(f"{k} = {show_value(v)}" for k, v in combination.items())
            raise ConfigError(f"{origin} ({shown}): {error}") from None
        scenarios.append(scenario)
    return scenarios


def _in_study(spec: StudySpec, error: ConfigError) -> ConfigError:
    """An error of the study's scenario, prefixed by the study file when it does not name it."""
    text = str(error)
    if str(spec.path) in text or text.startswith("--set "):  # a --set names itself, as in run
        return error
    return ConfigError(f"{spec.path}: [study] scenario = {spec.scenario!r}: {text}")


def load_study(path: str | Path, sets: Mapping[str, Any] | None = None) -> StudySpec:
    """Read and validate a study file (every combination is checked as a scenario).

    Args:
        path: the study file.
        sets: ``section.key`` -> value set in every run (``cosim study --set``,
            :func:`~cosim.studies.spec.with_sets`).

    Raises:
        ConfigError: naming the file, the section, the key, the value and what was expected
            (or the ``--set``).
    """
    spec = read_study(path)
    if sets:
        spec = with_sets(spec, sets)
    validate_study(spec)
    return spec


def validate_study(spec: StudySpec) -> None:
    """Load and check every combination, and the names the study asks its runs for.

    Raises:
        ConfigError: a combination that cannot run, a kept table no run writes, or a
            ``[report]`` metric, table or column no run produces.
    """
    scenarios = combination_scenarios(spec)
    named = [t for t in spec.tables if t != "*"]
    check_names = bool(spec.report) and names_to_check(spec.report)
    if not named and not check_names:
        return
    columns = probe(scenarios)
    # a table some runs have is kept where it exists (a grid with and without people)
    if missing := [t for t in named if t not in columns.tables]:
        raise ConfigError(
            f"{spec.path}: [study] tables = {list(spec.tables)!r}: no run of this study has "
            f"{', '.join(map(repr, missing))} (expected some of "
            f"{', '.join(sorted(columns.tables))})"
        )
    if check_names:
        keys = study_keys(spec.grid, {**spec.overrides, **spec.sets}, spec.cases)
        kept = columns.tables if "*" in spec.tables else _only(columns.tables, named)
        check_report_names(spec.path, spec.report, keys, _with_tables(columns, kept))


def probe(scenarios: list[Scenario]) -> RunColumns:
    """Summary metrics and table columns of a millisecond run per distinct set of adapters."""
    seen: set[tuple[str, ...]] = set()
    metrics: set[str] = set()
    tables: dict[str, set[str]] = {}
    for scenario in scenarios:
        names = tuple(adapter_names(scenario))
        if names in seen:
            continue
        seen.add(names)
        result = execute(scenario.with_duration(PROBE_S))
        metrics |= set(result.summary)
        metrics.add("wall_time_s")
        for name, frame in result.tables.items():
            tables.setdefault(name, set()).update(map(str, frame.columns))
    return RunColumns(
        metrics=frozenset(metrics),
        derived={name: metric.inputs for name, metric in DERIVED_METRICS.items()},
        tables={name: frozenset(cols) for name, cols in tables.items()},
    )


def _only(tables: Mapping[str, frozenset[str]], names: list[str]) -> dict[str, frozenset[str]]:
    return {name: cols for name, cols in tables.items() if name in names}


def _with_tables(columns: RunColumns, tables: Mapping[str, frozenset[str]]) -> RunColumns:
    return RunColumns(metrics=columns.metrics, derived=columns.derived, tables=tables)
