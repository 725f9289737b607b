"""A study's folder, and what ``--resume`` trusts in it.

The folder::

    plan.json           the runs, and a fingerprint of what they depend on
    runs/<run_id>/      row.json, summary.json, scenario.toml[, tables/*.parquet]
    results.parquet     one row per run

A run's folder appears at once, complete (:mod:`cosim.studies.writing`). ``--resume``
continues only the study that started the folder: the same runs (seeds, overrides,
duration, tables) of the same resolved scenario and the same files it reads
(:mod:`cosim.studies.fingerprint`; a section that a package installed since added, and
that changes no run, is let through: :mod:`cosim.studies.gained`). If ``plan.json`` is
lost or garbled, the finished runs are the evidence: each one's row and ``scenario.toml``
must be what this study would run, and then the plan is written again. A run whose
``row.json`` cannot be read, or is not the planned run's (its seed or an override
differs), is run again.

Run folders of every earlier format are read (:mod:`cosim.runner.runfolder`): a key
renamed since with its meaning kept (:data:`cosim.scenario.migrations.RENAMES`) is the
same setting, so a finished run whose ``scenario.toml`` differs from today's only by such
names is resumed, with a note; a rename whose model changed too is a changed scenario,
named as such.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from cosim.core.errors import ConfigError, ExportError
from cosim.runner.runfolder import folder_format
from cosim.scenario.migrations import migrate_dotted
from cosim.studies.fingerprint import (
    PLAN_FILE,
    RUNS_DIR,
    SCENARIO_FILE,
    changed,
    check_fingerprint,
    fingerprint,
    gained_since,
    job_of,
    scenario_change,
)
from cosim.studies.spec import StudySpec
from cosim.studies.worker import row_cells

ROW_FILE = "row.json"
RESULTS_FILE = "results.parquet"
PARTIAL = ".partial"
"""What the folders of runs on their way ended with before format 1 (never read)."""


@dataclass(frozen=True)
class FolderState:
    """What a study's folder holds, read before anything is written to it.

    Attributes:
        done: the runs finished earlier (skipped on resume).
        notes: one line each for the user: a plan rebuilt, a run to run again and why.
        plan: the ``plan.json`` text to write.
    """

    done: frozenset[str]
    notes: tuple[str, ...]
    plan: str


@dataclass(frozen=True)
class _Found:
    """A run folder: its row, or why it cannot be trusted (and the run is run again)."""

    row: dict[str, Any] | None
    problem: str = ""


def _canonical(value: Any) -> str:
    return json.dumps(value, sort_keys=True, default=str)


def _reason(error: OSError) -> str:
    text = error.strerror or str(error)
    return f"{text}: {error.filename}" if error.filename else text


def plan_of(spec: StudySpec) -> dict[str, Any]:
    """The plan written to ``plan.json``: the runs and the fingerprint (JSON values)."""
    plan = {
        "study": spec.name,
        "scenario": spec.scenario,
        "duration_s": spec.duration_s,
        "tables": list(spec.tables),
        "runs": [
            {"run_id": r.run_id, "seed": r.seed, "overrides": r.overrides} for r in spec.runs()
        ],
        "fingerprint": fingerprint(spec),
    }
    loaded: dict[str, Any] = json.loads(_canonical(plan))
    return loaded


def _entries(out: Path) -> list[str]:
    """The names in ``out`` (none if it does not exist yet).

    Raises:
        ExportError: ``out``, or a folder it would be created in, is not a folder.
    """
    if out.exists() and not out.is_dir():
        raise ExportError(f"{out}: is a file; expected a study folder for --out")
    if not out.exists():
        for parent in out.parents:
            if parent.exists():
                if not parent.is_dir():
                    raise ExportError(f"{out}: cannot create the study folder: {parent} is a file")
                break
        return []
    try:
        return os.listdir(out)
    except OSError as error:
        raise ExportError(f"{out}: cannot read the study folder ({_reason(error)})") from None


def read_row(path: Path) -> _Found:
    """A run's ``row.json``, or why it cannot be used."""
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        return _Found(None, f"has no {ROW_FILE}")
    except (OSError, UnicodeDecodeError) as error:
        return _Found(None, f"{ROW_FILE} cannot be read ({error})")
    try:
        row = json.loads(text)
    except (ValueError, RecursionError):  # RecursionError: nested deeper than Python's stack
        return _Found(None, f"{ROW_FILE} is not valid JSON")
    if (
        not isinstance(row, dict)
        or row.get("run_id") != path.parent.name
        or not isinstance(row.get("status"), str)
    ):
        return _Found(None, f"{ROW_FILE} is not this run's row (run_id, status)")
    return _Found(row)


