"""Running one run of a study, in whatever process or Dask worker picks it up.

:func:`run_one` takes plain data and returns plain data (a result row and, if asked, the
run's tables as Parquet bytes), so it can be shipped to another process or machine; the
study runner alone writes to the study folder.
"""

from __future__ import annotations

import io
import json
import time
import traceback
from dataclasses import dataclass
from typing import Any

from cosim.core.errors import CosimError
from cosim.runner.execute import execute
from cosim.runner.result import RECORD_KEYS, RunResult
from cosim.runner.stopping import StopRequest
from cosim.scenario import Scenario, load_scenario
from cosim.scenario.loader import dump_scenario

VOLATILE_METRICS = (
    "wall_time_s",
    "real_time_factor",
    "python",
    "version",
    "humans_coupling_wall_s",
    "humans_sumo_in_process",
    "threads",
    "thread_busy",
    "controller_ms_per_tick",
    "controller_us_per_robot",
    "radio_wall_s",
    "radio_start_s",
)
"""Summary entries that depend on the machine or executor, not on the scenario and seed."""


@dataclass(frozen=True)
class Job:
    """Everything a worker needs for one run.

    Attributes:
        run_id: the run's id in the study.
        scenario: preset name or absolute path.
        seed: scenario seed.
        duration_s: overrides the scenario's duration when set.
        overrides: ``section.key`` -> value.
        tables: table names to return (``("*",)``: all; empty: none).
    """

    run_id: str
    scenario: str
    seed: int
    duration_s: float | None
    overrides: dict[str, Any]
    tables: tuple[str, ...]


@dataclass(frozen=True)
class Outcome:
    """What a run gives back.

    Attributes:
        row: run_id, seed, the overrides, every summary metric, wall_time_s, status, error.
        scenario_toml: the resolved scenario (empty if it failed to load).
        summary: the run's summary.
        tables: Parquet bytes by table name (only those asked for).
        failure: a failed run's one-line error and traceback (its folder's
            ``failure.txt``), or ``""``.
    """

    row: dict[str, Any]
    scenario_toml: str
    summary: dict[str, Any]
    tables: dict[str, bytes]
    failure: str = ""


def _cell(value: Any) -> Any:
    """A table cell for an override: lists (e.g. ``world.size_m``) become their JSON text.

    Array cells cannot be grouped or compared by pandas, so ``[15.0, 15.0]`` is kept as the
    string ``"[15.0, 15.0]"``; scalars are kept as they are.
    """
    if isinstance(value, list | tuple):
        return json.dumps(list(value))
    return value


def run_overrides(
    combination: dict[str, Any], *, seed: int | None, duration_s: float | None
) -> dict[str, Any]:
    """A combination's overrides with the keys the study itself sets (seed, duration)."""
    overrides = dict(combination)
    if seed is not None:
        overrides["scenario.seed"] = seed
    if duration_s is not None:
        overrides["scenario.duration_s"] = duration_s
    return overrides


def job_scenario(job: Job) -> Scenario:
    """The scenario a job runs (its ``scenario.toml`` is this, resolved).

    Raises:
        ConfigError: the scenario or an override is invalid.
    """
    overrides = run_overrides(job.overrides, seed=job.seed, duration_s=job.duration_s)
    return load_scenario(job.scenario, overrides, override_origin="study")


def row_cells(job: Job) -> dict[str, Any]:
    """The columns of a job's row that the study sets: run_id, seed and every override."""
    row: dict[str, Any] = {"run_id": job.run_id, "seed": job.seed}
    row.update((key, _cell(value)) for key, value in job.overrides.items())
    return row


def failed(
    job: Job, error: str, wall_time_s: float, *, kind: str = "input", failure: str = ""
) -> Outcome:
    """The outcome of a run that did not start: its row says why."""
    row = row_cells(job)
    row.update(status="error", error=error, failure_kind=kind, wall_time_s=round(wall_time_s, 4))
    return Outcome(row, "", {}, {}, failure)


def run_one(job: Job, *, stop: StopRequest | None = None) -> Outcome:
    """Run one study run; failures come back as a row with status ``error``, never raise.

    A run that failed once it had started (a plugin's fault, cosim's own, an external
    system's) keeps what ran: its summary of the simulated time reached, its tables and
    its traceback (``failure``), as ``cosim run`` keeps them in a run folder.

    Args:
        job: the run.
        stop: the study's stop request, for a run in the study's own process: a signal
            while the kernel runs ends the run at its next event boundary, then the
            request raises (the run under way is not kept).

    Raises:
        KeyboardInterrupt: the study was asked to stop (``stop``'s exception).
    """
    start = time.perf_counter()
    scenario = None
    try:
        scenario = job_scenario(job)
        result = _execute(scenario, stop)
    except CosimError as error:
        kept = error.kept
        kind = _kind(error)
        trace = f"{error}\n\n{getattr(error, 'details', '')}" if kind != "input" else ""
        if kept is None or scenario is None:
            return failed(job, str(error), time.perf_counter() - start, kind=kind, failure=trace)
        return _outcome(job, kept, dump_scenario(scenario), str(error), kind, trace)
    except Exception as error:  # a bug in a run must not stop the study
        detail = "".join(traceback.format_exception_only(type(error), error)).strip()
        trace = "".join(traceback.format_exception(error))
        return failed(
            job,
            f"internal error: {detail}",
            time.perf_counter() - start,
            kind="cosim",
            failure=f"internal error: {detail}\n\n{trace}",
        )
    return _outcome(job, result, dump_scenario(scenario), "", "", "")


def _execute(scenario: Scenario, stop: StopRequest | None) -> RunResult:
    """:func:`execute`, then the stop asked for during the run, if any (whatever it gave)."""
    try:
        return execute(scenario, stop=stop)
    finally:
        if stop is not None:
            stop.raise_if_requested()


def _kind(error: CosimError) -> str:
    """Whose fault a run's error was: ``plugin``, ``cosim``, ``external`` or ``input``."""
    kept = error.kept
    failure = kept.summary.get("failure") if kept is not None else None
    if isinstance(failure, dict) and isinstance(failure.get("kind"), str):
        return str(failure["kind"])
    from cosim.core.plugins import PluginError
    from cosim.runner.faults import InternalError

    if isinstance(error, PluginError):
        return "plugin"
    return "cosim" if isinstance(error, InternalError) else "input"


def _outcome(
    job: Job, result: RunResult, scenario_toml: str, error: str, kind: str, failure: str
) -> Outcome:
    row = row_cells(job)
    summary = result.summary
    for key, value in summary.items():
        # records are no metrics; failed: said by the row's error and failure_kind
        if key not in ("scenario", "source", "seed", "failed", *RECORD_KEYS):
            row[key] = value
    row.update(
        status="error" if error else "ok",
        error=error,
        failure_kind=kind,
        wall_time_s=summary["wall_time_s"],
    )
    wanted = (
        result.tables
        if "*" in job.tables
        else {name: frame for name, frame in result.tables.items() if name in job.tables}
    )
    tables = {}
    for name, frame in wanted.items():
        buffer = io.BytesIO()
        frame.to_parquet(buffer, index=False)
        tables[name] = buffer.getvalue()
    return Outcome(row, scenario_toml, summary, tables, failure)