def _run_folders(out: Path) -> dict[str, _Found]:
    runs = out / RUNS_DIR
    if not runs.is_dir():
        return {}
    try:
        folders = [
            p
            for p in runs.iterdir()
            if p.is_dir() and not p.name.startswith(".") and not p.name.endswith(PARTIAL)
        ]
    except OSError as error:
        raise ExportError(f"{runs}: cannot read the study's runs ({_reason(error)})") from None
    for folder in folders:  # a run of a newer format than this cosim reads stops the resume
        folder_format(folder)
    return {p.name: read_row(p / ROW_FILE) for p in sorted(folders)}


def _read_plan(path: Path) -> tuple[dict[str, Any] | None, str]:
    """The plan, or None and what is wrong with it."""
    try:
        plan = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        return None, "is missing"
    except (OSError, UnicodeDecodeError, ValueError, RecursionError):
        return None, "is garbled"
    if not isinstance(plan, dict) or not isinstance(plan.get("runs"), list):
        return None, "is garbled"
    return plan, ""


def inspect(spec: StudySpec, out: Path, *, resume: bool) -> FolderState:
    """Read a study's folder and decide what to run; nothing is written.

    Raises:
        ExportError: a non-empty folder without ``resume``; a folder that is not a study's.
        ConfigError: resuming another study, or the same one over a changed scenario.
    """
    plan = plan_of(spec)
    text = json.dumps(plan, indent=1, sort_keys=True)
    if not _entries(out):
        return FolderState(frozenset(), (), text)
    if not resume:
        raise ExportError(
            f"{out}: folder is not empty; use --resume to continue the study "
            "there, or another --out"
        )
    found = _run_folders(out)
    old, problem = _read_plan(out / PLAN_FILE)
    if old is None and not (out / RUNS_DIR).is_dir():
        raise ExportError(
            f"{out}: not a study folder (no {PLAN_FILE}, no {RUNS_DIR}/); use another --out"
        )
    planned = {r.run_id: r for r in spec.runs()}
    notes = [
        f"{out / RUNS_DIR / run_id} {f.problem}: running {run_id} again"
        for run_id, f in found.items()
        if f.problem and run_id in planned
    ]
    finished = {run_id: f.row for run_id, f in found.items() if f.row and f.row["status"] == "ok"}
    if old is not None and (difference := _plan_difference(old, plan)):
        what = f"the study's runs changed ({difference})"
        raise ConfigError(changed(spec, out, what, finished))
    if old is not None and isinstance(old.get("fingerprint"), dict):
        notes += check_fingerprint(spec, out, old["fingerprint"], plan["fingerprint"], finished)
        done = set()
        for run_id in (r for r in finished if r in planned):
            if bad := _unlike(finished[run_id], row_cells(job_of(spec, planned[run_id]))):
                notes.append(
                    f"{out / RUNS_DIR / run_id} {ROW_FILE} has {bad}: running {run_id} again"
                )
            else:
                done.add(run_id)
    else:
        done, unverified = _verify(spec, out, finished)
        notes += unverified
        if old is None:
            notes.insert(
                0,
                f"{out / PLAN_FILE} {problem}: rebuilt from the {len(done)} finished runs, "
                "which match this study",
            )
    return FolderState(frozenset(done), tuple(notes), text)


def _plan_difference(old: dict[str, Any], new: dict[str, Any]) -> str:
    """What differs between the plan that started the folder and this study's, or ""."""
    for key in ("scenario", "duration_s", "tables"):
        if key in old and _canonical(old[key]) != _canonical(new[key]):
            return f"{key} {_canonical(old[key])} then, {_canonical(new[key])} now"
    then = {str(r.get("run_id")): _renamed_run(r) for r in old["runs"] if isinstance(r, dict)}
    now = {r["run_id"]: r for r in new["runs"]}
    if set(then) != set(now):
        gone, added = sorted(set(then) - set(now)), sorted(set(now) - set(then))
        example = f"{gone[0]} gone" if gone else f"{added[0]} new"
        return f"{len(then)} runs then, {len(now)} now, e.g. {example}"
    for run_id, run in now.items():
        before = then[run_id]
        if _canonical(before) != _canonical(run):
            return _run_difference(run_id, before, run)
    return ""


def _renamed_run(run: dict[str, Any]) -> dict[str, Any]:
    """A planned run of ``plan.json`` with its overrides' keys under today's names."""
    overrides = run.get("overrides")
    return {**run, "overrides": migrate_dotted(overrides)} if isinstance(overrides, dict) else run


def _run_difference(run_id: str, before: dict[str, Any], now: dict[str, Any]) -> str:
    old, new = before.get("overrides", {}), now["overrides"]
    if not isinstance(old, dict):
        return f"run {run_id}: other overrides"
    for key in sorted({*old, *new}):
        if _canonical(old.get(key)) != _canonical(new.get(key)):
            then, now_ = _canonical(old.get(key)), _canonical(new.get(key))
            return f"run {run_id}: {key} = {then} then, {now_} now"
    return f"run {run_id}: seed {before.get('seed')} then, {now['seed']} now"


def _verify(
    spec: StudySpec, out: Path, finished: dict[str, dict[str, Any]]
) -> tuple[set[str], list[str]]:
    """Finished runs that are this study's runs (row and resolved scenario), with notes.

    Raises:
        ConfigError: a finished run is not one of this study's, or ran other settings.
    """
    planned = {r.run_id: r for r in spec.runs()}
    done: set[str] = set()
    notes: list[str] = []
    for run_id, row in finished.items():
        run = planned.get(run_id)
        if run is None:
            what = f"finished run {run_id} is not one of this study's runs"
            raise ConfigError(changed(spec, out, what, finished))
        if bad := _unlike(row, row_cells(job_of(spec, run))):
            raise ConfigError(changed(spec, out, f"finished run {run_id} has {bad}", finished))
        compared = scenario_change(spec, out, run)
        change = compared.change
        if change is None:
            notes.append(
                f"{out / RUNS_DIR / run_id} has no readable {SCENARIO_FILE} to tell which "
                f"scenario it ran: running {run_id} again"
            )
            continue
        if change:
            what = f"the scenario of finished run {run_id} changed ({change})"
            raise ConfigError(changed(spec, out, what, finished))
        notes += [note for note in compared.notes if note not in notes]
        if not done and (note := gained_since(spec, out, run, finished)):
            notes.append(note)  # a package's new section that changes nothing: said once
        done.add(run_id)
    return done, notes


def _unlike(row: dict[str, Any], expected: dict[str, Any]) -> str:
    """``key = value, the study other`` for the first cell of a row unlike the run's, or "".

    The row's keys are read under today's names (renamed keys of the same meaning).
    """
    row = migrate_dotted(row)
    for key, value in expected.items():
        if _canonical(row.get(key)) != _canonical(value):
            return f"{key} = {_canonical(row.get(key))}, the study {_canonical(value)}"
    return ""
